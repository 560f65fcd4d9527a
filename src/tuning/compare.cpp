#include "servotwin/tuning/compare.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <cmath>
#include <limits>

#include "servotwin/core/error.hpp"

namespace servotwin::tuning {

std::vector<Structure> comparison_structures() {
  return {Structure::kPi, Structure::kPid, Structure::kLqg, Structure::kHinf};
}

std::vector<StructureComparison> compare_structures(const fit::PlantModel& model, const TuneOptions& options,
                                                    const std::vector<Structure>& structures) {
  std::vector<StructureComparison> out;
  std::optional<core::InputError> first_failure;
  for (const Structure s : structures) {
    if (controls_position(s) || measures_load(s))
      throw core::InputError(core::at_field("structures"),
                             "expected motor-feedback velocity-loop structures (pi, pid, lqg, hinf): " + to_string(s) +
                                 (measures_load(s) ? " measures the load" : " closes the position loop"));
    StructureComparison entry;
    entry.structure = s;
    TuneOptions o = options;
    o.structure = s;
    o.allow_negative_kd = true;
    try {
      entry.result = tune(model, o);
    } catch (const core::InputError& e) {
      entry.failure = e.reason();
      if (!first_failure) first_failure = e;
    }
    out.push_back(std::move(entry));
  }
  // What fails every structure (the plant, the options) is the caller's error, not a comparison.
  const bool any = std::any_of(out.begin(), out.end(), [](const StructureComparison& c) { return c.result.has_value(); });
  if (!any && first_failure) throw *first_failure;
  return out;
}

double relative_to_pi(const std::vector<StructureComparison>& comparison, double LoopIndices::*index, double value) {
  for (const StructureComparison& c : comparison) {
    if (c.structure != Structure::kPi || !c.result) continue;
    const double pi = c.result->controller.predicted.*index;
    if (std::isfinite(pi) && pi != 0.0) return value / pi;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::vector<std::string> comparison_notes(const std::vector<StructureComparison>& comparison) {
  std::vector<std::string> notes;
  for (const StructureComparison& c : comparison) {
    if (!c.result || c.structure == Structure::kPi) continue;
    const double itae = c.result->controller.predicted.itae_load_step;
    const double ratio = relative_to_pi(comparison, &LoopIndices::itae_load_step, itae);
    if (!(ratio > kFarWorseItae)) continue;
    notes.push_back(fmt::format("{}: its load-step ITAE is {:.3g} times the PI's: it rejects a load torque much more "
                                "slowly (weaker integral action) although it wins on bandwidth; prefer the PI where "
                                "load disturbances matter",
                                to_string(c.structure), ratio));
  }
  return notes;
}

}  // namespace servotwin::tuning
