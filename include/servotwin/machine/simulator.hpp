#pragma once
/// \file
/// Time simulation of a virtual machine: discrete controllers at ts driving continuous plants
/// that are integrated exactly between samples (the linear part by its exact zero-order-hold
/// solution; Coulomb friction by splitting the sample at velocity zero crossings and applying
/// the stiction test at rest). The per-sample step is allocation-free and exception-free.

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
};

/// Runs the machine on commanded positions, one vector per machine axis in `machine.axes` order,
/// all of equal length. Sample k of the result is the state at t = k ts: `act` is what the
/// position feedback reads (quantized, noisy) and `cmd` echoes the command. Throws
/// core::InputError when the number or lengths of the command vectors do not match.
core::Capture simulate(const MachineConfig& machine, const std::vector<std::vector<double>>& commands,
                       const SimulationOptions& options = {});

}  // namespace servotwin::machine
