#pragma once
/// \file
/// The rapid-identification thesis's loop on a virtual machine, as building blocks for the demo,
/// the report and the validation: run the identification experiment (Table 3.2 program on every
/// program axis of the machine), identify each axis, then run a toolpath on the machine and
/// predict it with the identified models, and compare.

#include <cstdint>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/machine/axis_config.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/motion/program.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/vcnc/prediction.hpp"

namespace servotwin::vcnc {

struct IdentificationExperiment {
  motion::IdentificationOptions options;
  motion::Program program;
  core::Capture capture;
};

/// Thesis Table 3.2 (200 random moves within +-10 mm at F12000, seeded) on every X/Y/Z axis of
/// the machine around its home position, run on the machine. core::InputError when the machine
/// has no X, Y or Z axis.
IdentificationExperiment run_identification_experiment(const machine::MachineConfig& machine, std::uint64_t seed);

/// identify_axis for every axis of the first capture whose command moves.
std::vector<AxisIdentification> identify_axes(const std::vector<NamedCapture>& captures,
                                              const IdentificationSettings& settings);

/// What prediction needs from identifications.
std::vector<AxisModelSpec> model_specs(const std::vector<AxisIdentification>& identifications);

/// A toolpath run on the machine and predicted with the models.
struct ContouringRun {
  Prediction prediction;
  core::Capture actual;
  MeasuredComparison comparison;
};
/// The program must start at the machine's home (vcnc::machine_start).
ContouringRun contouring_run(const machine::MachineConfig& machine, const std::vector<AxisModelSpec>& models,
                             const motion::Program& program);

/// Score of one quantity over the whole comparison ("all" samples), or nullptr.
const PredictionScore* overall_score(const MeasuredComparison& comparison, const std::string& quantity);

}  // namespace servotwin::vcnc
