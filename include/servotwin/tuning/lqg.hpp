#pragma once
/// \file
/// LQG velocity and position compensators for the normalized two-mass plant with the weighting
/// scheme of the dissertation (catalog C7.13, example E29): one design knob kbw, weights scaled by
/// c = r²/2 so that the same kbw gives comparable loops for any resonance ratio.
///
/// Plant (normalized: Im = 1, ωz = 1; FrictionTwoMass), the load torque Tl opposing the motion:
///   ω̇m = −(b + bm) ωm + b ωl − Ts + Tm,   Il ω̇l = b ωm − (b + bl) ωl + Ts − Tl,   Ṫs = k (ωm − ωl).
///
/// Velocity LQG. Regulator on x = [ωm, ωl, Ts, xi] with xi' = ω* − ωm (integral action),
/// Q = diag(0, q_load, kbw/c², q_integral), R = ρ = kbw/c² (printed q_load = q_integral = 20;
/// a larger kbw makes control dearer: a slower loop). Kalman filter on [ωm, ωl, Ts, Tl] with a
/// constant load torque, y = ωm, process noise into ωm and Tl with intensities W = diag(wm, wt)
/// (printed 1, 1), measurement noise V (printed 0.1). The integral state is not estimated.
/// Compensator (5 states [x̂, xi], inputs [ω*, ωm], output u):
///   u = −K₁ x̂₁ − K₂ x̂₂ − K₃ x̂₃ − K₄ xi + kff ω*   (x̂₁ replaced by the measured ωm with
///   raw_motor_velocity), x̂' = Ae x̂ + Be u + L (ωm − x̂₁), xi' = ω* − ωm.
///
/// Load-side LQG (C7.17). The velocity regulator with the integral on the load, xi' = ω* − ωl, and
/// the velocity weights ("cost unchanged": the doc points at eq. 7.137, the position weights, but
/// this is the 4-state velocity model, so the velocity weights of C7.13 apply); the Kalman filter
/// measures both velocities, y = [ωm, ωl], W as for the velocity LQG and V = diag(v, v) (printed
/// 0.1). Compensator (5 states, inputs [ω*, ωm, ωl], output u).
///
/// Position LQG. Regulator on [φm, ωm, φl, ωl, xi], xi' = φ* − φm, Q = diag(1, 1, 20, 20, 5),
/// R = kbw/c²; Kalman filter on [φm, ωm, φl, ωl, Tl] (the estimator model, eq. 7.138, is missing
/// from the source, defect 19: the position model plus a constant load torque), y = φm, W = I₅,
/// V = 0.01. Compensator (6 states, inputs [φ*, φm]).
///
/// An LQG compensator is often unstable itself (the regulator pushes against the lightly damped
/// pair and the estimator's copy of it): the design reports the compensator's poles and whether
/// it is stable, as a drive commissioner must know before switching it on.

#include <complex>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "servotwin/core/state_space.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {

/// Velocity-LQG weights (C7.13; defaults as printed).
struct VelocityLqgOptions {
  double kbw = 1.0;                 ///< bandwidth knob (> 0): larger = slower
  double q_load_velocity = 20.0;    ///< Q weight of ωl
  double q_integral = 20.0;         ///< Q weight of the integral state
  double noise_motor = 1.0;         ///< process-noise intensity into ωm
  double noise_load_torque = 1.0;   ///< process-noise intensity into the load torque
  double measurement_noise = 0.1;   ///< V
  double feedforward = 0.0;         ///< kff: ω* straight to the torque (normalized)
  bool raw_motor_velocity = false;  ///< regulate ωm with the measurement instead of its estimate
};

/// Position-LQG weights (C7.13; defaults as printed).
struct PositionLqgOptions {
  double kbw = 1.0;
  Eigen::Matrix<double, 5, 1> q = (Eigen::Matrix<double, 5, 1>() << 1.0, 1.0, 20.0, 20.0, 5.0).finished();  ///< diag of Q
  double process_noise = 1.0;      ///< W = process_noise · I₅
  double measurement_noise = 0.01; ///< V
};

/// A designed LQG compensator (normalized units).
struct LqgDesign {
  Eigen::RowVectorXd regulator_gain;  ///< K (u = −K x)
  Eigen::MatrixXd estimator_gain;     ///< L (one column per measurement)
  std::vector<std::complex<double>> regulator_poles;   ///< eig(A − B K)
  std::vector<std::complex<double>> estimator_poles;   ///< eig(Ae − L Ce)
  std::vector<std::complex<double>> controller_poles;  ///< eig of the compensator
  std::vector<std::complex<double>> closed_loop_poles; ///< plant + compensator (separation: regulator ∪ estimator)
  bool controller_stable = false;     ///< every compensator pole in the open left half-plane (the integrator excepted)
  core::StateSpace compensator;       ///< inputs [reference, measurement], output u
  double riccati_residual = 0.0;      ///< the larger relative residual of the two Riccati solves
};

/// The normalized plant as a state space with inputs [Tm, Tl] and outputs [ωm, ωl] (velocity:
/// states [ωm, ωl, Ts]) or [φm, φl] (position: states [φm, ωm, φl, ωl]).
[[nodiscard]] core::StateSpace two_mass_state_space(const FrictionTwoMass& plant, bool position);

/// The velocity LQG of C7.13. core::InputError (field named after the option) for weights that are
/// not finite and > 0 (kff, q >= 0), or a plant without stiffness.
[[nodiscard]] LqgDesign velocity_lqg(const FrictionTwoMass& plant, double r, const VelocityLqgOptions& options = {});

/// The velocity LQG on a plant with higher modes (C7.16: "just extend the model"): each mode
/// enters the design model as its unit-DC-gain factor of NormalizedPlant::motor(true), in series
/// with the motor torque (two states per mode, appended after [ωm, ωl, Ts]; no weight in Q and no
/// process noise on them), so the model's motor response is the full plant's and both the
/// regulator and the estimator know the modes. The compensator has 5 + 2·modes states. Without
/// modes this is velocity_lqg(plant, r, options). core::InputError also for a mode that is not a
/// stable pair (resonance and antiresonance > 0, dampings >= 0).
[[nodiscard]] LqgDesign velocity_lqg(const FrictionTwoMass& plant, std::span<const fit::Mode> higher_modes, double r,
                                     const VelocityLqgOptions& options = {});

/// The two-mass velocity model (two_mass_state_space, velocity) with `higher_modes` in series with
/// the motor torque, as velocity_lqg designs on: states [ωm, ωl, Ts, two per mode], inputs
/// [Tm, Tl], outputs [ωm, ωl].
[[nodiscard]] core::StateSpace two_mass_state_space_with_modes(const FrictionTwoMass& plant,
                                                               std::span<const fit::Mode> higher_modes);

/// The load-side LQG of C7.17 (the velocity options; raw_motor_velocity is refused: core::InputError).
[[nodiscard]] LqgDesign load_side_lqg(const FrictionTwoMass& plant, double r, const VelocityLqgOptions& options = {});

/// The position LQG of C7.13 (field names as above).
[[nodiscard]] LqgDesign position_lqg(const FrictionTwoMass& plant, double r, const PositionLqgOptions& options = {});

/// The compensator's stability rule of LqgDesign::controller_stable: every pole in the open left
/// half-plane except one integrator pole at 0 (within 1e-9 of the largest pole's modulus).
[[nodiscard]] bool stable_except_integrator(const std::vector<std::complex<double>>& poles);

/// The 2-DoF form of a compensator with inputs [reference, y] and output u (C7.13 robust
/// analysis): u = C1 reference − C2 y with C1 = Cc(sI − Ac)⁻¹B1 + D1, C2 = −(Cc(sI − Ac)⁻¹B2 + D2)
/// over the one denominator det(sI − Ac) (no cancellation; the prefilter is F = C1/C2). A
/// VelocityLoop built from it gives every loop function of the LQG loop. std::invalid_argument
/// unless the compensator has 2 inputs and 1 output.
[[nodiscard]] ControllerTf two_dof_form(const core::StateSpace& compensator);

/// The same for a compensator with inputs [reference, ωm, ωl] (load_side_lqg): R, Cm = −(u/ωm) and
/// Cl = −(u/ωl) over det(sI − Ac), for VelocityLoop::two_measurements. std::invalid_argument unless
/// it has 3 inputs and 1 output.
[[nodiscard]] TwoMeasurementController two_measurement_form(const core::StateSpace& compensator);

/// A position controller u = C1 φ* − C2 φm in the velocity form a VelocityLoop takes (reference
/// input still φ*, measurement ωm = s φm): feedback C2/s and reference C1, both over den·s. On a
/// VelocityLoop built from it, S, T and the margins are the position loop's, and ωm/φ*, ωl/φ*,
/// ωl/Tl divided by jω are φm/φ*, φl/φ*, φl/Tl.
[[nodiscard]] ControllerTf velocity_form(const ControllerTf& position);

/// C7.13's reference prefilter F = 1/(τ s + 1) of the position LQG: the smallest τ >= 0 with
/// sup_ω |F φl/φ*| <= peak_limit (1: the load position does not overshoot in frequency) on a
/// VelocityLoop of velocity_form(); `grid` the normalized frequencies of the peak search. |F(jω)|
/// falls as τ grows at every ω, so the peak is non-increasing in τ and a bisection (to 1e-9
/// relative) finds the boundary. 0 when the loop meets the limit without a prefilter.
/// std::invalid_argument for a loop without a load side or a limit <= 0.
[[nodiscard]] double prefilter_time_constant(const VelocityLoop& velocity_form_loop, std::span<const double> grid,
                                             double peak_limit = 1.0);

/// The same for any position tracking function φ/φ* (normalized frequency; the load's, or the
/// motor's where there is no load side), the bisection to `rel_tol` relative (the tuner's scans
/// rank candidates at a coarser one).
[[nodiscard]] double prefilter_time_constant(const std::function<std::complex<double>(double)>& position_tracking,
                                             std::span<const double> grid, double peak_limit = 1.0,
                                             double rel_tol = 1e-9);

/// The compensator with the prefilter 1/(τ s + 1) on its reference input (one more state, first);
/// τ = 0 returns it unchanged.
[[nodiscard]] core::StateSpace with_prefilter(const core::StateSpace& compensator, double tau);

}  // namespace servotwin::tuning
