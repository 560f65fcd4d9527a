#include "servotwin/io/rapid_json.hpp"

#include <cmath>
#include <numbers>

#include "json_reader.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/program_file.hpp"

namespace servotwin::io {

namespace {

using detail::JsonObject;
using nlohmann::json;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// JSON has no NaN or infinity: such values are written as null.
json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json modal_list(const std::vector<core::ModalInfo>& roots) {
  json list = json::array();
  for (const auto& m : roots)
    list.push_back({{"hz", number_or_null(m.freq_hz)}, {"zeta", number_or_null(m.zeta)}, {"re", m.root.real()},
                    {"im", m.root.imag()}});
  return list;
}

json fit_to_json(const rapid::FitMetrics& f) {
  json j = {{"rms", f.rms_difference},          {"nrmse", number_or_null(f.nrmse)}, {"max", f.max_difference},
            {"rms_measured", f.rms_measured}, {"rms_predicted", f.rms_predicted}};
  if (f.reading_quantum > 0.0) {
    j["reading_quantum"] = f.reading_quantum;
    j["quantization_floor"] = f.quantization_floor;
  }
  if (f.diverged) j["diverged_at_sample"] = f.diverged_at;
  return j;
}

double read_element(const json& v, const std::string& field, std::string_view source) {
  if (!v.is_number()) throw core::InputError({std::string(source), 0, 0, field}, std::string("expected a number, found ") + v.type_name());
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw core::InputError({std::string(source), 0, 0, field}, "expected a finite number");
  return x;
}

const json& sized_array(const json& v, std::size_t size, const std::string& field, std::string_view source) {
  if (!v.is_array() || v.size() != size)
    throw core::InputError({std::string(source), 0, 0, field},
                           "expected an array of " + std::to_string(size) + " elements");
  return v;
}

}  // namespace

json normal_equations_to_json(const rapid::NormalEquations& ne, const std::string& axis,
                              const std::vector<std::string>& sources, int command_shift) {
  json p = json::array();
  for (int i = 0; i < rapid::kParameterCount; ++i) {
    json row = json::array();
    for (int j = 0; j < rapid::kParameterCount; ++j) row.push_back(ne.P(i, j));
    p.push_back(row);
  }
  json r = json::array();
  for (int i = 0; i < rapid::kParameterCount; ++i) r.push_back(ne.R(i));
  json names = json::array();
  for (auto name : rapid::kRegressorNames) names.push_back(name);
  json doc = {{"format", kNormalEquationsFormat}, {"regressors", names}, {"P", p}, {"R", r},
              {"Gamma", ne.gamma},               {"N", ne.n},            {"Ts", ne.ts},
              {"command_shift", command_shift}};
  if (!axis.empty()) doc["axis"] = axis;
  if (!sources.empty()) doc["sources"] = sources;
  return doc;
}

rapid::NormalEquations parse_normal_equations_json(std::string_view text, std::string_view source_name,
                                                   std::string* axis, int* command_shift) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kNormalEquationsFormat, source_name);
  const JsonObject root(document, "", source_name);
  root.allow_only({"format", "regressors", "P", "R", "Gamma", "N", "Ts", "axis", "sources", "command_shift"});
  const json& names = sized_array(root.array("regressors"), rapid::kParameterCount, "regressors", source_name);
  for (int i = 0; i < rapid::kParameterCount; ++i) {
    const auto& expected = rapid::kRegressorNames[static_cast<std::size_t>(i)];
    if (!names[static_cast<std::size_t>(i)].is_string() || names[static_cast<std::size_t>(i)].get<std::string>() != expected)
      throw core::InputError({std::string(source_name), 0, 0, "regressors[" + std::to_string(i) + "]"},
                             "expected \"" + std::string(expected) +
                                 "\" (regressors must be e_i, -xdot, -xddot, x_r, xdot_r, xddot_r, -PV, -NV in this order)");
  }
  rapid::NormalEquations ne;
  const json& p = sized_array(root.array("P"), rapid::kParameterCount, "P", source_name);
  for (int i = 0; i < rapid::kParameterCount; ++i) {
    const std::string row_field = "P[" + std::to_string(i) + "]";
    const json& row = sized_array(p[static_cast<std::size_t>(i)], rapid::kParameterCount, row_field, source_name);
    for (int j = 0; j < rapid::kParameterCount; ++j)
      ne.P(i, j) = read_element(row[static_cast<std::size_t>(j)], row_field + "[" + std::to_string(j) + "]", source_name);
  }
  const json& r = sized_array(root.array("R"), rapid::kParameterCount, "R", source_name);
  for (int i = 0; i < rapid::kParameterCount; ++i)
    ne.R(i) = read_element(r[static_cast<std::size_t>(i)], "R[" + std::to_string(i) + "]", source_name);
  ne.gamma = root.number("Gamma");
  const double n = root.number("N");
  if (n < 1.0 || n != std::floor(n) || n > 9.0e15) root.fail("N", "expected a positive whole number of samples");
  ne.n = static_cast<std::uint64_t>(n);
  ne.ts = root.number("Ts");
  if (!(ne.ts > 0.0)) root.fail("Ts", "sample period must be > 0");
  if (axis != nullptr) *axis = root.string_or("axis", "");
  const double shift = root.number_or("command_shift", 0.0);
  if (shift != std::floor(shift) || std::abs(shift) > static_cast<double>(rapid::kMaxDelay))
    root.fail("command_shift", "expected a whole number of samples");
  if (command_shift != nullptr) *command_shift = static_cast<int>(shift);
  return ne;
}

LoadedStatistics load_statistics(const std::vector<std::string>& paths) {
  if (paths.empty()) throw core::InputError("no statistics files given");
  LoadedStatistics total;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const std::string& path = paths[i];
    std::string axis;
    int shift = 0;
    const rapid::NormalEquations ne = parse_normal_equations_json(read_text_file(path), path, &axis, &shift);
    if (i == 0) {
      total.axis = axis;
      total.command_shift = shift;
    } else if (axis != total.axis) {
      throw core::InputError({path, 0, 0, "axis"}, "statistics of axis '" + axis + "' cannot be added to those of axis '" +
                                                       total.axis + "' (" + paths.front() + ")");
    } else if (shift != total.command_shift) {
      throw core::InputError({path, 0, 0, "command_shift"},
                             "statistics built with command shift " + std::to_string(shift) +
                                 " cannot be added to those built with shift " + std::to_string(total.command_shift) +
                                 " (" + paths.front() + "): rebuild them with the same --shift");
    }
    try {
      std::vector<std::string> repairs;
      const auto one = rapid::RegressionProblem::from_normal_equations(ne, &repairs);
      for (const std::string& r : repairs) total.warnings.push_back(path + ": " + r);
      if (total.problem.empty()) total.problem = one;
      else total.problem.merge(one);
    } catch (const core::InputError& e) {
      throw core::InputError({path, 0, 0, e.where().field}, e.reason());
    }
  }
  return total;
}

namespace {

json coefficients_to_json(const rapid::ModelCoefficients& c) {
  return {{"a1", c.a1}, {"a2", c.a2}, {"a3", c.a3}, {"b0", c.b0}, {"b1", c.b1}, {"b2", c.b2}, {"d0", c.d0}, {"d1", c.d1}};
}

json search_to_json(double wn, double zeta, double p) {
  return {{"wn_hz", number_or_null(wn / kTwoPi)}, {"zeta", number_or_null(zeta)}, {"p_hz", number_or_null(p / kTwoPi)}};
}

json active_to_json(const std::vector<rapid::ActiveBound>& bounds) {
  json active = json::array();
  for (const auto& a : bounds) active.push_back({{"name", a.name}, {"multiplier", a.multiplier}});
  return active;
}

/// The solver's model and what the output-error refinement did (the refined model is "model").
json refinement_to_json(const vcnc::AxisIdentification& record) {
  const rapid::Refinement& f = *record.refinement;
  const rapid::Solution& s = record.solution;
  json doc = {{"method", "output-error"},
              {"solver_model", coefficients_to_json(s.coefficients)},
              {"solver_search", search_to_json(s.wn, s.zeta, s.p)},
              {"initial_cost", f.initial_cost},
              {"cost", f.cost},
              {"active_constraints", active_to_json(f.active)},
              {"iterations", f.iterations},
              {"simulations", f.simulations},
              {"converged", f.converged},
              {"stop_reason", f.stop_reason},
              {"time_ms", f.time_ms}};
  if (record.solver_fit) doc["solver_fit"] = fit_to_json(*record.solver_fit);
  if (record.solver_validation) doc["solver_validation"] = fit_to_json(*record.solver_validation);
  return doc;
}

}  // namespace

json axis_model_to_json(const vcnc::AxisIdentification& record) {
  const rapid::Solution& s = record.solution;
  const rapid::ModelCoefficients& c = record.coefficients();
  const rapid::AxisModel model(c, record.ts);
  json solver = {{"method", rapid::method_name(s.method)}, {"seed", nullptr}, {"time_ms", s.time_ms}};
  if (s.method == rapid::Method::Ga) {
    solver["seed"] = s.seed;
    json history = json::array();
    for (const auto& g : s.history)
      history.push_back({g.objective, g.p / kTwoPi, g.wn / kTwoPi, g.zeta});
    solver["history"] = {{"columns", {"objective", "p_hz", "wn_hz", "zeta"}}, {"rows", history}};
  }
  const rapid::Vector8 th = record.refinement ? rapid::theta_from_coefficients(c) : s.theta;
  const json search = record.refinement ? search_to_json(record.refinement->wn, record.refinement->zeta, record.refinement->p)
                                        : search_to_json(s.wn, s.zeta, s.p);
  json doc = {
      {"format", kAxisModelFormat},
      {"axis", record.axis},
      {"ts", record.ts},
      {"length_unit", record.length_unit},
      {"model", coefficients_to_json(c)},
      {"theta",
       {{"alpha_i", th(0)}, {"alpha_1", th(1)}, {"alpha_2", th(2)}, {"beta_0", th(3)}, {"beta_1", th(4)},
        {"beta_2", th(5)}, {"delta_pos", th(6)}, {"delta_neg", th(7)}}},
      {"search", search},
      {"poles", modal_list(model.poles())},
      {"zeros", modal_list(model.zeros())},
      {"stable", model.is_stable()},
      {"bandwidth_hz", number_or_null(model.bandwidth_hz())},
      {"bounds",
       {{"p_min_hz", record.bounds.p_min / kTwoPi},
        {"p_max_hz", record.bounds.p_max / kTwoPi},
        {"wn_min_hz", record.bounds.wn_min / kTwoPi},
        {"wn_max_hz", record.bounds.wn_max / kTwoPi},
        {"zeta_min", record.bounds.zeta_min},
        {"zeta_max", record.bounds.zeta_max}}},
      {"feasible", s.feasible},
      {"active_constraints", active_to_json(s.active)},
      {"kkt_case", s.kkt_case},
      {"objective", s.objective},
      {"lower_bound", number_or_null(s.lower_bound)},
      {"solver", solver},
      {"regressors",
       {{"command_shift", record.regressors.command_shift},
        {"trim_start", record.regressors.trim_start},
        {"trim_end", record.regressors.trim_end},
        {"velocity_deadband", record.regressors.velocity_deadband ? json(*record.regressors.velocity_deadband) : json(nullptr)}}},
      {"warnings", s.warnings},
      {"sources", record.sources}};
  if (!record.shift_trials.empty()) {
    json trials = json::array();
    // complete = false: the candidate's simulation stopped once it could not be chosen, and
    // nrmse is a lower bound.
    for (const auto& t : record.shift_trials)
      trials.push_back({{"shift", t.shift}, {"nrmse", t.nrmse}, {"stable", t.stable}, {"complete", t.complete}});
    doc["shift_search"] = trials;
  }
  if (record.refinement) doc["refinement"] = refinement_to_json(record);
  if (record.fit) doc["fit"] = fit_to_json(*record.fit);
  if (record.validation) doc["validation"] = fit_to_json(*record.validation);
  return doc;
}

LoadedAxisModel parse_axis_model_json(std::string_view text, std::string_view source_name) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kAxisModelFormat, source_name);
  const JsonObject root(document, "", source_name);
  // Every member axis_model_to_json writes; anything else is a misspelling (issue 27 §3).
  root.allow_only({"format", "axis", "ts", "length_unit", "model", "theta", "search", "poles", "zeros", "stable",
                   "bandwidth_hz", "bounds", "feasible", "active_constraints", "kkt_case", "objective", "lower_bound",
                   "solver", "regressors", "warnings", "sources", "shift_search", "refinement", "fit", "validation"});
  const JsonObject m = root.object("model");
  m.allow_only({"a1", "a2", "a3", "b0", "b1", "b2", "d0", "d1"});
  rapid::ModelCoefficients c;
  c.a1 = m.number("a1");
  c.a2 = m.number("a2");
  c.a3 = m.number("a3");
  c.b0 = m.number("b0");
  c.b1 = m.number("b1");
  c.b2 = m.number("b2");
  c.d0 = m.number("d0");
  c.d1 = m.number("d1");
  const double ts = root.number("ts");
  if (!(ts > 0.0)) root.fail("ts", "sample period must be > 0");
  const std::string axis = root.string("axis");
  if (axis.size() != 1 || std::string_view("xyzabc").find(axis.front()) == std::string_view::npos)
    root.fail("axis", "expected an axis name x, y, z, a, b or c, found " +
                          (axis.size() > 20 ? json(axis.substr(0, 20)).dump() + "... (" + std::to_string(axis.size()) + " characters)"
                                            : json(axis).dump()));
  std::string method;
  if (auto solver = root.optional_object("solver")) method = solver->string_or("method", "");
  int shift = 0;
  if (auto regressors = root.optional_object("regressors")) {
    const double value = regressors->number_or("command_shift", 0.0);
    if (value != std::round(value) || std::abs(value) > 1e6) regressors->fail("command_shift", "expected a whole number of samples");
    shift = static_cast<int>(value);
  }
  return {axis, rapid::AxisModel(c, ts), method, shift};
}

LoadedAxisModel load_axis_model(const std::string& path) { return parse_axis_model_json(read_text_file(path), path); }

}  // namespace servotwin::io
