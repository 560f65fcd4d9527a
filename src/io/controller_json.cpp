#include "servotwin/io/controller_json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <span>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "drive_filter_json.hpp"
#include "json_reader.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"

namespace servotwin::io {

namespace {

using detail::JsonObject;
using nlohmann::json;
using tuning::Structure;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Agreement demanded between redundant members (gains vs normalized gains, state spaces vs gains,
/// derived `_hz`/`_s` members): far above the rounding of a written and re-read double, far below
/// any deliberate edit.
constexpr double kRelTol = 1e-6;
constexpr std::array<const char*, 2> kInputNames = {"velocity_reference", "motor_velocity"};
constexpr std::array<const char*, 2> kPositionInputNames = {"position_reference", "motor_position"};
constexpr std::array<const char*, 2> kLoadInputNames = {"velocity_reference", "load_velocity"};
constexpr std::array<const char*, 3> kBothInputNames = {"velocity_reference", "motor_velocity", "load_velocity"};

/// The controller's inputs: [ω*, ωm], [φ*, φm] for a full-order position controller, [ω*, ωl] for a
/// load-measuring one, [ω*, ωm, ωl] for one measuring both (C7.17's LQG).
std::span<const char* const> input_names(Structure s) {
  if (tuning::measures_both(s)) return kBothInputNames;
  if (tuning::measures_load(s)) return kLoadInputNames;
  return tuning::is_position_controller(s) ? kPositionInputNames : kInputNames;
}

json input_names_json(Structure s) {
  json names = json::array();
  for (const char* name : input_names(s)) names.push_back(name);
  return names;
}

/// What the controller measures: "motor", "load" or "both" (C7.17).
std::string feedback_name(Structure s) {
  if (tuning::measures_both(s)) return "both";
  return tuning::measures_load(s) ? "load" : "motor";
}

std::string show(double v) { return fmt::format("{:.9g}", v); }

bool agree(double given, double expected) {
  return std::abs(given - expected) <= kRelTol * std::max(std::abs(given), std::abs(expected));
}

std::string loop_name(Structure s) { return tuning::controls_position(s) ? "position" : "velocity"; }

// ---------------------------------------------------------------- writer

/// A value that must be finite: JSON would silently write NaN and infinity as null.
double finite(double v, const std::string& field) {
  if (!std::isfinite(v))
    throw std::invalid_argument("controller_to_json: " + field + " is not finite (" + show(v) + ")");
  return v;
}

json numbers_json(const std::vector<double>& v, const std::string& field) {
  json out = json::array();
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(finite(v[i], field + "[" + std::to_string(i) + "]"));
  return out;
}

json optional_finite(const std::optional<double>& v, const std::string& field) {
  return v ? json(finite(*v, field)) : json(nullptr);
}

/// Finite numbers as numbers, ±infinity as "inf"/"-inf", NaN (undefined) as null.
json extended(double v) {
  if (std::isnan(v)) return nullptr;
  if (std::isinf(v)) return v > 0.0 ? "inf" : "-inf";
  return v;
}

json matrix_json(const Eigen::MatrixXd& m, const std::string& field) {
  json rows = json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    json row = json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      row.push_back(finite(m(i, j), field + "[" + std::to_string(i) + "][" + std::to_string(j) + "]"));
    rows.push_back(std::move(row));
  }
  return rows;
}

json gains_json(const tuning::PidGains& g, const std::optional<double>& kpp, const std::string& section) {
  return {{"kp", finite(g.kp, section + ".kp")},          {"ki", finite(g.ki, section + ".ki")},
          {"kd", finite(g.kd, section + ".kd")},          {"tau", finite(g.tau, section + ".tau")},
          {"wp", finite(g.wp, section + ".wp")},          {"wd", finite(g.wd, section + ".wd")},
          {"kpp", optional_finite(kpp, section + ".kpp")}};
}

/// How a LoopIndices member scales to physical units: frequencies get a `_hz` twin (× ωz/2π),
/// times a `_s` twin (/ ωz); the rest are dimensionless or stay normalized.
enum class Scale { kNone, kFrequency, kTime };

struct IndexField {
  const char* name;
  double tuning::LoopIndices::*member;
  Scale scale;
};

using tuning::LoopIndices;
/// Every numeric member of tuning::LoopIndices, in the struct's order.
constexpr std::array kIndexFields{
    IndexField{"bandwidth_motor", &LoopIndices::bandwidth_motor, Scale::kFrequency},
    IndexField{"bandwidth_load", &LoopIndices::bandwidth_load, Scale::kFrequency},
    IndexField{"peak_s", &LoopIndices::peak_s, Scale::kNone},
    IndexField{"peak_s_omega", &LoopIndices::peak_s_omega, Scale::kFrequency},
    IndexField{"peak_t", &LoopIndices::peak_t, Scale::kNone},
    IndexField{"peak_tm", &LoopIndices::peak_tm, Scale::kNone},
    IndexField{"peak_tl", &LoopIndices::peak_tl, Scale::kNone},
    IndexField{"peak_load_disturbance", &LoopIndices::peak_load_disturbance, Scale::kNone},
    IndexField{"j2", &LoopIndices::j2, Scale::kNone},
    IndexField{"gain_margin_db", &LoopIndices::gain_margin_db, Scale::kNone},
    IndexField{"phase_crossover", &LoopIndices::phase_crossover, Scale::kFrequency},
    IndexField{"phase_margin_deg", &LoopIndices::phase_margin_deg, Scale::kNone},
    IndexField{"gain_crossover", &LoopIndices::gain_crossover, Scale::kFrequency},
    IndexField{"modulus_margin", &LoopIndices::modulus_margin, Scale::kNone},
    IndexField{"overshoot", &LoopIndices::overshoot, Scale::kNone},
    IndexField{"settling_time", &LoopIndices::settling_time, Scale::kTime},
    IndexField{"overshoot_motor", &LoopIndices::overshoot_motor, Scale::kNone},
    IndexField{"settling_time_motor", &LoopIndices::settling_time_motor, Scale::kTime},
    IndexField{"itae_load_step", &LoopIndices::itae_load_step, Scale::kNone},
    IndexField{"peak_torque_step", &LoopIndices::peak_torque_step, Scale::kNone},
    IndexField{"hf_controller_gain", &LoopIndices::hf_controller_gain, Scale::kNone},
    IndexField{"min_damping", &LoopIndices::min_damping, Scale::kNone},
    IndexField{"sample_time", &LoopIndices::sample_time, Scale::kTime},
    IndexField{"horizon", &LoopIndices::horizon, Scale::kTime},
};

/// The physical twin of a scaled index: its name and factor (normalized × factor = physical).
std::pair<std::string, double> physical_twin(const IndexField& f, double omega_z) {
  if (f.scale == Scale::kFrequency) return {std::string(f.name) + "_hz", omega_z / kTwoPi};
  return {std::string(f.name) + "_s", 1.0 / omega_z};
}

json poles_json(const std::vector<std::complex<double>>& poles, const std::string& section) {
  json out = json::array();
  for (std::size_t i = 0; i < poles.size(); ++i) {
    const std::string field = section + "[" + std::to_string(i) + "]";
    out.push_back({finite(poles[i].real(), field), finite(poles[i].imag(), field)});
  }
  return out;
}

json predicted_json(const LoopIndices& p, double omega_z) {
  json j = {{"closed_loop_stable", p.closed_loop_stable}};
  for (const IndexField& f : kIndexFields) {
    const double v = p.*f.member;
    j[f.name] = extended(v);
    if (f.scale == Scale::kNone) continue;
    const auto [twin, factor] = physical_twin(f, omega_z);
    j[twin] = extended(v * factor);
  }
  j["closed_loop_poles"] = poles_json(p.closed_loop_poles, "predicted.closed_loop_poles");
  return j;
}

json robustness_json(const tuning::RobustnessSummary& r) {
  const auto put = [](const std::optional<double>& v, const char* name) {
    if (!v) return json(nullptr);
    if (std::isnan(*v)) throw std::invalid_argument(std::string("controller_to_json: robustness.") + name + " is NaN");
    return extended(*v);
  };
  return {{"rs", put(r.rs, "rs")},
          {"np", put(r.np, "np")},
          {"rp", put(r.rp, "rp")},
          {"rp_tracking", put(r.rp_tracking, "rp_tracking")}};
}

json position_json(const tuning::Controller& c, double omega_z) {
  const std::optional<tuning::PositionSummary>& p = c.position;
  if (!p) return nullptr;
  return {{"kpp", finite(*c.kpp_physical, "position.kpp")},
          {"kpp_normalized", finite(*c.kpp_normalized, "position.kpp_normalized")},
          {"kpp_nominal", finite(p->kpp_nominal, "position.kpp_nominal")},
          {"kpp_rs", optional_finite(p->kpp_rs, "position.kpp_rs")},
          {"kpp_rp_exact", optional_finite(p->kpp_rp_exact, "position.kpp_rp_exact")},
          {"bandwidth_load", finite(p->bandwidth_load, "position.bandwidth_load")},
          {"bandwidth_load_hz", p->bandwidth_load * omega_z / kTwoPi},
          {"j2", finite(p->j2, "position.j2")},
          {"peak_load_tracking", finite(p->peak_load_tracking, "position.peak_load_tracking")}};
}

json state_space_json(const core::StateSpace& ss, const std::string& section, Structure structure) {
  return {{"inputs", input_names_json(structure)},
          {"output", "torque"},
          {"A", matrix_json(ss.A, section + ".A")},
          {"B", matrix_json(ss.B, section + ".B")},
          {"C", matrix_json(ss.C, section + ".C")},
          {"D", matrix_json(ss.D, section + ".D")}};
}

/// The compensator members common to the lqg and hinf sections (a position controller's with its
/// prefilter's time constant).
void add_compensator(json& section, const tuning::FullOrderSummary& f, const std::string& name, Structure structure) {
  if (tuning::is_position_controller(structure)) section["prefilter_tau"] = finite(f.prefilter_tau, name + ".prefilter_tau");
  section["controller_stable"] = f.controller_stable;
  section["controller_poles"] = poles_json(f.controller_poles, name + ".controller_poles");
  section["compensator"] = state_space_json(f.compensator, name + ".compensator", structure);
}

json position_lqg_json(const tuning::FullOrderSummary& f, Structure structure) {
  const tuning::PositionLqgOptions& w = *f.position_weights;
  json q = json::array();
  for (Eigen::Index i = 0; i < w.q.size(); ++i) q.push_back(finite(w.q(i), "lqg.q"));
  json out = {{"kbw", finite(w.kbw, "lqg.kbw")},
              {"kbw_source", f.kbw_source},
              {"feedforward_source", f.feedforward_source},
              {"q", q},
              {"process_noise", finite(w.process_noise, "lqg.process_noise")},
              {"measurement_noise", finite(w.measurement_noise, "lqg.measurement_noise")}};
  add_compensator(out, f, "lqg", structure);
  return out;
}

json hinf_json(const std::optional<tuning::FullOrderSummary>& f, Structure structure) {
  if (!f || !f->hinf) return nullptr;
  const tuning::HinfSummary& h = *f->hinf;
  json out = {{"omega_0s", finite(h.omega_0s, "hinf.omega_0s")},
              {"omega_0s_source", h.omega_0s_source},
              {"omega_0t", finite(h.omega_0t, "hinf.omega_0t")},
              {"xi_v", finite(h.xi_v, "hinf.xi_v")},
              {"gamma_optimal", finite(h.gamma_optimal, "hinf.gamma_optimal")},
              {"gamma", finite(h.gamma, "hinf.gamma")},
              {"modes", tuning::to_string(h.modes)},
              {"full_order", h.full_order},
              {"hankel_singular_values", numbers_json(h.hankel, "hinf.hankel_singular_values")},
              {"reduction_error_bound", finite(h.reduction_error_bound, "hinf.reduction_error_bound")},
              {"rolloff", optional_finite(h.rolloff, "hinf.rolloff")}};
  add_compensator(out, *f, "hinf", structure);
  return out;
}

json lqg_json(const std::optional<tuning::FullOrderSummary>& f, Structure structure) {
  if (!f || f->hinf) return nullptr;
  if (f->position_weights) return position_lqg_json(*f, structure);
  const tuning::VelocityLqgOptions& w = f->weights;
  json out = {{"kbw", finite(w.kbw, "lqg.kbw")},
          {"kbw_source", f->kbw_source},
          {"feedforward", finite(w.feedforward, "lqg.feedforward")},
          {"feedforward_source", f->feedforward_source},
          {"q_load_velocity", finite(w.q_load_velocity, "lqg.q_load_velocity")},
          {"q_integral", finite(w.q_integral, "lqg.q_integral")},
          {"noise_motor", finite(w.noise_motor, "lqg.noise_motor")},
          {"noise_load_torque", finite(w.noise_load_torque, "lqg.noise_load_torque")},
          {"measurement_noise", finite(w.measurement_noise, "lqg.measurement_noise")},
          {"raw_motor_velocity", w.raw_motor_velocity}};
  add_compensator(out, *f, "lqg", structure);
  return out;
}

// ---------------------------------------------------------------- reader

/// A JSON object with its raw value, for members that JsonObject does not type (matrices,
/// nullable and extended numbers).
struct Section {
  const json& value;
  JsonObject object;

  Section(const json& v, std::string path, std::string_view source) : value(v), object(v, std::move(path), source) {}

  [[nodiscard]] const json& raw(std::string_view key) const {
    const auto it = value.find(key);
    if (it == value.end()) object.fail(key, "missing required field");
    return *it;
  }
  [[nodiscard]] Section section(std::string_view key) const {
    return Section(raw(key), object.member_path(key), object.source());
  }
  [[noreturn]] void fail(std::string_view key, const std::string& message) const { object.fail(key, message); }

  [[nodiscard]] double number(std::string_view key) const { return object.number(key); }
  [[nodiscard]] double positive(std::string_view key, const char* what) const {
    const double v = number(key);
    if (!(v > 0.0)) fail(key, std::string("expected ") + what + " > 0, got " + show(v));
    return v;
  }
  [[nodiscard]] double non_negative(std::string_view key, const char* what) const {
    const double v = number(key);
    if (!(v >= 0.0)) fail(key, std::string("expected ") + what + " >= 0, got " + show(v));
    return v;
  }
  [[nodiscard]] bool boolean(std::string_view key) const {
    const json& v = raw(key);
    if (!v.is_boolean()) fail(key, std::string("expected true or false, found ") + v.type_name());
    return v.get<bool>();
  }
  /// A number, "inf", "-inf", or null (NaN: undefined).
  [[nodiscard]] double extended(std::string_view key) const {
    const json& v = raw(key);
    if (v.is_null()) return std::numeric_limits<double>::quiet_NaN();
    if (v.is_string()) {
      const auto s = v.get<std::string>();
      if (s == "inf") return std::numeric_limits<double>::infinity();
      if (s == "-inf") return -std::numeric_limits<double>::infinity();
      fail(key, "expected a number, \"inf\", \"-inf\" or null, got \"" + s + "\"");
    }
    return number(key);
  }
  /// A finite number or null (required member).
  [[nodiscard]] std::optional<double> nullable(std::string_view key) const {
    if (raw(key).is_null()) return std::nullopt;
    return number(key);
  }
  /// A string equal to `expected`.
  void expect_string(std::string_view key, std::string_view expected) const {
    const std::string s = object.string(key);
    if (s != expected) fail(key, "expected \"" + std::string(expected) + "\", got \"" + s + "\"");
  }
};

/// Array of rows, every row as long as the first, finite numbers; `rows`/`cols` < 0: any (>= 1).
Eigen::MatrixXd read_matrix(const Section& s, std::string_view key, Eigen::Index rows, Eigen::Index cols) {
  const std::string name(key);
  const json& m = s.raw(key);
  const auto shape = [](Eigen::Index r, Eigen::Index c) {
    return (r < 0 ? std::string("n") : std::to_string(r)) + "x" + (c < 0 ? std::string("n") : std::to_string(c));
  };
  if (!m.is_array() || m.empty() || !m[0].is_array() || m[0].empty())
    s.fail(key, "expected a non-empty array of rows (a " + shape(rows, cols) + " matrix)");
  const auto r = static_cast<Eigen::Index>(m.size());
  const auto c = static_cast<Eigen::Index>(m[0].size());
  if ((rows >= 0 && r != rows) || (cols >= 0 && c != cols))
    s.fail(key, "expected a " + shape(rows, cols) + " matrix, got " + std::to_string(r) + "x" + std::to_string(c));
  Eigen::MatrixXd out(r, c);
  for (Eigen::Index i = 0; i < r; ++i) {
    const json& row = m[static_cast<std::size_t>(i)];
    const std::string row_key = name + "[" + std::to_string(i) + "]";
    if (!row.is_array() || static_cast<Eigen::Index>(row.size()) != c)
      s.fail(row_key, "expected a row of " + std::to_string(c) + " numbers (as the first row)");
    for (Eigen::Index j = 0; j < c; ++j) {
      const json& v = row[static_cast<std::size_t>(j)];
      if (!v.is_number() || !std::isfinite(v.get<double>()))
        s.fail(row_key + "[" + std::to_string(j) + "]", "expected a finite number, found " + v.dump());
      out(i, j) = v.get<double>();
    }
  }
  return out;
}

/// A, B, C, D of a controller with the structure's inputs and one output.
void read_matrices(const Section& s, Structure structure, Eigen::MatrixXd& a, Eigen::MatrixXd& b, Eigen::MatrixXd& c,
                   Eigen::MatrixXd& d) {
  const auto inputs = static_cast<Eigen::Index>(input_names(structure).size());
  a = read_matrix(s, "A", -1, -1);
  if (a.rows() != a.cols())
    s.fail("A", "expected a square matrix, got " + std::to_string(a.rows()) + "x" + std::to_string(a.cols()));
  b = read_matrix(s, "B", a.rows(), inputs);
  c = read_matrix(s, "C", 1, a.rows());
  d = read_matrix(s, "D", 1, inputs);
}

/// The file's system must have the response of the system the gains define at every `omegas`
/// (rad/s): relative to the larger channel, so a channel that is (nearly) zero is judged against
/// the others. `response(sys, ω)` evaluates a 1×(inputs) response.
template <typename System, typename Response>
void check_realization(const Section& parent, std::string_view key, const System& file, const System& expected,
                       const std::vector<double>& omegas, Response response, Structure structure) {
  for (double w : omegas) {
    const Eigen::MatrixXcd g = response(file, w);
    const Eigen::MatrixXcd e = response(expected, w);
    const double scale = e.row(0).cwiseAbs().maxCoeff();
    for (Eigen::Index k = 0; k < e.cols(); ++k) {
      const std::complex<double> diff = g(0, k) - e(0, k);
      if (!(std::abs(diff) <= kRelTol * scale))
        parent.fail(key, fmt::format("does not realize the controller of \"gains\": at {} Hz the response from {} is "
                                     "{}{:+.9g}j, the gains give {}{:+.9g}j (agreement within {} relative expected)",
                                     show(w / kTwoPi), input_names(structure)[static_cast<std::size_t>(k)], show(g(0, k).real()),
                                     g(0, k).imag(), show(e(0, k).real()), e(0, k).imag(), kRelTol));
    }
  }
}

struct GainsRead {
  tuning::PidGains gains;
  std::optional<double> kpp;
};

GainsRead read_gains(const Section& s, Structure structure) {
  s.object.allow_only({"kp", "ki", "kd", "tau", "wp", "wd", "kpp"});
  GainsRead out;
  tuning::PidGains& g = out.gains;
  g.kp = s.number("kp");
  g.ki = s.number("ki");
  g.kd = s.number("kd");
  g.tau = s.non_negative("tau", "a derivative filter time constant");
  for (const auto& [key, weight] : {std::pair{"wp", &g.wp}, std::pair{"wd", &g.wd}}) {
    *weight = s.number(key);
    if (!(*weight >= 0.0 && *weight <= 1.0)) s.fail(key, "expected a setpoint weight in [0, 1], got " + show(*weight));
  }
  if (structure == Structure::kPid) {
    if (!(g.tau > 0.0))
      s.fail("tau", "a pid needs a derivative filter time constant > 0 (an ideal derivative has no state space)");
  } else {
    const std::string name = to_string(structure);
    if (g.kd != 0.0)
      s.fail("kd", "expected 0 for a \"" + name + "\" controller (only \"pid\" has a derivative), got " + show(g.kd));
    if (g.tau != 0.0)
      s.fail("tau", "expected 0 for a \"" + name + "\" controller (only \"pid\" has a derivative), got " + show(g.tau));
  }
  out.kpp = s.nullable("kpp");
  if (structure == Structure::kPiP) {
    if (!out.kpp || !(*out.kpp > 0.0)) s.fail("kpp", "expected a position gain > 0 for a \"pi+p\" controller");
  } else if (out.kpp) {
    s.fail("kpp", "expected null: only a \"pi+p\" controller has a position gain");
  }
  return out;
}

/// gains.<key> must be normalized.<key> de-normalized.
void check_scaled(const Section& s, const char* key, double physical, double expected, const char* rule) {
  if (!agree(physical, expected))
    s.fail(key, "is " + show(physical) + " but normalized." + key + " de-normalized with the plant scales (" + rule +
                    ") gives " + show(expected) + " (agreement within 1e-6 relative expected)");
}

void check_gains_agree(const Section& s, const GainsRead& physical, const GainsRead& normalized,
                       const tuning::PlantScales& scales) {
  tuning::NormalizedPlant plant;
  plant.omega_z = scales.omega_z;
  plant.motor_inertia = scales.motor_inertia;
  const tuning::PidGains e = tuning::to_physical(normalized.gains, plant);
  const tuning::PidGains& g = physical.gains;
  check_scaled(s, "kp", g.kp, e.kp, "Kp = Kp_n·Im·ωz");
  check_scaled(s, "ki", g.ki, e.ki, "Ki = Ki_n·Im·ωz²");
  check_scaled(s, "kd", g.kd, e.kd, "Kd = Kd_n·Im");
  check_scaled(s, "tau", g.tau, e.tau, "τ = τ_n/ωz");
  check_scaled(s, "wp", g.wp, e.wp, "the same weight");
  check_scaled(s, "wd", g.wd, e.wd, "the same weight");
  if (physical.kpp) check_scaled(s, "kpp", *physical.kpp, *normalized.kpp * scales.omega_z, "Kpp = Kpp_n·ωz");
}

tuning::PlantScales read_plant(const Section& s, std::string& source) {
  s.object.allow_only({"source", "omega_z_hz", "motor_inertia", "r", "zeta_z", "zeta_p", "a"});
  source = s.object.string("source");
  tuning::PlantScales p;
  p.omega_z = kTwoPi * s.positive("omega_z_hz", "an antiresonance frequency [Hz]");
  p.motor_inertia = s.positive("motor_inertia", "a motor inertia");
  p.r = s.number("r");
  if (!(p.r > 1.0)) s.fail("r", "expected a resonance ratio > 1 (antiresonance below resonance), got " + show(p.r));
  p.zeta_z = s.non_negative("zeta_z", "a damping ratio");
  p.zeta_p = s.non_negative("zeta_p", "a damping ratio");
  p.a = s.non_negative("a", "a normalized rigid pole");
  return p;
}

/// A member derived from a normalized one: `derived` = `base` · factor, with the same non-finite class.
void check_derived(const Section& s, const char* derived, const char* base, double base_value, double factor,
                   const char* relation) {
  const double given = s.extended(derived);
  const double expected = base_value * factor;
  const bool ok = std::isnan(expected)   ? std::isnan(given)
                  : std::isinf(expected) ? given == expected
                                         : std::isfinite(given) && agree(given, expected);
  if (!ok)
    s.fail(derived, "is " + json(extended(given)).dump() + " but " + base + " " + relation + " gives " +
                        json(extended(expected)).dump() + " (agreement within 1e-6 relative expected)");
}

tuning::DesignParameters read_design(const Section& s, double omega_z, Structure structure) {
  s.object.allow_only(
      {"omega_star", "omega_star_hz", "zeta_star", "r_target", "ms", "mt", "min_damping", "omega_star_source"});
  tuning::DesignParameters d;
  if (tuning::is_full_order(structure)) {
    // A full-order design assigns no pole pair: ω* and ζ* are null.
    for (const char* key : {"omega_star", "omega_star_hz", "zeta_star"}) {
      if (!s.raw(key).is_null()) s.fail(key, "expected null for a full-order controller (no assigned pole pair)");
    }
  } else {
    d.omega_star = s.positive("omega_star", "a normalized bandwidth ω*/ωz");
    check_derived(s, "omega_star_hz", "omega_star", d.omega_star, omega_z / kTwoPi, "× ωz/2π");
    d.zeta_star = s.positive("zeta_star", "a damping ratio");
  }
  d.r_target = s.nullable("r_target");
  if (d.r_target && !(*d.r_target > 1.0))
    s.fail("r_target", "expected a target resonance ratio > 1 or null, got " + show(*d.r_target));
  for (const char* key : {"ms", "mt"}) {
    const std::optional<double> v = s.nullable(key);
    if (v && !(*v >= 1.0)) s.fail(key, "expected a peak limit >= 1 or null, got " + show(*v));
    (std::string(key) == "ms" ? d.ms : d.mt) = v;
  }
  if (s.object.has("min_damping")) {  // absent in files written before the option existed
    d.min_damping = s.nullable("min_damping");
    if (d.min_damping && !(*d.min_damping > 0.0 && *d.min_damping < 1.0))
      s.fail("min_damping", "expected a damping ratio in (0, 1) or null, got " + show(*d.min_damping));
  }
  d.omega_star_source = s.object.string("omega_star_source");
  return d;
}

/// An array of finite numbers (possibly empty).
std::vector<double> read_numbers(const Section& s, std::string_view key) {
  const json& values = s.raw(key);
  if (!values.is_array()) s.fail(key, "expected an array of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const json& e = values[i];
    if (!e.is_number() || !std::isfinite(e.get<double>()))
      s.fail(std::string(key) + "[" + std::to_string(i) + "]", "expected a finite number, found " + e.dump());
    out.push_back(e.get<double>());
  }
  return out;
}

std::vector<std::complex<double>> read_poles(const Section& s, std::string_view key) {
  const json& poles = s.raw(key);
  const std::string name(key);
  if (!poles.is_array()) s.fail(key, "expected an array of [re, im] pairs");
  std::vector<std::complex<double>> out;
  for (std::size_t i = 0; i < poles.size(); ++i) {
    const json& e = poles[i];
    const bool pair = e.is_array() && e.size() == 2 && e[0].is_number() && e[1].is_number() &&
                      std::isfinite(e[0].get<double>()) && std::isfinite(e[1].get<double>());
    if (!pair) s.fail(name + "[" + std::to_string(i) + "]", "expected a pair [re, im] of finite numbers, found " + e.dump());
    out.emplace_back(e[0].get<double>(), e[1].get<double>());
  }
  return out;
}

LoopIndices read_predicted(const Section& s, double omega_z) {
  std::vector<std::string> known = {"closed_loop_stable", "closed_loop_poles"};
  for (const IndexField& f : kIndexFields) {
    known.emplace_back(f.name);
    if (f.scale != Scale::kNone) known.push_back(physical_twin(f, omega_z).first);
  }
  for (const auto& [key, value] : s.value.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    s.fail(key, "unknown field (expected one of: " + list + ")");
  }
  LoopIndices p;
  p.closed_loop_stable = s.boolean("closed_loop_stable");
  for (const IndexField& f : kIndexFields) {
    p.*f.member = s.extended(f.name);
    if (f.scale == Scale::kNone) continue;
    const auto [twin, factor] = physical_twin(f, omega_z);
    check_derived(s, twin.c_str(), f.name, p.*f.member, factor, f.scale == Scale::kFrequency ? "× ωz/2π" : "/ ωz");
  }

  p.closed_loop_poles = read_poles(s, "closed_loop_poles");
  return p;
}

/// The position-loop section: null for the velocity structures, an object for pi+p and lqg+p. Its
/// "kpp"/"kpp_normalized" carry the position gain (required for lqg+p, whose gains are null; for
/// pi+p optional, as files before lqg+p lack them, and equal to the gains' when present).
void read_position(const Section& root, tuning::Controller& c) {
  const bool wanted = tuning::has_position_loop(c.structure);
  const std::string name = to_string(c.structure);
  const bool present = !root.raw("position").is_null();
  if (present != wanted)
    root.fail("position", wanted ? "a \"" + name + "\" controller needs its position-loop section"
                                 : "only pi+p and lqg+p controllers have a position-loop section (expected null)");
  if (!present) return;
  const Section s = root.section("position");
  s.object.allow_only({"kpp", "kpp_normalized", "kpp_nominal", "kpp_rs", "kpp_rp_exact", "bandwidth_load",
                       "bandwidth_load_hz", "j2", "peak_load_tracking"});
  const double omega_z = c.plant.omega_z;
  if (c.structure == Structure::kLqgP || s.value.contains("kpp")) {
    const double kpp = s.positive("kpp", "a position gain [1/s]");
    const double kpp_n = s.positive("kpp_normalized", "a normalized position gain");
    check_scaled(s, "kpp", kpp, kpp_n * omega_z, "Kpp = Kpp_n·ωz");
    if (c.kpp_physical && !agree(*c.kpp_physical, kpp))
      s.fail("kpp", "is " + show(kpp) + " but gains.kpp is " + show(*c.kpp_physical));
    c.kpp_physical = kpp;
    c.kpp_normalized = kpp_n;
  }
  tuning::PositionSummary p;
  p.kpp_nominal = s.positive("kpp_nominal", "a position gain");
  for (const char* key : {"kpp_rs", "kpp_rp_exact"}) {
    const std::optional<double> v = s.nullable(key);
    if (v && !(*v >= 0.0)) s.fail(key, "expected a position gain >= 0 or null, got " + show(*v));
    (std::string(key) == "kpp_rs" ? p.kpp_rs : p.kpp_rp_exact) = v;
  }
  p.bandwidth_load = s.non_negative("bandwidth_load", "a normalized bandwidth");
  check_derived(s, "bandwidth_load_hz", "bandwidth_load", p.bandwidth_load, omega_z / kTwoPi, "× ωz/2π");
  p.j2 = s.non_negative("j2", "a peak gain");
  p.peak_load_tracking = s.non_negative("peak_load_tracking", "a peak gain");
  c.position = p;
}

tuning::RobustnessSummary read_robustness(const Section& s) {
  s.object.allow_only({"rs", "np", "rp", "rp_tracking"});
  const auto read = [&](const char* key) -> std::optional<double> {
    if (s.raw(key).is_null()) return std::nullopt;
    const double v = s.extended(key);
    if (!(v >= 0.0)) s.fail(key, "expected a norm >= 0, \"inf\" or null (not evaluated), got " + show(v));
    return v;
  };
  tuning::RobustnessSummary r;
  r.rs = read("rs");
  r.np = read("np");
  r.rp = read("rp");
  if (s.value.contains("rp_tracking")) r.rp_tracking = read("rp_tracking");  // absent in files of 2026-11-23 and before
  return r;
}

/// Frequencies [rad/s] at which the continuous realization is compared: four decades around ωz
/// (the design band) and the derivative filter's corner.
std::vector<double> continuous_check_frequencies(double omega_z, const tuning::PidGains& g) {
  std::vector<double> w;
  for (double k : {0.01, 0.1, 0.5, 1.0, 2.0, 10.0, 100.0}) w.push_back(k * omega_z);
  if (g.tau > 0.0) w.push_back(1.0 / g.tau);
  return w;
}

/// The members "inputs", "output", "A".."D" of a controller state space.
core::StateSpace read_controller_matrices(const Section& s, Structure structure) {
  s.object.allow_only({"inputs", "output", "A", "B", "C", "D"});
  const json& inputs = s.raw("inputs");
  if (inputs != input_names_json(structure))
    s.fail("inputs", "expected " + input_names_json(structure).dump() + " for a \"" + to_string(structure) +
                         "\" controller, got " + inputs.dump());
  s.expect_string("output", "torque");
  core::StateSpace out;
  read_matrices(s, structure, out.A, out.B, out.C, out.D);
  return out;
}

/// The physical state space must realize `expected` (the gains', or the compensator de-normalized).
void read_state_space(const Section& root, const core::StateSpace& expected, const std::vector<double>& omegas,
                      Structure structure) {
  const core::StateSpace file = read_controller_matrices(root.section("state_space"), structure);
  const auto response = [](const core::StateSpace& sys, double w) { return core::frequency_response(sys, w); };
  check_realization(root, "state_space", file, expected, omegas, response, structure);
}

std::optional<core::DiscreteStateSpace> read_discrete(const Section& root, const tuning::Controller& c,
                                                      std::optional<double>& prewarp_rad_s) {
  if (root.raw("discrete").is_null()) return std::nullopt;
  const Section s = root.section("discrete");
  s.object.allow_only({"ts", "method", "prewarp_hz", "A", "B", "C", "D"});
  const double ts = s.positive("ts", "a sample period [s]");
  s.expect_string("method", "tustin");
  const double nyquist_hz = 0.5 / ts;
  if (const auto prewarp_hz = s.nullable("prewarp_hz")) {
    if (!(*prewarp_hz > 0.0 && *prewarp_hz < nyquist_hz))
      s.fail("prewarp_hz", "expected a frequency in (0, " + show(nyquist_hz) + ") Hz (below Nyquist) or null, got " +
                               show(*prewarp_hz));
    prewarp_rad_s = kTwoPi * *prewarp_hz;
  }
  core::DiscreteStateSpace file;
  file.ts = ts;
  read_matrices(s, c.structure, file.A, file.B, file.C, file.D);
  const core::DiscreteStateSpace expected = tuning::discretize_controller(c, ts, prewarp_rad_s);
  std::vector<double> omegas;
  for (double k : {1e-3, 1e-2, 0.1, 0.3, 0.6, 0.9}) omegas.push_back(k * kTwoPi * nyquist_hz);
  if (prewarp_rad_s) omegas.push_back(*prewarp_rad_s);
  const auto response = [](const core::DiscreteStateSpace& sys, double w) { return core::frequency_response(sys, w); };
  check_realization(root, "discrete", file, expected, omegas, response, c.structure);
  return file;
}

/// Every listed pole must be an eigenvalue of `a` (one to one, relative 1e-6 of the largest).
void check_poles(const Section& s, std::string_view key, const std::vector<std::complex<double>>& listed,
                 const Eigen::MatrixXd& a) {
  const Eigen::VectorXcd eig = a.eigenvalues();
  std::vector<std::complex<double>> left(eig.data(), eig.data() + eig.size());
  if (listed.size() != left.size())
    s.fail(key, "expected the " + std::to_string(left.size()) + " eigenvalues of compensator.A, got " +
                    std::to_string(listed.size()) + " poles");
  double scale = 1.0;
  for (const auto& p : left) scale = std::max(scale, std::abs(p));
  for (std::size_t i = 0; i < listed.size(); ++i) {
    const auto nearest = std::min_element(left.begin(), left.end(), [&](auto x, auto y) {
      return std::abs(x - listed[i]) < std::abs(y - listed[i]);
    });
    if (!(std::abs(*nearest - listed[i]) <= kRelTol * scale))
      s.fail(std::string(key) + "[" + std::to_string(i) + "]",
             fmt::format("{}{:+.9g}j is not an eigenvalue of compensator.A (nearest {}{:+.9g}j)", show(listed[i].real()),
                         listed[i].imag(), show(nearest->real()), nearest->imag()));
    left.erase(nearest);
  }
}

/// Whether the optional section `key` is present (not absent, not null) exactly when `wanted`.
bool section_present(const Section& root, const char* key, bool wanted, const std::string& owners,
                     Structure structure) {
  const bool present = root.value.contains(key) && !root.raw(key).is_null();  // absent in older files
  if (present != wanted)
    root.fail(key, wanted ? "an \"" + to_string(structure) + "\" controller needs its compensator section"
                          : "only " + owners + " controllers have this section (expected null)");
  return present;
}

/// A position controller's prefilter time constant: >= 0, and when > 0 the compensator's first
/// state is the prefilter's (tuning::with_prefilter: x' = (φ* − x)/τ).
void read_prefilter(const Section& s, tuning::FullOrderSummary& f) {
  f.prefilter_tau = s.non_negative("prefilter_tau", "a time constant");
  const double tau = f.prefilter_tau;
  if (tau == 0.0) return;
  const Eigen::MatrixXd& a = f.compensator.A;
  const Eigen::MatrixXd& b = f.compensator.B;
  const bool first_state = a.rows() > 0 && b.rows() > 0 && b.cols() == 2 && agree(a(0, 0), -1.0 / tau) &&
                           agree(b(0, 0), 1.0 / tau) && (a.row(0).tail(a.cols() - 1).array() == 0.0).all() &&
                           b(0, 1) == 0.0;
  if (!first_state)
    s.fail("prefilter_tau", "is " + show(tau) + " but the compensator's first state is not the prefilter x' = (r - x)/tau");
}

/// The compensator, its poles (checked against its A) and its stability flag (checked against them).
void read_compensator(const Section& s, tuning::FullOrderSummary& f, Structure structure) {
  f.compensator = read_controller_matrices(s.section("compensator"), structure);
  if (tuning::is_position_controller(structure)) read_prefilter(s, f);
  f.controller_poles = read_poles(s, "controller_poles");
  check_poles(s, "controller_poles", f.controller_poles, f.compensator.A);
  f.controller_stable = s.boolean("controller_stable");
  if (f.controller_stable != tuning::stable_except_integrator(f.controller_poles))
    s.fail("controller_stable", std::string("contradicts controller_poles (they say ") +
                                    (f.controller_stable ? "unstable" : "stable") + ")");
}

/// The C7.16 members of the hinf section (absent in files of 2026-11-24 and before: a full-order
/// first-mode design is assumed then).
void read_reduction(const Section& s, Eigen::Index states, tuning::HinfSummary& h) {
  h.full_order = static_cast<int>(states);
  if (!s.value.contains("modes")) return;
  const std::string modes = s.object.string("modes");
  const std::optional<tuning::ModeHandling> m = tuning::parse_mode_handling(modes);
  if (!m) s.fail("modes", "expected \"first\", \"passive\" or \"active\", got \"" + modes + "\"");
  h.modes = *m;
  const double full = s.positive("full_order", "a number of states");
  if (full != std::floor(full) || full < static_cast<double>(states) || full > 1e4)
    s.fail("full_order", "expected a whole number of states >= the compensator's " + std::to_string(states) + ", got " +
                             show(full));
  h.full_order = static_cast<int>(full);
  h.hankel = read_numbers(s, "hankel_singular_values");
  for (std::size_t i = 0; i < h.hankel.size(); ++i) {
    if (!(h.hankel[i] >= 0.0) || (i > 0 && h.hankel[i] > h.hankel[i - 1] * (1.0 + 1e-12)))
      s.fail("hankel_singular_values[" + std::to_string(i) + "]", "expected non-negative values in descending order");
  }
  h.reduction_error_bound = s.non_negative("reduction_error_bound", "an error bound");
}

/// The "hinf" section: the compensator, its weights and gamma for hinf; null otherwise.
std::optional<tuning::FullOrderSummary> read_hinf(const Section& root, Structure structure) {
  if (!section_present(root, "hinf", tuning::is_hinf(structure), "hinf and hinf-pos", structure)) return std::nullopt;
  const Section s = root.section("hinf");
  std::vector<std::string_view> members{"omega_0s", "omega_0s_source", "omega_0t", "xi_v", "gamma_optimal", "gamma", "modes",
                                        "full_order", "hankel_singular_values", "reduction_error_bound",
                                        "controller_stable", "controller_poles", "compensator", "rolloff"};
  if (tuning::is_position_controller(structure)) members.emplace_back("prefilter_tau");
  s.object.allow_only(members);
  tuning::FullOrderSummary f;
  tuning::HinfSummary h;
  h.omega_0s = s.positive("omega_0s", "a normalized frequency w0S");
  h.omega_0s_source = s.object.string("omega_0s_source");
  h.omega_0t = s.positive("omega_0t", "a normalized frequency w0T");
  h.xi_v = s.positive("xi_v", "a damping ratio");
  h.gamma_optimal = s.positive("gamma_optimal", "an H-infinity norm");
  h.gamma = s.positive("gamma", "an H-infinity norm");
  if (h.gamma < h.gamma_optimal * (1.0 - 1e-9)) s.fail("gamma", "is below gamma_optimal");
  read_compensator(s, f, structure);
  if (s.value.contains("rolloff")) {  // absent in files of 2026-11-25 and before: no roll-off
    h.rolloff = s.nullable("rolloff");
    if (h.rolloff && !(*h.rolloff > 0.0)) s.fail("rolloff", "expected a normalized corner frequency > 0 or null, got " + show(*h.rolloff));
  }
  read_reduction(s, f.compensator.states(), h);
  f.hinf = h;
  return f;
}

/// The lqg-pos "lqg" section: the position weights of C7.13, the prefilter and the compensator.
tuning::FullOrderSummary read_position_lqg(const Section& s, Structure structure) {
  s.object.allow_only({"kbw", "kbw_source", "feedforward_source", "q", "process_noise", "measurement_noise",
                       "prefilter_tau", "controller_stable", "controller_poles", "compensator"});
  tuning::FullOrderSummary f;
  tuning::PositionLqgOptions w;
  w.kbw = s.positive("kbw", "a bandwidth knob");
  f.kbw_source = s.object.string("kbw_source");
  f.feedforward_source = s.object.string("feedforward_source");
  const std::vector<double> q = read_numbers(s, "q");
  if (q.size() != static_cast<std::size_t>(w.q.size()))
    s.fail("q", "expected the 5 state weights of [phi_m, w_m, phi_l, w_l, xi], got " + std::to_string(q.size()));
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (!(q[i] >= 0.0)) s.fail("q[" + std::to_string(i) + "]", "expected a state weight >= 0, got " + show(q[i]));
    w.q(static_cast<Eigen::Index>(i)) = q[i];
  }
  w.process_noise = s.positive("process_noise", "a noise intensity");
  w.measurement_noise = s.positive("measurement_noise", "a noise intensity");
  f.position_weights = w;
  read_compensator(s, f, structure);
  return f;
}

/// The "lqg" section: null for the cascade structures, the compensator and its weights for lqg,
/// lqg+p, lqg-pos and lqg-load.
std::optional<tuning::FullOrderSummary> read_lqg(const Section& root, Structure structure) {
  if (!section_present(root, "lqg", tuning::is_lqg(structure), "lqg, lqg+p, lqg-pos and lqg-load", structure))
    return std::nullopt;
  const Section s = root.section("lqg");
  if (structure == Structure::kLqgPos) return read_position_lqg(s, structure);
  s.object.allow_only({"kbw", "kbw_source", "feedforward", "feedforward_source", "q_load_velocity", "q_integral",
                       "noise_motor", "noise_load_torque", "measurement_noise", "raw_motor_velocity",
                       "controller_stable", "controller_poles", "compensator"});
  tuning::FullOrderSummary f;
  tuning::VelocityLqgOptions& w = f.weights;
  w.kbw = s.positive("kbw", "a bandwidth knob");
  f.kbw_source = s.object.string("kbw_source");
  w.feedforward = s.non_negative("feedforward", "a feedforward gain");
  f.feedforward_source = s.object.string("feedforward_source");
  w.q_load_velocity = s.non_negative("q_load_velocity", "a state weight");
  w.q_integral = s.non_negative("q_integral", "a state weight");
  w.noise_motor = s.non_negative("noise_motor", "a noise intensity");
  w.noise_load_torque = s.non_negative("noise_load_torque", "a noise intensity");
  w.measurement_noise = s.positive("measurement_noise", "a noise intensity");
  w.raw_motor_velocity = s.boolean("raw_motor_velocity");
  if (w.raw_motor_velocity && tuning::measures_both(structure))
    s.fail("raw_motor_velocity", "expected false: the load-side LQG (C7.17) regulates the estimated motor velocity");
  read_compensator(s, f, structure);
  return f;
}

std::vector<std::string> read_notes(const Section& root) {
  const json& notes = root.raw("notes");
  if (!notes.is_array()) root.fail("notes", std::string("expected an array of strings, found ") + notes.type_name());
  std::vector<std::string> out;
  for (std::size_t i = 0; i < notes.size(); ++i) {
    if (!notes[i].is_string())
      root.fail("notes[" + std::to_string(i) + "]", "expected a string, found " + notes[i].dump());
    out.push_back(notes[i].get<std::string>());
  }
  return out;
}

}  // namespace

json controller_to_json(const tuning::Controller& c, std::string_view plant_source) {
  const bool position = tuning::has_position_loop(c.structure);
  if (position != c.kpp_physical.has_value() || position != c.kpp_normalized.has_value())
    throw std::invalid_argument("controller_to_json: a position gain kpp belongs to exactly the pi+p and lqg+p controllers");
  if (position != c.position.has_value())
    throw std::invalid_argument("controller_to_json: the position-loop summary belongs to exactly the pi+p and lqg+p controllers");
  const bool full_order = tuning::is_full_order(c.structure);
  if (full_order != c.full_order.has_value())
    throw std::invalid_argument("controller_to_json: the compensator section belongs to exactly the full-order controllers");
  if (tuning::is_hinf(c.structure) != (c.full_order && c.full_order->hinf.has_value()))
    throw std::invalid_argument("controller_to_json: the H-infinity summary belongs to exactly the hinf and hinf-pos controllers");
  if (!c.drive_filters.empty() && full_order)
    throw std::invalid_argument("controller_to_json: drive filters belong to the pi, pid and pi+p controllers");
  if ((c.structure == Structure::kLqgPos) != (c.full_order && c.full_order->position_weights.has_value()))
    throw std::invalid_argument("controller_to_json: the position-LQG weights belong to exactly the lqg-pos controllers");
  const double wz = finite(c.plant.omega_z, "plant.omega_z");
  const tuning::PlantScales& p = c.plant;
  const core::StateSpace ss = tuning::controller_state_space(c);
  json discrete = nullptr;
  if (c.discrete) {
    const core::DiscreteStateSpace& d = *c.discrete;
    discrete = {
        {"ts", finite(d.ts, "discrete.ts")},
        {"method", "tustin"},
        {"prewarp_hz", c.prewarp_rad_s ? json(finite(*c.prewarp_rad_s, "prewarp_rad_s") / kTwoPi) : json(nullptr)},
        {"A", matrix_json(d.A, "discrete.A")},
        {"B", matrix_json(d.B, "discrete.B")},
        {"C", matrix_json(d.C, "discrete.C")},
        {"D", matrix_json(d.D, "discrete.D")}};
  }
  const tuning::DesignParameters& d = c.design;
  return {{"format", kControllerFormat},
          {"structure", to_string(c.structure)},
          {"loop", loop_name(c.structure)},
          {"feedback", feedback_name(c.structure)},
          {"plant",
           {{"source", std::string(plant_source)},
            {"omega_z_hz", wz / kTwoPi},
            {"motor_inertia", finite(p.motor_inertia, "plant.motor_inertia")},
            {"r", finite(p.r, "plant.r")},
            {"zeta_z", finite(p.zeta_z, "plant.zeta_z")},
            {"zeta_p", finite(p.zeta_p, "plant.zeta_p")},
            {"a", finite(p.a, "plant.a")}}},
          {"gains", full_order ? json(nullptr) : gains_json(c.physical, c.kpp_physical, "gains")},
          {"normalized", full_order ? json(nullptr) : gains_json(c.normalized, c.kpp_normalized, "normalized")},
          {"drive_filters", detail::drive_filters_json(c.drive_filters)},
          {"state_space", state_space_json(ss, "state_space", c.structure)},
          {"discrete", discrete},
          {"design",
           {{"omega_star", full_order ? json(nullptr) : json(finite(d.omega_star, "design.omega_star"))},
            {"omega_star_hz", full_order ? json(nullptr) : json(d.omega_star * wz / kTwoPi)},
            {"zeta_star", full_order ? json(nullptr) : json(finite(d.zeta_star, "design.zeta_star"))},
            {"r_target", optional_finite(d.r_target, "design.r_target")},
            {"ms", optional_finite(d.ms, "design.ms")},
            {"mt", optional_finite(d.mt, "design.mt")},
            {"min_damping", optional_finite(d.min_damping, "design.min_damping")},
            {"omega_star_source", d.omega_star_source}}},
          {"predicted", predicted_json(c.predicted, wz)},
          {"robustness", robustness_json(c.robustness)},
          {"position", position_json(c, wz)},
          {"lqg", lqg_json(c.full_order, c.structure)},
          {"hinf", hinf_json(c.full_order, c.structure)},
          {"notes", c.notes}};
}

LoadedController parse_controller_json(std::string_view text, std::string_view source_name) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kControllerFormat, source_name);
  const Section root(document, "", source_name);
  root.object.allow_only({"format", "structure", "loop", "feedback", "plant", "gains", "normalized", "drive_filters",
                          "state_space", "discrete", "design", "predicted", "robustness", "position", "lqg", "hinf", "notes"});
  LoadedController out;
  tuning::Controller& c = out.controller;

  const std::string structure = root.object.string("structure");
  const auto parsed = tuning::structure_from_string(structure);
  if (!parsed)
    root.fail("structure", "expected \"pi\", \"pid\", \"pi+p\", \"lqg\", \"lqg+p\", \"hinf\", \"lqg-pos\", \"hinf-pos\", \"hinf-load\" or \"lqg-load\", got \"" +
                               structure + "\"");
  c.structure = *parsed;
  const std::string loop = root.object.string("loop");
  if (loop != "velocity" && loop != "position")
    root.fail("loop", "expected \"velocity\" or \"position\", got \"" + loop + "\"");
  if (loop != loop_name(c.structure))
    root.fail("loop", "a \"" + structure + "\" controller closes the " + loop_name(c.structure) + " loop, got \"" +
                          loop + "\"");
  root.expect_string("feedback", feedback_name(c.structure));

  c.plant = read_plant(root.section("plant"), out.plant_source);
  if (tuning::is_full_order(c.structure)) {
    for (const char* key : {"gains", "normalized"}) {
      if (!root.raw(key).is_null())
        root.fail(key, "expected null for an \"" + structure + "\" controller (its law is the compensator)");
    }
  }
  c.full_order = read_lqg(root, c.structure);
  if (auto hinf = read_hinf(root, c.structure)) c.full_order = std::move(hinf);
  if (!c.full_order) {
    const Section gains = root.section("gains");
    const GainsRead physical = read_gains(gains, c.structure);
    const GainsRead normalized = read_gains(root.section("normalized"), c.structure);
    check_gains_agree(gains, physical, normalized, c.plant);
    c.physical = physical.gains;
    c.normalized = normalized.gains;
    c.kpp_physical = physical.kpp;
    c.kpp_normalized = normalized.kpp;
  }
  std::optional<double> controller_ts;
  if (const auto d = document.find("discrete"); d != document.end() && d->is_object() && d->contains("ts") &&
                                                d->at("ts").is_number())
    controller_ts = d->at("ts").get<double>();
  c.drive_filters = detail::read_drive_filters(document, root.object, "drive_filters", controller_ts);
  if (!c.drive_filters.empty() && tuning::is_full_order(c.structure))
    root.fail("drive_filters", "expected none for an \"" + structure + "\" controller (its compensator holds its filters)");
  read_state_space(root, tuning::controller_state_space(c), continuous_check_frequencies(c.plant.omega_z, c.physical),
                   c.structure);
  c.discrete = read_discrete(root, c, c.prewarp_rad_s);
  c.design = read_design(root.section("design"), c.plant.omega_z, c.structure);
  c.predicted = read_predicted(root.section("predicted"), c.plant.omega_z);
  c.robustness = read_robustness(root.section("robustness"));
  read_position(root, c);
  c.notes = read_notes(root);
  return out;
}

LoadedController load_controller(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the controller file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_controller_json(text.str(), path);
}

}  // namespace servotwin::io
