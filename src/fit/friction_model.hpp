#pragma once
// Internal to the fit module: the two-mass chain with Coulomb friction on both masses through
// their describing functions (C3.12 with C5.10), solved by harmonic balance at one frequency and
// one measured velocity amplitude, seen from either encoder; and its linear part as a modal
// PlantModel. friction_fit.cpp fits it; friction_fit.hpp states the model.

#include <complex>

#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit::detail {

/// The chain's parameters: inertias, shaft stiffness and damping, the motor's viscous damping and
/// the Coulomb levels on motor and load.
struct ChainParameters {
  double jm, jl, k, bs, bv, mm, ml;
};

/// P(jω) of the chain with friction, the measured velocity amplitude being `velocity_amplitude`
/// (the motor's for `sensor == kMotor`, the load's for kLoad; for a position output the velocity
/// amplitude all the same), driven through `actuator`'s lag p/(s + p) and delay (its other fields
/// unused) and divided by s for a position `output`.
std::complex<double> chain_response(double omega, double velocity_amplitude, const ChainParameters& p,
                                    const PlantModel& actuator, SensorSide sensor);

/// The linear part (friction left out) as a modal model on the given side: motor side zeros of
/// Jl s² + bs s + k, gain p/Jm; load side the shaft's damping zero, gain p/(Jm + Jl); poles of
/// (Jm s + bv)(Jl s² + bs s + k) + Jl s (bs s + k), the real root nearest 0 the rigid pole (an
/// integrator when bv = 0 or `rigid` says so). Output, lag and delay from `actuator`.
PlantModel chain_linear_part(const ChainParameters& p, const PlantModel& actuator, RigidKind rigid, SensorSide sensor);

}  // namespace servotwin::fit::detail
