#include "servotwin/vcnc/identification.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "servotwin/core/error.hpp"
#include "servotwin/core/parallel.hpp"

namespace servotwin::vcnc {

namespace {

const core::AxisTrace& require_axis(const NamedCapture& c, const std::string& axis) {
  const core::AxisTrace* trace = c.capture.find(axis);
  if (trace == nullptr) {
    std::string names;
    for (const auto& a : c.capture.axes) names += (names.empty() ? "" : ", ") + a.name;
    throw core::InputError({c.source, 0, 0, "--axis"}, "no axis '" + axis + "' in this capture (axes: " + names + ")");
  }
  return *trace;
}

}  // namespace

rapid::Bounds complete_bounds(rapid::Bounds bounds, double ts) {
  const rapid::Bounds d = rapid::default_bounds(ts);
  if (bounds.p_min == 0.0) bounds.p_min = d.p_min;
  if (bounds.p_max == 0.0) bounds.p_max = d.p_max;
  if (bounds.wn_min == 0.0) bounds.wn_min = d.wn_min;
  if (bounds.wn_max == 0.0) bounds.wn_max = d.wn_max;
  rapid::validate(bounds);
  return bounds;
}

rapid::RegressionProblem axis_problem(const std::vector<NamedCapture>& captures, const std::string& axis,
                                      const rapid::RegressorOptions& options, std::vector<std::string>& warnings) {
  rapid::RegressionProblem total;
  double command_range = 0.0, actual_range = 0.0;
  for (const auto& c : captures) {
    const core::AxisTrace& trace = require_axis(c, axis);
    rapid::RegressionDiagnostics diagnostics;
    rapid::RegressionProblem one;
    try {
      one = rapid::build_problem(trace.cmd, trace.act, c.capture.ts, options, &diagnostics);
    } catch (const core::InputError& e) {
      throw core::InputError({c.source, 0, 0, e.where().field}, e.reason());
    }
    for (const auto& w : diagnostics.warnings) warnings.push_back(c.source + ": " + w);
    command_range = std::max(command_range, diagnostics.command_range);
    actual_range = std::max(actual_range, diagnostics.actual_range);
    if (total.empty()) {
      total = one;
      continue;
    }
    try {
      total.merge(one);
    } catch (const core::InputError& e) {
      throw core::InputError({c.source, 0, 0, "t"}, e.reason());
    }
  }
  // A model fitted to no motion would be all noise: refuse rather than write it.
  const std::string names = captures.size() == 1 ? captures.front().source : std::to_string(captures.size()) + " captures";
  if (command_range == 0.0) {
    throw core::InputError({names, 0, 0, axis + "_cmd"}, "the command of axis '" + axis +
                                                           "' never moves: nothing to identify (capture an identification program, "
                                                           "see `servotwin gcode identification`)");
  }
  if (actual_range == 0.0) {
    throw core::InputError({names, 0, 0, axis + "_act"},
                           "the actual position of axis '" + axis + "' never changes although the command moves: is the "
                                                                    "right column mapped (--map " + axis + "_act=...)?");
  }
  return total;
}

rapid::FitMetrics simulated_fit(const rapid::AxisModel& model, const std::vector<NamedCapture>& captures,
                                const std::string& axis, int command_shift, double give_up_above) {
  std::vector<rapid::TrackingRecord> records;
  records.reserve(captures.size());
  for (const auto& c : captures) {
    const core::AxisTrace& trace = require_axis(c, axis);
    records.push_back({trace.cmd, trace.act});
  }
  rapid::ModelSimulationOptions options;
  options.command_shift = command_shift;
  return rapid::simulation_fit(model, records, options, give_up_above);
}

namespace {

/// The encoder count the captures' actual positions share, 0 when any has none or they differ.
double captures_quantum(const std::vector<NamedCapture>& captures, const std::string& axis) {
  double common = 0.0;
  for (const auto& c : captures) {
    const double q = rapid::reading_quantum(require_axis(c, axis).act);
    if (q == 0.0 || (common != 0.0 && std::abs(q - common) > 1e-9 * common)) return 0.0;
    common = q;
  }
  return common;
}

/// The solver's model with the shift in settings.regressors, without its simulated fit.
AxisIdentification solve_with_shift(const std::vector<NamedCapture>& captures, const std::string& axis,
                                    const IdentificationSettings& settings, const rapid::Bounds& bounds) {
  AxisIdentification result;
  result.axis = axis;
  result.ts = captures.front().capture.ts;
  result.bounds = bounds;
  result.regressors = settings.regressors;
  std::vector<std::string> warnings;
  const rapid::RegressionProblem problem = axis_problem(captures, axis, settings.regressors, warnings);
  result.solution = rapid::solve(problem, settings.method, result.bounds, settings.solve);
  result.solution.warnings.insert(result.solution.warnings.begin(), warnings.begin(), warnings.end());
  return result;
}

/// Identification with the shift in settings.regressors.
AxisIdentification identify_with_shift(const std::vector<NamedCapture>& captures, const std::string& axis,
                                       const IdentificationSettings& settings, const rapid::Bounds& bounds) {
  AxisIdentification result = solve_with_shift(captures, axis, settings, bounds);
  result.fit = simulated_fit(rapid::AxisModel(result.solution.coefficients, result.ts), captures, axis,
                             settings.regressors.command_shift);
  return result;
}

/// Simulated fits of the shift candidates, the likely winners first (a stable model when there is
/// one, then by |shift|), each simulation stopped once its candidate can no longer be chosen: its
/// nrmse already above (1 + kShiftFitTolerance) times the best complete one of the class that
/// choose_shift picks from. That best only falls as candidates complete, so every candidate within
/// the tolerance of the final best runs to the end, and choose_shift decides as on complete fits
/// (issue 26: a chattering candidate at shift -3 took 4.7 s of a 6.3 s identification).
std::vector<ShiftTrial> fit_shift_candidates(std::vector<AxisIdentification>& candidates,
                                             const std::vector<NamedCapture>& captures, const std::string& axis,
                                             const std::vector<int>& shifts) {
  std::vector<ShiftTrial> trials(candidates.size());
  std::vector<std::size_t> order(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    trials[i].shift = shifts[i];
    trials[i].stable = rapid::AxisModel(candidates[i].solution.coefficients, candidates[i].ts).is_stable();
    order[i] = i;
  }
  const bool any_stable = std::any_of(trials.begin(), trials.end(), [](const ShiftTrial& t) { return t.stable; });
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const bool in_a = trials[a].stable == any_stable, in_b = trials[b].stable == any_stable;
    if (in_a != in_b) return in_a;
    return std::abs(trials[a].shift) < std::abs(trials[b].shift);
  });
  double best = std::numeric_limits<double>::infinity();
  for (const std::size_t i : order) {
    AxisIdentification& c = candidates[i];
    c.fit = simulated_fit(rapid::AxisModel(c.solution.coefficients, c.ts), captures, axis, shifts[i],
                          best * (1.0 + kShiftFitTolerance));
    trials[i].nrmse = c.fit->nrmse;
    trials[i].complete = c.fit->complete;
    if (c.fit->complete && trials[i].stable == any_stable) best = std::min(best, c.fit->nrmse);
  }
  return trials;
}

/// Index of the candidate to keep: a stable model before an unstable one; among the stable ones
/// whose fit is within kShiftFitTolerance of the best, the smallest |shift| (a shift should only
/// be used when the data ask for it clearly, not to fit noise).
std::size_t choose_shift(const std::vector<ShiftTrial>& trials) {
  const bool any_stable = std::any_of(trials.begin(), trials.end(), [](const ShiftTrial& t) { return t.stable; });
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : trials)
    if (t.stable == any_stable) best = std::min(best, t.nrmse);
  std::size_t chosen = trials.size();
  for (std::size_t i = 0; i < trials.size(); ++i) {
    const ShiftTrial& t = trials[i];
    if (t.stable != any_stable || !(t.nrmse <= best * (1.0 + kShiftFitTolerance))) continue;
    if (chosen == trials.size() || std::abs(t.shift) < std::abs(trials[chosen].shift) ||
        (std::abs(t.shift) == std::abs(trials[chosen].shift) && t.nrmse < trials[chosen].nrmse)) {
      chosen = i;
    }
  }
  return chosen == trials.size() ? 0 : chosen;
}

}  // namespace

std::vector<std::string> moving_axes(const std::vector<NamedCapture>& captures) {
  std::vector<std::string> names;
  if (captures.empty()) return names;
  const auto command_moves = [](const core::AxisTrace& trace) {
    const auto [lo, hi] = std::minmax_element(trace.cmd.begin(), trace.cmd.end());
    return lo != trace.cmd.end() && *lo != *hi;
  };
  for (const auto& axis : captures.front().capture.axes) {
    const bool moves = std::any_of(captures.begin(), captures.end(), [&](const NamedCapture& c) {
      const core::AxisTrace* t = c.capture.find(axis.name);
      return t != nullptr && command_moves(*t);
    });
    if (moves) names.push_back(axis.name);
  }
  return names;
}

void refine_identification(AxisIdentification& result, const std::vector<NamedCapture>& captures,
                           const rapid::RefineOptions& refine_options) {
  rapid::RefineOptions options = refine_options;
  if (!result.solution.feasible) {
    result.solution.warnings.push_back("not refined: the solver's poles are outside the bounds (use --method exact)");
    return;
  }
  std::vector<rapid::TrackingRecord> records;
  for (const auto& c : captures) {
    const core::AxisTrace& trace = require_axis(c, result.axis);
    records.push_back({trace.cmd, trace.act});
  }
  options.command_shift = result.regressors.command_shift;
  result.refinement = rapid::refine_output_error(result.solution.coefficients, result.ts, records, result.bounds, options);
  result.solver_fit = result.fit;
  result.fit = simulated_fit(rapid::AxisModel(result.coefficients(), result.ts), captures, result.axis,
                             result.regressors.command_shift);
}

AxisIdentification identify_axis(const std::vector<NamedCapture>& captures, const std::vector<NamedCapture>& validation,
                                 const std::string& axis, const IdentificationSettings& settings) {
  if (captures.empty()) throw core::InputError("no captures to identify from");
  const rapid::Bounds bounds = complete_bounds(settings.bounds, captures.front().capture.ts);
  AxisIdentification result;
  if (settings.shift_search) {
    const ShiftSearch range = *settings.shift_search;
    if (range.first > range.last || range.last - range.first > 64) {
      throw core::InputError({"", 0, 0, "--shift"}, "shift search range " + std::to_string(range.first) + ".." +
                                                        std::to_string(range.last) +
                                                        " must be ascending and at most 64 samples wide");
    }
    std::vector<int> shifts;
    for (int shift = range.first; shift <= range.last; ++shift) shifts.push_back(shift);
    // Each candidate is one pass over the captures and a solve, independent of the others.
    std::vector<AxisIdentification> candidates(shifts.size());
    core::parallel_parts(shifts.size(), settings.workers, 1, [&](std::size_t begin, std::size_t end) {
      IdentificationSettings one = settings;
      for (std::size_t i = begin; i < end; ++i) {
        one.regressors.command_shift = shifts[i];
        candidates[i] = solve_with_shift(captures, axis, one, bounds);
      }
    });
    std::vector<ShiftTrial> trials = fit_shift_candidates(candidates, captures, axis, shifts);
    result = std::move(candidates[choose_shift(trials)]);
    result.shift_trials = std::move(trials);
  } else {
    result = identify_with_shift(captures, axis, settings, bounds);
  }
  if (settings.refine) refine_identification(result, captures, settings.refine_options);
  if (!validation.empty()) {
    const rapid::AxisModel model(result.coefficients(), result.ts);
    result.validation = simulated_fit(model, validation, axis, result.regressors.command_shift);
    if (result.refinement) {
      result.solver_validation = simulated_fit(rapid::AxisModel(result.solution.coefficients, result.ts), validation, axis,
                                               result.regressors.command_shift);
    }
  }
  // Once, at the end: the quantum sorts every reading, and the shift search does not need it.
  const double fit_quantum = captures_quantum(captures, axis);
  for (auto* fit : {&result.fit, &result.solver_fit})
    if (*fit) rapid::set_reading_quantum(**fit, fit_quantum);
  if (!validation.empty()) {
    const double validation_quantum = captures_quantum(validation, axis);
    for (auto* fit : {&result.validation, &result.solver_validation})
      if (*fit) rapid::set_reading_quantum(**fit, validation_quantum);
  }
  for (const auto& c : captures) result.sources.push_back(c.source);
  for (const auto& [fit, what] : {std::pair{&result.fit, "identification"}, std::pair{&result.validation, "validation"}})
    if (*fit && (*fit)->diverged)
      result.solution.warnings.push_back(fmt::format(
          "the model is unstable: its simulated tracking error on the {} captures diverges at sample {} (the fit covers "
          "the samples before it); an unconstrained least-squares model can be unstable, the bounded methods (exact, "
          "ga) are not",
          what, (*fit)->diverged_at));
  return result;
}

}  // namespace servotwin::vcnc
