#pragma once
/// \file
/// Coulomb friction fitted with the two-mass model from one swept-sine measurement (issue 25 §1).
///
/// Friction comparable to the excitation torque distorts a swept-sine response in two ways a linear
/// model can only absorb wrongly: below the antiresonance the motor-side describing function
/// 4M/(πV) looks like viscous damping (the linear fit invents a rigid pole of tenths of a hertz),
/// and at the antiresonance, where the motor barely moves and the load swings, the load's friction
/// adds (2/π)·M_l/T of damping to ζz (T the excitation amplitude there). Both depend on the
/// velocity amplitudes, which the measurement knows: every point carries its excitation amplitude
/// (FrequencyPoint::amplitude), so the motor's velocity amplitude is |P|·T (ω|P|·T for a position
/// output).
///
/// The model (dissertation C3.12's two-mass with C5.10's describing functions, harmonic balance
/// at each point): motor inertia Jm with viscous damping bv and Coulomb level Mm, shaft stiffness k
/// and damping bs, load inertia Jl with Coulomb level Ml, driven through the linear fit's lag
/// p/(s + p) and delay. With the shaft impedance Z = bs + k/s and the load's describing function
/// cl = 4Ml/(π|Vl|), the load follows Vl = G·Vm, G = Z/(Jl s + cl + Z); |Vl| = |G||Vm| is then a
/// quadratic in |Vl| with a closed-form root (none when |Vm||Z| ≤ 4Ml/π: the load sticks, G = 0).
/// The motor's describing function uses the measured |Vm|, so each point's model response is
///
///   P = L(s) / (Jm s + bv + 4Mm/(π|Vm|) + Z (1 − G)),
///
/// explicit in the parameters. Seen from a load encoder (a load-side linear fit,
/// SensorSide::kLoad) the balance is explicit too: the load's describing function cl = 4Ml/(π|Vl|)
/// comes from the measured |Vl|, the load's balance gives Vm/Vl = H = 1 + (Jl s + cl)/Z and with it
/// |Vm| and the motor's describing function, and P = L/((Jm s + bv + 4Mm/(π|Vm|))H + Jl s + cl).
/// A load-side response's linear part does not tell Jm from Jl (it depends on J = Jm + Jl,
/// k·J/(Jm Jl) and bs·J/(Jm Jl) only); the friction does, since the two describing functions act
/// on different velocities. The share Jm/J is fitted from 1/2 and, when the friction is too small
/// to tell it (a singular Jacobian), held where LM left it (its std NaN) and said so in the note;
/// short of that its std tells how well it is seen. (With the motor's viscous damping bv the
/// linear part sees the split too, weakly.)
/// Levenberg–Marquardt fits (ln Jm, ln Jl, ln k, ln bs, bv, Mm, Ml, and
/// the lag pole and delay when the linear fit has them: friction bends its phase, and with it the
/// lag) to the complex log errors of the points the linear fit used (its left-out points stay out),
/// weighted as the linear fit weights them (fit.hpp), from the linear fit's physical parameters:
/// one start reads its rigid pole as viscous damping, two as Coulomb friction; the converged start
/// of least cost wins. Standard deviations follow the linear fit's rule
/// (FitResult::uncertainty_scale); with `--rigid integrator` bv is held at 0 and is not a
/// parameter of the covariance.

#include <Eigen/Dense>
#include <complex>
#include <cstddef>
#include <string>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {

/// The two-mass model with Coulomb friction on both masses, and its linear part.
struct CoulombFit {
  bool fitted = false;
  std::string note;                    ///< how it was fitted, or why not
  /// The linear part (viscous damping only): what tuning and simulation should use. The linear
  /// fit's output kind, the lag and delay refitted with the friction; an integrator when bv = 0.
  PlantModel model;
  Estimate gain;                       ///< the linear part's K = p/Jm (1/Jm without a lag)
  Estimate motor_coulomb, load_coulomb;  ///< Mm, Ml in the input's units (torque, force, current)
  Estimate motor_inertia, load_inertia, stiffness, shaft_damping, viscous_damping;
  Estimate total_inertia;              ///< Jm + Jl (its std from the fit on the load side only)
  Estimate motor_share;                ///< Jm/(Jm + Jl) (its std from the fit on the load side only)
  Estimate rigid_pole_rad_s;           ///< bv's pole of the linear part (0 for an integrator)
  Estimate resonance_ratio;            ///< r = ωn/ωz of the linear part
  Estimate lag_pole_rad_s, delay_s;    ///< refitted with the friction (NaN when the linear fit has none)
  ModeUncertainty mode;                ///< antiresonance (NaN on the load side) and resonance of the linear part
  /// θ = (ln Jm, ln Jl, ln k, ln bs, bv, Mm, Ml[, ln p][, T]) (scaled; on the load side
  /// (ln J, logit Jm/J, ln k̃, ln b̃s, ...) with k = 4s(1 − s)k̃, bs = 4s(1 − s)b̃s) at the solution and
  /// its covariance (the linear fit's rule; the rows and columns of a held bv or share are zero).
  Eigen::VectorXd theta;
  Eigen::MatrixXd covariance;
  std::string weighting;               ///< "std_dev" or "log-relative", as the linear fit's
  double cost = 0.0;                   ///< ½ Σ |e_l|² (weighted) at the solution
  double sigma2 = 0.0;                 ///< residual variance of the covariance (1 with std_dev)
  double uncertainty_scale = 1.0;      ///< as FitResult::uncertainty_scale
  std::string uncertainty_note;
  double rms_log_error = 0.0;          ///< with the friction terms, unweighted
  double linear_rms_log_error = 0.0;   ///< of the linear fit on the same points
  std::size_t points = 0;
  int iterations = 0;
  std::string message;                 ///< LM stopping reason
};

/// Fits the two-mass model with Coulomb friction to `response` (the points `linear` used: valid and
/// not in linear.left_out_hz), starting from `linear` (a two-mass fit of the same response with
/// physical parameters, or a one-mode load-side fit; the side is linear's). Returns fitted = false
/// with the reason when the linear fit has no two-mass reading, the points carry no excitation
/// amplitude, or LM does not converge. `options.rigid == kIntegrator` fixes bv = 0.
CoulombFit fit_coulomb_friction(const core::FrequencyResponse& response, const FitReport& linear, const FitOptions& options);

/// `linear` with its result replaced by the friction fit's linear part (model, estimates, physical
/// parameters, residual, weighting and uncertainty rule), the report to write and tune from;
/// `linear` unchanged when !f.fitted.
FitReport with_friction_model(FitReport linear, const CoulombFit& f);

/// The fitted model with friction at a measured point (its excitation amplitude and measured
/// magnitude give the velocity amplitudes), e.g. to draw it over the measurement. NaN when the
/// point carries no amplitude or !f.fitted.
std::complex<double> coulomb_response_at(const CoulombFit& f, const core::FrequencyPoint& point);

/// The model response P(jω) of a point of excitation amplitude `amplitude` whose measured motor
/// velocity amplitude is `motor_velocity_amplitude` (exposed for tests). Parameters as in CoulombFit
/// (values), `lag` and `delay` from `linear_model` (its other fields are not used).
std::complex<double> coulomb_two_mass_response(double omega_rad_s, double motor_velocity_amplitude, double jm, double jl,
                                               double k, double bs, double bv, double mm, double ml,
                                               const PlantModel& linear_model);

/// The same chain seen from the load encoder: the load's velocity over the torque at a point whose
/// measured load velocity amplitude is `load_velocity_amplitude` (exposed for tests).
std::complex<double> coulomb_two_mass_load_response(double omega_rad_s, double load_velocity_amplitude, double jm, double jl,
                                                    double k, double bs, double bv, double mm, double ml,
                                                    const PlantModel& linear_model);

}  // namespace servotwin::fit
