#pragma once
/// \file
/// Plant model classes for fitting measured frequency responses (seed catalog C5.7):
///
///   P(s) = K · R(s) · Π_i (s² + 2ζz_i ωz_i s + ωz_i²)/(s² + 2ζp_i ωp_i s + ωp_i²) · L(s) · e^{−sT} · O(s)
///
/// with the rigid mode R = 1/(s + a) (real pole, viscous friction) or 1/s (integrator), an
/// optional lag L = 1/(s + τ2) (test-bed form, catalog A6; it lumps sampling, communication and
/// actuator lag), an optional pure delay, and O = 1 for a velocity output or 1/s for a position
/// output. Each mode is an antiresonance (complex zero pair) with its resonance (complex pole
/// pair) when the sensor is on the motor (collocated). With the sensor on the load of a mass chain
/// (non-collocated, e.g. a load encoder) a mode has no antiresonance: its factor is
/// (2ζp ωp s + ωp²)/(s² + 2ζp ωp s + ωp²), the shaft's damping zero b s + k of C3.12's load
/// velocity over the torque, (b s + k)/(s (Jm Jl s² + (Jm + Jl)(b s + k))), written with
/// ωp² = k (Jm + Jl)/(Jm Jl) and 2ζp ωp = b (Jm + Jl)/(Jm Jl); K is then 1/(Jm + Jl) (times the
/// lag's τ2). Exact without viscous friction on the motor; with it (a rigid pole a) the zero stays
/// tied to the resonance, an approximation of order a·Jl/(Jm ωp), below 3 % of ζp on the test
/// benches. The model is held in modal parameters; the transfer function is derived from them.
/// Frequencies are in rad/s (design.md "Units").

#include <complex>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/transfer_function.hpp"

namespace servotwin::fit {

/// What the measured output is: velocity, or position (one more integrator).
enum class OutputKind { kVelocity, kPosition };
/// The rigid-body part: a real pole K/(s+a) or an integrator K/s.
enum class RigidKind { kRealPole, kIntegrator };

/// Where the measured output is taken: on the motor (collocated: every mode has its
/// antiresonance) or on the load (non-collocated: resonances alone).
enum class SensorSide { kMotor, kLoad };

/// "velocity" / "position".
[[nodiscard]] std::string to_string(OutputKind output);
/// "pole" / "integrator".
[[nodiscard]] std::string to_string(RigidKind rigid);
/// "motor" / "load".
[[nodiscard]] std::string to_string(SensorSide sensor);

/// Natural frequency and damping of a complex pair s² + 2ζωs + ω².
struct ModalPair {
  double omega_rad_s = 0.0;
  double zeta = 0.0;
};

/// One flexible mode: the antiresonance (zeros) and resonance (poles). For a collocated
/// (motor-side) measurement the antiresonance lies below the resonance; for a load-side one the
/// antiresonance is unused and zero.
struct Mode {
  ModalPair antiresonance;
  ModalPair resonance;
};

/// A fitted or user-given plant model.
struct PlantModel {
  OutputKind output = OutputKind::kVelocity;
  RigidKind rigid = RigidKind::kRealPole;
  SensorSide sensor = SensorSide::kMotor;
  double gain = 1.0;                       ///< K (motor side: high-frequency asymptote K/s of a velocity model without lag; load side: 1/(Jm + Jl))
  double rigid_pole_rad_s = 0.0;           ///< a for kRealPole; ignored for kIntegrator
  std::vector<Mode> modes;                 ///< ordered by increasing resonance frequency
  std::optional<double> lag_pole_rad_s;    ///< τ2 of the lag 1/(s + τ2), when present
  std::optional<double> delay_s;           ///< pure delay T, when present

  /// P(jω).
  [[nodiscard]] std::complex<double> response(double omega_rad_s) const noexcept;
  /// The rational part num/den (the delay, if any, is not included). Denominator monic.
  [[nodiscard]] core::TransferFunction transfer_function() const;
  /// Number of free parameters of this structure (K, a, 4 per mode (2 on the load side), τ2, T).
  [[nodiscard]] std::size_t parameter_count() const noexcept;
};

/// The plant model of a velocity transfer function K·Π(s² + 2ζzi ωzi s + ωzi²)/((s + a)·Π(s² + 2ζi ωi s + ωi²))
/// (or with s for s + a), optionally times a lag 1/(s + τ2) (relative degree 2: the faster of the
/// two real poles is the lag): how a user-given or simulated plant (a mass chain's motor velocity
/// per torque, the test bed of A6) enters the tools that take fitted models. Zeros and poles are
/// paired by increasing frequency (collocated order). Throws core::InputError (field `field`) when
/// the function does not have that structure: relative degree other than 1 or 2, a real-pole count
/// other than the relative degree, a real zero,
/// an unstable pole or zero, or a pole pair without a zero pair; the message names the root.
[[nodiscard]] PlantModel plant_model_from_transfer_function(const core::TransferFunction& velocity_tf,
                                                            const std::string& field = "plant");

/// Parameter count of a structure without building the model.
[[nodiscard]] std::size_t parameter_count(std::size_t modes, RigidKind rigid, bool lag, bool delay,
                                          SensorSide sensor = SensorSide::kMotor) noexcept;

/// core::InputError (field `field`) naming `what` when `model` is a load-side model: the
/// controller tuning, the two-mass realization and the friction analyses need the antiresonance
/// that only a motor-side measurement shows.
void require_motor_side(const PlantModel& model, const std::string& what, const std::string& field = "plant");

}  // namespace servotwin::fit
