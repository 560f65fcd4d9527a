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
inline vcnc::NamedCapture thesis_capture(const machine::MachineConfig& machine, std::uint64_t seed,
                                         motion::IdentificationSet set = motion::IdentificationSet::Standard) {
  motion::IdentificationOptions o = motion::identification_defaults(set);
  o.axes = {motion::Axis::X};
  o.seed = seed;
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

/// RMS of (predicted - actual tracking error) / RMS of the actual one, the actual error being
/// command - `position`, the model simulated from the command and the capture's first reading.
inline double error_ratio(const rapid::AxisModel& model, const core::AxisTrace& trace, const std::vector<double>& position,
                          int shift) {
  rapid::ModelSimulationOptions options;
  options.command_shift = shift;
  options.initial_position = trace.act.front();
  const rapid::ModelResponse r = model.simulate(trace.cmd, options);
  double diff = 0.0, actual = 0.0;
  for (std::size_t k = 0; k < trace.cmd.size(); ++k) {
    const double e = trace.cmd[k] - position[k];
    diff += (r.tracking_error[k] - e) * (r.tracking_error[k] - e);
    actual += e * e;
  }
  return std::sqrt(diff / actual);
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
