#pragma once
/// \file
/// Coulomb friction fitted with a mass-chain model from one swept-sine measurement (issue 25 §1).
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
/// The model (dissertation C3.12's two-mass, and its mass chain, with C5.10's describing functions,
/// harmonic balance at each point): the motor J1 with viscous damping bv and Coulomb level Mm,
/// shafts of stiffness ki and damping bi, inner masses without friction, the load (the last mass)
/// with Coulomb level Ml, driven through the linear fit's lag p/(s + p) and delay. With the load's
/// describing function cl = 4Ml/(π|Vl|), walking the chain from the load (each shaft's force over
/// its impedance bi + ki/s moves the next mass inward) gives the motor's velocity and the first
/// shaft's force per unit load velocity, Vm/Vl = A + B·cl and F1/Vl, both affine in cl; |Vm| =
/// |Vl||A + B·cl| is then a quadratic in |Vl| with a closed-form root (none when |Vm| ≤ |B|·4Ml/π:
/// the load sticks and the walk starts from a held load). The motor's describing function uses
/// the measured |Vm|, so each point's model response is
///
///   P = L(s) / (J1 s + bv + 4Mm/(π|Vm|) + F1/Vm),
///
/// explicit in the parameters (for two masses F1/Vm = Z(1 − G), Z = bs + k/s, G = Z/(Jl s + cl + Z)).
/// A motor-side linear fit of n modes starts the chain of n + 1 masses: its undamped modes give
/// the inertias and stiffnesses by Cauer's continued fraction (the two-mass parameters for one
/// mode). Seen from a load encoder (a one-mode load-side linear fit,
/// SensorSide::kLoad) the balance is explicit too: the load's describing function cl = 4Ml/(π|Vl|)
/// comes from the measured |Vl|, the load's balance gives Vm/Vl = H = 1 + (Jl s + cl)/Z and with it
/// |Vm| and the motor's describing function, and P = L/((Jm s + bv + 4Mm/(π|Vm|))H + Jl s + cl).
/// A load-side response's linear part does not tell Jm from Jl (it depends on J = Jm + Jl,
/// k·J/(Jm Jl) and bs·J/(Jm Jl) only); the friction does, since the two describing functions act
/// on different velocities. The share Jm/J is fitted from 1/2 and, when the friction is too small
/// to tell it (a singular Jacobian), held where LM left it (its std NaN) and said so in the note;
/// short of that its std tells how well it is seen. (With the motor's viscous damping bv the
/// linear part sees the split too, weakly.) A load-side fit of n > 1 modes starts chains of n + 1
/// masses from the total inertia and the resonances, with the antiresonances a motor encoder
/// would show guessed between them (0.3, 0.6, 0.9 of the way in log frequency, 3^n starts;
/// Cauer's chain of each guess): the linear part gives n + 1 numbers for 2n + 1 inertias and
/// stiffnesses, and only the friction tells the rest (on data of the chain itself the split comes
/// back to 0.2 %; without friction the fit does not converge and says why).
/// Levenberg–Marquardt fits (ln Ji, ln ki, ln bi, bv, Mm, Ml, and
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
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {

/// The mass-chain model with Coulomb friction on motor and load, and its linear part.
struct CoulombFit {
  bool fitted = false;
  std::string note;                    ///< how it was fitted, or why not
  /// The linear part (viscous damping only): what tuning and simulation should use. The linear
  /// fit's output kind, the lag and delay refitted with the friction; an integrator when bv = 0.
  PlantModel model;
  Estimate gain;                       ///< the linear part's K = p/Jm (1/Jm without a lag)
  Estimate motor_coulomb, load_coulomb;  ///< Mm, Ml in the input's units (torque, force, current)
  Estimate motor_inertia, load_inertia;  ///< the first and the last mass
  Estimate stiffness, shaft_damping;    ///< the shaft of a two-mass chain (NaN for a longer chain)
  std::vector<Estimate> inertias;      ///< every mass, motor first
  std::vector<Estimate> stiffnesses, shaft_dampings;  ///< every shaft, from the motor
  Estimate viscous_damping;
  Estimate total_inertia;              ///< Jm + Jl (its std from the fit on the load side only)
  Estimate motor_share;                ///< Jm/(Jm + Jl) (its std from the fit on the load side only)
  Estimate rigid_pole_rad_s;           ///< bv's pole of the linear part (0 for an integrator)
  Estimate resonance_ratio;            ///< r = ωn/ωz of a two-mass linear part (NaN otherwise)
  Estimate lag_pole_rad_s, delay_s;    ///< refitted with the friction (NaN when the linear fit has none)
  /// Each mode's antiresonance (NaN on the load side) and resonance of the linear part.
  std::vector<ModeUncertainty> modes;
  /// θ = (ln J1…ln Jn+1, ln k1…ln kn, ln b1…ln bn, bv, Mm, Ml[, ln p][, T]) (scaled; on the load side
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

/// Fits the mass chain with Coulomb friction to `response` (the points `linear` used: valid and
/// not in linear.left_out_hz), starting from `linear` (a fit of n modes: a chain of n + 1 masses,
/// seen from linear's side). Returns fitted = false with the reason when the linear fit has no
/// chain reading (no two-mass parameters, modes that do not interlace), the points carry no
/// excitation amplitude, LM does not converge, or the fit is worse than the linear one. `options.rigid == kIntegrator` fixes bv = 0.
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

/// The mass chain of `inertias.size()` masses (motor first; `stiffnesses` and `dampings` one per
/// shaft from the motor) with Coulomb friction `mm` on the motor and `ml` on the load (the last
/// mass), seen from `sensor`'s encoder at a point whose measured velocity amplitude on that side is
/// `velocity_amplitude` (exposed for tests; the two-mass functions above are its one-shaft case).
std::complex<double> coulomb_chain_response(double omega_rad_s, double velocity_amplitude, const std::vector<double>& inertias,
                                            const std::vector<double>& stiffnesses, const std::vector<double>& dampings,
                                            double bv, double mm, double ml, const PlantModel& linear_model,
                                            SensorSide sensor);

}  // namespace servotwin::fit
