#pragma once
// Shared steps of the validation tests: run thesis-style identification experiments on the virtual
// machine presets and score the identified models against the machines' true behaviour.

#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/presets.hpp"
#include "servotwin/machine/simulator.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/vcnc/machine_run.hpp"

namespace servotwin::validation {

inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Capture of a Table 3.2-style X program (200 random moves within +-10 mm at F12000) on a machine.
/// As printed in the thesis, the program states no path-control mode (servotwin's generator
/// writes G61 by default): the machine's own rule decides whether consecutive moves in the same
/// direction run on (the ZPETC preset) or stop (the Fadal presets stop after every block).
inline vcnc::NamedCapture thesis_capture(const machine::MachineConfig& machine, std::uint64_t seed,
                                         motion::IdentificationSet set = motion::IdentificationSet::Standard) {
  motion::IdentificationOptions o = motion::identification_defaults(set);
  o.axes = {motion::Axis::X};
  o.seed = seed;
  o.path_control = motion::PathControl::Unstated;
  const motion::Program program = motion::make_identification_program(o);
  return {machine.name + " seed " + std::to_string(seed), vcnc::run_program(machine, program)};
}

/// The command preview a preset's controller uses (the ZPETC reads 2 samples ahead): the shift
/// the thesis applies to the command for identification (section 4.3.2).
inline int identification_shift(const machine::MachineConfig& machine) {
  return machine::command_preview(machine.axes.front());
}

/// Largest relative deviation of the identified tracking response from the machine's true sampled
/// loop between f_lo and f_hi [Hz] (40 log-spaced points).
/// The model was identified against the command shifted by `shift` samples (x(k) explained by
/// x_r(k + shift)), so its response to the unshifted command carries exp(j omega shift ts).
inline std::complex<double> shifted_tracking_response(const rapid::AxisModel& model, double omega, int shift, double ts) {
  return model.tracking().frequency_response(omega) * std::polar(1.0, omega * shift * ts);
}

inline double tracking_frf_error(const rapid::AxisModel& model, const machine::AxisConfig& axis, double ts, int shift,
                                 double f_lo, double f_hi) {
  const auto truth = machine::discrete_tracking_tf(axis, ts);
  double worst = 0.0;
  for (int i = 0; i < 40; ++i) {
    const double f = f_lo * std::pow(f_hi / f_lo, i / 39.0);
    const std::complex<double> t = truth.frequency_response(kTwoPi * f);
    const std::complex<double> g = shifted_tracking_response(model, kTwoPi * f, shift, ts);
    worst = std::max(worst, std::abs(g - t) / std::abs(t));
  }
  return worst;
}

/// The model's tracking error on the capture's command, started at the capture's first reading.
inline std::vector<double> model_tracking_error(const rapid::AxisModel& model, const core::AxisTrace& trace, int shift) {
  rapid::ModelSimulationOptions options;
  options.command_shift = shift;
  options.initial_position = trace.act.front();
  return model.simulate(trace.cmd, options).tracking_error;
}

/// RMS of (predicted - actual tracking error) / RMS of the actual one, for positions already
/// predicted by any means (the tracking errors are command - position).
inline double position_error_ratio(const std::vector<double>& command, const std::vector<double>& predicted,
                                   const std::vector<double>& actual) {
  double diff = 0.0, norm = 0.0;
  for (std::size_t k = 0; k < command.size(); ++k) {
    diff += (predicted[k] - actual[k]) * (predicted[k] - actual[k]);
    norm += (command[k] - actual[k]) * (command[k] - actual[k]);
  }
  return std::sqrt(diff / norm);
}

/// RMS of (predicted - actual tracking error) / RMS of the actual one, the actual error being
/// command - `position`, the model simulated from the command and the capture's first reading.
inline double error_ratio(const rapid::AxisModel& model, const core::AxisTrace& trace, const std::vector<double>& position,
                          int shift) {
  const std::vector<double> error = model_tracking_error(model, trace, shift);
  std::vector<double> predicted(error.size());
  for (std::size_t k = 0; k < error.size(); ++k) predicted[k] = trace.cmd[k] - error[k];
  return position_error_ratio(trace.cmd, predicted, position);
}

/// |RMS(predicted tracking error) / RMS(actual tracking error) - 1|: how well the size of the
/// error is predicted, the level a user reads off a twin before machining.
inline double rms_level_error(const rapid::AxisModel& model, const core::AxisTrace& trace, int shift) {
  const std::vector<double> error = model_tracking_error(model, trace, shift);
  double predicted = 0.0, actual = 0.0;
  for (std::size_t k = 0; k < trace.cmd.size(); ++k) {
    predicted += error[k] * error[k];
    actual += (trace.cmd[k] - trace.act[k]) * (trace.cmd[k] - trace.act[k]);
  }
  return std::abs(std::sqrt(predicted / actual) - 1.0);
}

/// The best any prediction driven by the command can score against the encoder's reading: the
/// machine itself (same friction, same noise stream) run again without its encoder quantum, whose
/// table position is then compared with the quantized reading like a model's prediction.
inline double quantum_free_machine_ratio(const machine::MachineConfig& machine, const core::AxisTrace& trace) {
  machine::AxisConfig ideal = machine.axes.front();
  ideal.nonlinear.encoder_resolution = 0.0;
  machine::SimulationOptions o;
  o.record_states = true;
  o.record_u = false;
  const machine::AxisRun run = machine::simulate_axis(ideal, machine.ts, trace.cmd, o, 0);
  return position_error_ratio(trace.cmd, run.table, trace.act);
}

/// RMS of (predicted - actual tracking error) / RMS of the actual tracking error on a capture.
inline double prediction_error_ratio(const rapid::AxisModel& model, const core::AxisTrace& trace, int shift) {
  return error_ratio(model, trace, trace.act, shift);
}

/// The same, against the machine's true tracking error (command - true table position, without
/// the encoder's quantization): the capture is run again on the machine's first axis with the
/// same noise stream and its states recorded (the run is deterministic, checked on `act`).
inline double prediction_error_ratio_to_truth(const rapid::AxisModel& model, const machine::MachineConfig& machine,
                                              const core::AxisTrace& trace, int shift) {
  machine::SimulationOptions o;
  o.record_states = true;
  o.record_u = false;
  const machine::AxisRun run = machine::simulate_axis(machine.axes.front(), machine.ts, trace.cmd, o, 0);
  if (run.act != trace.act) return std::nan("");  // not the same run: the comparison would be meaningless
  return error_ratio(model, trace, run.table, shift);
}

}  // namespace servotwin::validation
