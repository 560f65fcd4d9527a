#pragma once
// Internal to the fit module: a mass chain (motor first, load last) with Coulomb friction on the
// motor and the load through their describing functions (C3.12 with C5.10), solved by harmonic
// balance at one frequency and one measured velocity amplitude, seen from either encoder; its
// linear part as a modal PlantModel; and the chain a collocated modal model describes (Cauer's
// continued fraction). friction_fit.cpp fits it; friction_fit.hpp states the model.

#include <complex>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit::detail {

/// The chain's parameters: n + 1 inertias (motor first), the n shafts' stiffnesses and dampings,
/// the motor's viscous damping and the Coulomb levels on motor and load (the first and last mass).
struct ChainParameters {
  std::vector<double> inertia, stiffness, damping;
  double bv = 0.0, mm = 0.0, ml = 0.0;
  [[nodiscard]] std::size_t shafts() const noexcept { return stiffness.size(); }
  [[nodiscard]] double total_inertia() const noexcept;
};

/// The two-mass chain (one shaft).
ChainParameters two_mass_chain(double jm, double jl, double k, double bs, double bv, double mm, double ml);

/// P(jω) of the chain with friction, the measured velocity amplitude being `velocity_amplitude`
/// (the motor's for `sensor == kMotor`, the load's for kLoad; for a position output the velocity
/// amplitude all the same), driven through `actuator`'s lag p/(s + p) and delay (its other fields
/// unused) and divided by s for a position `output`.
std::complex<double> chain_response(double omega, double velocity_amplitude, const ChainParameters& p,
                                    const PlantModel& actuator, SensorSide sensor);

/// The linear part (friction left out) as a modal model on the given side: poles of the chain
/// (the real one nearest 0 the rigid pole, an integrator when bv = 0 or `rigid` says so), motor
/// side zeros those of the chain with the motor held and gain p/J_motor; load side (one shaft
/// only: PlantModel ties each load-side zero to its resonance) the shaft's damping zero and gain
/// p/ΣJ. Output, lag and delay from `actuator`.
PlantModel chain_linear_part(const ChainParameters& p, const PlantModel& actuator, RigidKind rigid, SensorSide sensor);

/// The undamped chain whose motor-side admittance is K/s·Π(s² + ωz_i²)/Π(s² + ωp_i²) (K = `gain`,
/// the lag's factor taken out), by Cauer's first continued fraction of its impedance about s = ∞:
/// Z = J1 s + 1/(s/k1 + 1/(J2 s + …)). Shaft i's damping starts at 2ζp_i k_i/ωp_i (exact for one
/// shaft up to the motor's share). Empty with `why` when the modes do not interlace as a chain's
/// (an element comes out non-positive).
std::optional<ChainParameters> chain_of_modes(const std::vector<Mode>& modes, double gain, std::string& why);

}  // namespace servotwin::fit::detail
