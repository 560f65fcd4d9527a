#include "servotwin/vcnc/thesis_loop.hpp"

#include <algorithm>

#include "servotwin/core/error.hpp"
#include "servotwin/vcnc/machine_run.hpp"

namespace servotwin::vcnc {

IdentificationExperiment run_identification_experiment(const machine::MachineConfig& machine, std::uint64_t seed) {
  IdentificationExperiment e;
  e.options = motion::identification_defaults(motion::IdentificationSet::Standard);
  e.options.axes = program_axes_of(machine);
  if (e.options.axes.empty()) throw core::InputError({machine.name, 0, 0, "axes"}, "the machine has no X, Y or Z axis to identify");
  e.options.seed = seed;
  e.options.center = machine_start(machine);
  e.program = motion::make_identification_program(e.options);
  e.capture = run_program(machine, e.program);
  return e;
}

std::vector<AxisIdentification> identify_axes(const std::vector<NamedCapture>& captures,
                                              const IdentificationSettings& settings) {
  std::vector<AxisIdentification> out;
  for (const auto& axis : moving_axes(captures)) out.push_back(identify_axis(captures, {}, axis, settings));
  return out;
}

std::vector<AxisModelSpec> model_specs(const std::vector<AxisIdentification>& identifications) {
  std::vector<AxisModelSpec> specs;
  for (const auto& id : identifications) {
    specs.push_back({id.axis, rapid::AxisModel(id.coefficients(), id.ts), id.regressors.command_shift,
                     "model of axis " + id.axis});
  }
  return specs;
}

ContouringRun contouring_run(const machine::MachineConfig& machine, const std::vector<AxisModelSpec>& models,
                             const motion::Program& program) {
  ContouringRun r;
  r.actual = run_program(machine, program);
  r.prediction = predict(program, program.name, limits_of(machine), models);
  r.comparison = compare_with_capture(r.prediction, r.actual, machine.name + " (virtual machine)");
  return r;
}

const PredictionScore* overall_score(const MeasuredComparison& comparison, const std::string& quantity) {
  for (const auto& s : comparison.scores)
    if (s.quantity == quantity && s.kind == "all") return &s;
  return nullptr;
}

}  // namespace servotwin::vcnc
