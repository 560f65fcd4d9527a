#include "servotwin/io/plant_model_json.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "json_reader.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"

namespace servotwin::io {

namespace {

using nlohmann::json;
using detail::JsonObject;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// NaN (not identifiable) becomes null.
json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json coefficients(std::span<const double> c) { return json(std::vector<double>(c.begin(), c.end())); }

std::string model_type(std::size_t modes) {
  return modes == 0 ? "rigid" : modes == 1 ? "two-mass" : "multi-mode";
}

json physical_json(const fit::TwoMassParameters& p) {
  json j;
  const auto put = [&](const char* name, const fit::Estimate& e) {
    j[name] = e.value;
    j[std::string(name) + "_std"] = number_or_null(e.std);
  };
  put("motor_inertia", p.motor_inertia);
  put("load_inertia", p.load_inertia);
  put("stiffness", p.stiffness);
  put("damping", p.damping);
  put("resonance_ratio", p.resonance_ratio);
  j["damping_consistency"] = p.damping_consistency;
  return j;
}

/// Coefficient lists agree within 1e-6 of the largest coefficient magnitude.
bool agree(std::span<const double> expected, const json& given) {
  if (given.size() != expected.size()) return false;
  double scale = 0.0;
  for (double v : expected) scale = std::max(scale, std::abs(v));
  for (std::size_t i = 0; i < expected.size(); ++i)
    if (!given[i].is_number() || std::abs(given[i].get<double>() - expected[i]) > 1e-6 * scale) return false;
  return true;
}

double positive(const JsonObject& o, std::string_view key) {
  const double v = o.number(key);
  if (!(v > 0.0)) o.fail(key, "expected a value > 0");
  return v;
}

json nonlinear_json(const fit::NonlinearMechanics& n) {
  json runs = json::array();
  for (const auto& r : n.backlash.runs)
    runs.push_back({{"amplitude", r.amplitude},
                    {"antiresonance_hz", r.antiresonance_hz},
                    {"antiresonance_hz_std", number_or_null(r.antiresonance_hz_std)},
                    {"effective_stiffness", r.effective_stiffness},
                    {"twist_amplitude", r.twist_amplitude}});
  return {{"coulomb",
           {{"estimated", n.coulomb.estimated}, {"level", n.coulomb.level}, {"level_std", number_or_null(n.coulomb.level_std)},
            {"significant", n.coulomb.significant}, {"frequencies", n.coulomb.frequencies},
            {"points", n.coulomb.points}, {"note", n.coulomb.note}}},
          {"backlash",
           {{"estimated", n.backlash.estimated}, {"significant", n.backlash.significant}, {"width", n.backlash.width},
            {"stiffness", n.backlash.stiffness}, {"note", n.backlash.note}, {"runs", runs}}}};
}

json friction_json(const fit::CoulombFit& c) {
  const auto values = [](const std::vector<fit::Estimate>& v, bool std) {
    json a = json::array();
    for (const fit::Estimate& e : v) a.push_back(std ? number_or_null(e.std) : json(e.value));
    return a;
  };
  const std::size_t masses = c.inertias.size();
  return {{"model", masses <= 2 ? std::string("two-mass, Coulomb on motor and load")
                                : std::to_string(masses) + "-mass chain, Coulomb on motor and load (motor first)"},
          {"inertias", values(c.inertias, false)},
          {"inertias_std", values(c.inertias, true)},
          {"stiffnesses", values(c.stiffnesses, false)},
          {"stiffnesses_std", values(c.stiffnesses, true)},
          {"shaft_dampings", values(c.shaft_dampings, false)},
          {"shaft_dampings_std", values(c.shaft_dampings, true)},
          {"motor_coulomb", c.motor_coulomb.value},
          {"motor_coulomb_std", number_or_null(c.motor_coulomb.std)},
          {"load_coulomb", c.load_coulomb.value},
          {"load_coulomb_std", number_or_null(c.load_coulomb.std)},
          {"viscous_damping", c.viscous_damping.value},
          {"viscous_damping_std", number_or_null(c.viscous_damping.std)},
          {"total_inertia", c.total_inertia.value},
          {"total_inertia_std", number_or_null(c.total_inertia.std)},
          {"motor_share", c.motor_share.value},
          {"motor_share_std", number_or_null(c.motor_share.std)},
          {"residual", c.rms_log_error},
          {"linear_residual", c.linear_rms_log_error},
          {"note", c.note}};
}

}  // namespace

json plant_model_to_json(const fit::FitReport& report, const fit::NonlinearMechanics* nonlinear,
                         const fit::CoulombFit* friction) {
  const fit::FitResult& f = report.result;
  const fit::PlantModel& m = f.model;
  const core::TransferFunction tf = m.transfer_function();
  json model = {{"type", model_type(m.modes.size())},
                {"output", fit::to_string(m.output)},
                {"rigid", fit::to_string(m.rigid)},
                {"sensor", fit::to_string(m.sensor)},
                {"gain", m.gain},
                {"gain_std", number_or_null(f.gain.std)}};
  const bool pole = m.rigid == fit::RigidKind::kRealPole;
  model["rigid_pole_hz"] = pole ? json(m.rigid_pole_rad_s / kTwoPi) : json(nullptr);
  model["rigid_pole_hz_std"] = pole ? number_or_null(f.rigid_pole_rad_s.std / kTwoPi) : json(nullptr);
  model["lag_pole_hz"] = m.lag_pole_rad_s ? json(*m.lag_pole_rad_s / kTwoPi) : json(nullptr);
  model["lag_pole_hz_std"] = m.lag_pole_rad_s ? number_or_null(f.lag_pole_rad_s.std / kTwoPi) : json(nullptr);
  model["delay_s"] = m.delay_s ? json(*m.delay_s) : json(nullptr);
  model["delay_s_std"] = m.delay_s ? number_or_null(f.delay_s.std) : json(nullptr);
  model["numerator"] = coefficients(tf.num().coefficients());
  model["denominator"] = coefficients(tf.den().coefficients());

  json modes = json::array();
  for (std::size_t i = 0; i < m.modes.size(); ++i) {
    const fit::ModeUncertainty& u = f.mode_estimates[i];
    const auto entry = [&](const char* kind, const fit::ModalPair& p, const fit::Estimate& w, const fit::Estimate& z) {
      return json{{"mode", i + 1},         {"kind", kind},
                  {"freq_hz", p.omega_rad_s / kTwoPi}, {"zeta", p.zeta},
                  {"freq_hz_std", number_or_null(w.std / kTwoPi)}, {"zeta_std", number_or_null(z.std)}};
    };
    if (m.sensor == fit::SensorSide::kMotor)
      modes.push_back(entry("antiresonance", m.modes[i].antiresonance, u.antiresonance_omega, u.antiresonance_zeta));
    modes.push_back(entry("resonance", m.modes[i].resonance, u.resonance_omega, u.resonance_zeta));
  }

  json candidates = json::array();
  for (const auto& c : report.selection.candidates)
    candidates.push_back({{"modes", c.modes}, {"parameters", c.parameters}, {"converged", c.converged},
                          {"cost", number_or_null(c.cost)}, {"score", number_or_null(c.score)}});
  json document{
      {"format", kPlantModelFormat},
      {"model", model},
      {"modes", modes},
      {"physical", f.physical.parameters ? physical_json(*f.physical.parameters) : json(nullptr)},
      {"physical_note", f.physical.note},
      {"fit",
       {{"converged", f.converged}, {"message", f.message}, {"initialization", f.initialization},
        {"weighting", f.weighting}, {"points", f.points}, {"parameters", f.parameters}, {"iterations", f.iterations},
        {"cost", f.cost}, {"residual", f.rms_log_error}, {"sigma2", number_or_null(f.sigma2)},
        {"uncertainty_scale", f.uncertainty_scale}, {"uncertainty_note", f.uncertainty_note},
        {"left_out", report.left_out}}},
      {"selection",
       {{"method", report.selection.method},
        {"criterion", report.selection.criterion},
        {"chosen_modes", report.selection.chosen},
        {"candidates", candidates},
        {"output_detection",
         {{"output", fit::to_string(report.output.output)},
          {"detected", report.output.detected},
          {"slope_db_per_decade", number_or_null(report.output.slope_db_per_decade)},
          {"note", report.output.note}}}}}};
  if (nonlinear) document["nonlinear"] = nonlinear_json(*nonlinear);
  if (friction) document["friction"] = friction_json(*friction);
  return document;
}

LoadedPlantModel parse_plant_model_json(std::string_view text, std::string_view source_name) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kPlantModelFormat, source_name);
  const JsonObject root(document, "", source_name);
  root.allow_only({"format", "model", "modes", "physical", "physical_note", "fit", "selection", "nonlinear", "friction"});
  const JsonObject m = root.object("model");
  m.allow_only({"type", "output", "rigid", "sensor", "gain", "gain_std", "rigid_pole_hz", "rigid_pole_hz_std", "lag_pole_hz",
                "lag_pole_hz_std", "delay_s", "delay_s_std", "numerator", "denominator"});
  LoadedPlantModel out;
  fit::PlantModel& model = out.model;
  const std::string output = m.string("output");
  if (output != "velocity" && output != "position") m.fail("output", "expected \"velocity\" or \"position\", got \"" + output + "\"");
  model.output = output == "velocity" ? fit::OutputKind::kVelocity : fit::OutputKind::kPosition;
  const std::string rigid = m.string("rigid");
  if (rigid != "pole" && rigid != "integrator") m.fail("rigid", "expected \"pole\" or \"integrator\", got \"" + rigid + "\"");
  model.rigid = rigid == "pole" ? fit::RigidKind::kRealPole : fit::RigidKind::kIntegrator;
  const std::string sensor = m.string_or("sensor", "motor");
  if (sensor != "motor" && sensor != "load") m.fail("sensor", "expected \"motor\" or \"load\", got \"" + sensor + "\"");
  model.sensor = sensor == "motor" ? fit::SensorSide::kMotor : fit::SensorSide::kLoad;
  const bool load = model.sensor == fit::SensorSide::kLoad;
  model.gain = m.number("gain");
  if (model.gain == 0.0) m.fail("gain", "expected a non-zero gain");
  if (model.rigid == fit::RigidKind::kRealPole) model.rigid_pole_rad_s = kTwoPi * positive(m, "rigid_pole_hz");
  if (const auto lag = m.optional_number("lag_pole_hz")) {
    if (!(*lag > 0.0)) m.fail("lag_pole_hz", "expected a value > 0 or null");
    model.lag_pole_rad_s = kTwoPi * *lag;
  }
  if (const auto delay = m.optional_number("delay_s")) {
    if (!(*delay >= 0.0)) m.fail("delay_s", "expected a value >= 0 or null");
    model.delay_s = *delay;
  }

  // Not JsonObject::array: a rigid-body model has an empty list of modes.
  if (!document.contains("modes")) root.fail("modes", "missing required field");
  const json& modes = document["modes"];
  if (!modes.is_array()) root.fail("modes", "expected an array");
  // A motor-side mode is an antiresonance entry and a resonance entry, a load-side one a resonance.
  const std::size_t per_mode = load ? 1 : 2;
  if (modes.size() % per_mode != 0) root.fail("modes", "expected an antiresonance and a resonance entry per mode");
  for (std::size_t i = 0; i < modes.size(); i += per_mode) {
    fit::Mode mode;
    for (std::size_t k = 0; k < per_mode; ++k) {
      const JsonObject e(modes[i + k], "modes[" + std::to_string(i + k) + "]", source_name);
      e.allow_only({"mode", "kind", "freq_hz", "zeta", "freq_hz_std", "zeta_std"});
      const std::string kind = e.string("kind");
      const bool zeros = !load && k == 0;
      const char* expected = zeros ? "antiresonance" : "resonance";
      if (kind != expected)
        e.fail("kind", std::string("expected \"") + expected + "\" " +
                           (load ? "(a load-side model has resonances only)" : "(entries alternate antiresonance, resonance)") +
                           ", got \"" + kind + "\"");
      const int number = e.integer_or("mode", static_cast<int>(i / per_mode + 1));
      if (number != static_cast<int>(i / per_mode + 1)) e.fail("mode", "expected mode " + std::to_string(i / per_mode + 1));
      fit::ModalPair& p = zeros ? mode.antiresonance : mode.resonance;
      p.omega_rad_s = kTwoPi * positive(e, "freq_hz");
      p.zeta = positive(e, "zeta");
    }
    model.modes.push_back(mode);
  }

  const core::TransferFunction tf = model.transfer_function();
  for (const char* key : {"numerator", "denominator"}) {
    if (!m.has(key)) continue;
    const json& given = m.array(key);
    const auto expected = std::string(key) == "numerator" ? tf.num().coefficients() : tf.den().coefficients();
    if (!agree(expected, given))
      m.fail(key, "does not match the gain, poles and modes of the file (expected " + std::to_string(expected.size()) +
                      " coefficients within 1e-6 relative)");
  }

  if (document.contains("physical") && !document.at("physical").is_null()) {
    const JsonObject p = root.object("physical");
    const auto read = [&](const char* name) {
      return fit::Estimate{p.number(name), p.optional_number(std::string(name) + "_std").value_or(std::nan(""))};
    };
    fit::TwoMassParameters t;
    t.motor_inertia = read("motor_inertia");
    t.load_inertia = read("load_inertia");
    t.stiffness = read("stiffness");
    t.damping = read("damping");
    t.resonance_ratio = read("resonance_ratio");
    t.damping_consistency = p.number_or("damping_consistency", std::nan(""));
    out.physical = t;
  }
  out.physical_note = root.string_or("physical_note", "");
  return out;
}

LoadedPlantModel load_plant_model(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the plant-model file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_plant_model_json(text.str(), path);
}

bool is_plant_model_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  return !j.is_discarded() && j.is_object() && j.contains("format") && j["format"].is_string() &&
         j["format"].get<std::string>() == kPlantModelFormat;
}

}  // namespace servotwin::io
