#pragma once
/// \file
/// Time simulation of a virtual machine: discrete controllers at ts driving continuous plants
/// that are integrated exactly between samples (the linear part by its exact zero-order-hold
/// solution; Coulomb friction by splitting the sample at velocity zero crossings and applying
/// the stiction test at rest, see rigid_axis.hpp). The per-sample step is allocation-free and
/// exception-free.
///
/// The axes of a machine are mechanically independent, so each axis is simulated over the whole
/// command in turn. Before sample 0 the axis rests at `home` (motor and table), the command is
/// taken as constant at its first value, the controller's memories (integrator, previous reading,
/// observer) are at rest; after the last sample the command is held at its last value (the
/// look-ahead of the controller reads it). Per sample k the signal chain of axis_config.hpp runs:
/// read encoder -> controller -> saturation -> DAC -> delay -> plant over [k ts, (k+1) ts).
/// The pole-placement controller's observer is driven by the value it sent to the amplifier
/// (after its own saturation and DAC rounding), as a real controller knows its output.
///
/// Encoder noise: per axis a std::mt19937_64 seeded with splitmix64(seed ^ (0x9E3779B97F4A7C15 *
/// (axis index + 1))), uniform deviates ((r >> 11) + 0.5) 2^-53 and the Box-Muller transform
/// (cos deviate first, then sin); identical on every platform (std::normal_distribution is not).

#include <cstdint>
#include <span>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/machine/axis_config.hpp"

namespace servotwin::machine {

struct SimulationOptions {
  bool ideal = false;        ///< switch every nonlinearity off (friction, backlash, saturation, DAC, encoder, delay)
  std::uint64_t seed = 1;    ///< encoder-noise seed
  bool record_u = true;      ///< keep the control signal in AxisTrace::u
  bool record_states = false;  ///< simulate_axis: keep motor, table and velocity
};

/// Everything one axis produced, sample k at t = k ts.
struct AxisRun {
  std::vector<double> act;       ///< position reading (quantized, noisy): what the CNC records
  std::vector<double> u;         ///< control signal applied to the plant over [k ts, (k+1) ts) (after saturation, DAC and delay); empty unless record_u
  std::vector<double> motor;     ///< true motor-side position; empty unless record_states
  std::vector<double> table;     ///< true table position (= motor without backlash)
  std::vector<double> velocity;  ///< true motor-side velocity
};

/// Runs one axis on its commanded positions. `stream` selects the noise stream (the axis index in
/// a machine). Throws core::InputError for an invalid axis or a non-finite command.
AxisRun simulate_axis(const AxisConfig& axis, double ts, std::span<const double> command,
                      const SimulationOptions& options = {}, std::uint64_t stream = 0);

/// Runs the machine on commanded positions, one vector per machine axis in `machine.axes` order,
/// all of equal length. Sample k of the result is the state at t = k ts: `act` is what the
/// position feedback reads (quantized, noisy), `cmd` echoes the command and `u` is the applied
/// control signal (when record_u). Throws core::InputError when the machine is invalid, when the
/// number or lengths of the command vectors do not match, or for a non-finite command.
core::Capture simulate(const MachineConfig& machine, const std::vector<std::vector<double>>& commands,
                       const SimulationOptions& options = {});

}  // namespace servotwin::machine
