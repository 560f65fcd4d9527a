#pragma once
/// \file
/// H-infinity mixed-sensitivity velocity controller for the normalized two-mass plant with the
/// pole-relocating weight V of the dissertation (catalog C7.14), solved by core::hinf_synthesis.
///
/// Modified mixed sensitivity (Kwakernaak): minimize gamma = sup_w sqrt(|W1 S V|^2 + |W2 U V|^2)
/// on the extended plant Pe = Pm/s (integral action; the controller is K = K0/s), with
///   W1 = 1/Ms,
///   W2 = (1/Mt) (s + w0T)^2 (s + r)^2 / [(s + w0S)^2 (s^2 + 2 xi_v r s + r^2) (w0T r)^2],
///   V  = (s + w0S)^2 (s^2 + 2 xi_v r s + r^2) / den(Pe).
/// V's denominator is Pe's (the open-loop poles: printed s^2 (s^2 + 2 zeta_z r^2 s + r^2) for the
/// frictionless plant, s (s + a)(s^2 + 2 zeta_p r s + r^2) with friction), its numerator the poles
/// the loop should get: the controller cannot cancel the lightly damped pair (that would make a
/// notch and lose active damping) and moves it to damping xi_v at r. w0S sets the dominant pole
/// pair (performance), w0T caps the bandwidth (robustness).
///
/// Generalized plant (states: the shared realization of [V Pe], then W2's), inputs [w, u0],
/// outputs [z1, z2, e]: z1 = W1 (Pe u0 + V w), z2 = W2 u0, e = -(Pe u0 + V w); u0 = K0 e.
/// V and Pe share one realization of den(Pe), so the disturbance model's integrators are the
/// plant's own (stabilizable) and D21 = 1: the disturbance-feedforward case, Y = 0.
///
/// Position loop (C7.14's position weights): Pe = Pm/s^2 (the position plant Pm/s with integral
/// action), the measurement the motor position, and the same weights with cubes:
///   W2 = (1/Mt) (s + w0T)^3 (s + r)^2 / [(s + w0S)^3 (s^2 + 2 xi_v r s + r^2) w0T^3 r^2],
///   V  = (s + w0S)^3 (s^2 + 2 xi_v r s + r^2) / den(Pe);
/// K = K0/s maps the position error to the torque.
///
/// Load-side feedback (C7.17): the loop measures the load velocity wl, Pe = Pl/s with
/// Pl = (b/k s + 1)/((s + a)(s^2 + 2 zeta_p r s + r^2)) the two-mass realization's load velocity per
/// torque (printed, frictionless: Pel = (1/s^2)(2 zeta_z s + 1)/(s^2 + 2 zeta_z r^2 s + r^2)), V as
/// for the motor, and W2 = (1/Mt) (s + w0T)^4 / [(s + w0S)^2 (s^2 + 2 xi_v r s + r^2) (w0T r)^2]:
/// there is no antiresonance to keep out of the loop.
///
/// The design model is Pm (normalized_plant.hpp) times the plant's known HF dynamics (hf: current
/// lag, lag, measurement filter, and the delay as its first-order Padé approximant
/// (1 - sT/2)/(1 + sT/2)); V's numerator gets the same extra poles, so its shape is unchanged.
/// The higher modes of a multi-mode plant (C7.16, approach B) enter as `modes` says:
///   kFirstMode  left out (approach A: design on mode 1, the tuner checks on the full plant);
///   kPassive    in Pe, V unchanged: V's numerator carries their lightly damped poles, so the
///               controller cancels them (a notch: passive, "gain" stabilization) and actively
///               damps mode 1 only; 2 controller states per mode;
///   kActive     in Pe, and V extended as eq. 7.164: each higher pair relocated to damping xi_v at
///               its own frequency, V = (s + w0S)^2 (s^2 + 2 xi_v r s + r^2) prod(s^2 + 2 xi_v wi s + wi^2) / den(Pe),
///               so the loop damps every mode actively (at a higher HF controller gain).
/// In kPassive and kActive a practically unobservable mode (resonance within 1 % of its
/// antiresonance, like the third mode of C7.19's flexible frame, 8.03 over 8.02) is left out of the
/// design model as in kFirstMode: the dissertation calls damping it from the motor "practically
/// infeasible", relocating it costs a controller gain ~1/(wp/wz - 1), and its nearly cancelled,
/// barely damped pair makes the synthesis ill-posed.
/// W2 is the same in all three. The tuner evaluates the loop with the exact delay and the higher
/// modes.

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/state_space.hpp"
#include "servotwin/tuning/normalized_plant.hpp"

namespace servotwin::tuning {

/// The accepted range of xi_v: C7.14's [sqrt(2)/2, 1], the lower end 0.7 so that a rounded
/// sqrt(2)/2 passes.
inline constexpr double kXiVMin = 0.7, kXiVMax = 1.0;

/// A higher mode whose resonance lies below this ratio times its antiresonance is practically
/// unobservable from the motor (pole and zero nearly cancel): the designs leave it out.
inline constexpr double kUnobservableModeRatio = 1.01;

/// True when `mode`'s resonance is below kUnobservableModeRatio times its antiresonance.
[[nodiscard]] bool practically_unobservable(const fit::Mode& mode) noexcept;

/// How a design treats the higher modes of a multi-mode plant (C7.16; see above).
enum class ModeHandling { kFirstMode, kPassive, kActive };

/// "first", "passive", "active".
[[nodiscard]] const char* to_string(ModeHandling m) noexcept;
/// The inverse of to_string; std::nullopt for anything else.
[[nodiscard]] std::optional<ModeHandling> parse_mode_handling(const std::string& text) noexcept;

/// C7.14's weights (normalized frequencies), for the velocity and the position designs.
struct VelocityHinfWeights {
  double omega_0s = 0.5;            ///< w0S: dominant closed-loop pole pair (> 0)
  std::optional<double> omega_0t;   ///< w0T: bandwidth cap (> 0); default r
  double xi_v = 0.8;                ///< damping of the relocated resonant pair, in [sqrt(2)/2, 1] (0.7 accepted)
  double ms = 1.5;                  ///< W1 = 1/Ms
  double mt = 1.5;                  ///< the 1/Mt of W2
  double backoff = 1.01;            ///< controller at gamma_opt * backoff (core::HinfOptions)
  ModeHandling modes = ModeHandling::kFirstMode;  ///< higher modes (C7.16); no effect on a two-mass plant
  /// Reduce the compensator K to this many states by balanced truncation of its stable part
  /// (core::balanced_truncation_stable_part: the integrator and any unstable poles are kept).
  /// std::nullopt gives K's minimal realization: only the states of Hankel singular value near
  /// rounding level (<= 1e-6 of the largest: W2's poles, which K cancels) are dropped, so a
  /// two-mass velocity controller has 5 states and each higher mode adds 2 (C7.14, C7.16).
  std::optional<int> controller_order;
  /// false (with no controller_order): K at its full order, without the Hankel values: a search
  /// that only needs K's response saves the split and the Gramians.
  bool minimal_realization = true;
  /// Roll-off: the corner ωf (normalized, > 0) of a low-pass F = ωf/(s + ωf) in series with the
  /// controller's output. The synthesis runs on the plant with F in its torque path (as a known
  /// lag: V's numerator gets its pole too), and the compensator is F·K' of that design: strictly
  /// proper (|K(j∞)| = 0, −20 dB/decade more above ωf) where C7.14's biproper W2 leaves K
  /// biproper. F's state is added after any reduction (controller_order counts K' only).
  std::optional<double> rolloff;
};

/// A designed H-infinity velocity controller (normalized units).
struct HinfDesign {
  core::StateSpace generalized_plant;  ///< inputs [w, u0], outputs [z1, z2, e]
  core::StateSpace k0;                 ///< controller of Pe: e -> u0
  core::StateSpace compensator;        ///< K = K0/s as inputs [w*, wm] (position: [φ*, φm]), output torque (1-DoF)
  double gamma_optimal = 0.0;          ///< optimal gamma (core::hinf_synthesis, relative tolerance 1e-4)
  double gamma = 0.0;                  ///< gamma of the returned controller (gamma_optimal * backoff)
  double closed_loop_norm = 0.0;       ///< ||F_l(P, K0)||_inf
  double omega_0t = 0.0;               ///< the w0T used
  std::vector<std::complex<double>> controller_poles;  ///< eig of the compensator (one integrator at 0)
  bool controller_stable = false;      ///< stable except the integrator (stable_except_integrator)
  int full_order = 0;                  ///< states of K before any reduction (the generalized plant's + 1, + 1 for a roll-off)
  /// Hankel singular values of K's stable part (descending; what a reduction would discard), and
  /// the bound 2 sum(discarded) on ||K - K_reduced||_inf (0 when nothing was dropped).
  std::vector<double> hankel;
  double reduction_error_bound = 0.0;
};

/// The generalized plant above for `plant` with its HF dynamics and, unless weights.modes is
/// kFirstMode, its higher modes (8 states, plus one per HF factor and two per higher mode).
/// core::InputError (field "omega_0s", "omega_0t", "xi_v", "ms", "mt", "controller_order") for
/// weights out of range; plant checks as in normalized_two_mass().
[[nodiscard]] core::StateSpace velocity_mixed_sensitivity_plant(const NormalizedPlant& plant,
                                                                const VelocityHinfWeights& weights);

/// The C7.14 velocity design: the generalized plant, core::hinf_synthesis (relative tolerance
/// 1e-4, the weights' backoff), K = K0/s in the tuner's two-input form. Throws core::InputError as
/// velocity_mixed_sensitivity_plant and for a backoff outside [1, 10] or a controller_order below the
/// compensator's unstable states (the integrator included) or above its full order;
/// std::domain_error when the synthesis finds no controller (not expected for valid weights: the
/// problem is always solvable).
[[nodiscard]] HinfDesign velocity_hinf(const NormalizedPlant& plant, const VelocityHinfWeights& weights);

/// The load-side generalized plant of C7.17 (8 states plus the HF factors). Errors as
/// velocity_mixed_sensitivity_plant, and core::InputError (field "plant") for a plant with higher
/// modes or without a two-mass realization (negative friction terms).
[[nodiscard]] core::StateSpace load_side_mixed_sensitivity_plant(const NormalizedPlant& plant,
                                                                 const VelocityHinfWeights& weights);

/// The C7.17 load-side design: K = K0/s with inputs [w*, wl] (the load velocity), output torque.
/// Errors as load_side_mixed_sensitivity_plant and velocity_hinf.
[[nodiscard]] HinfDesign load_side_hinf(const NormalizedPlant& plant, const VelocityHinfWeights& weights);

/// The position loop's generalized plant (Pe = Pm/s^2, cubic weights; 10 states plus one per HF
/// factor). Same errors as velocity_mixed_sensitivity_plant.
[[nodiscard]] core::StateSpace position_mixed_sensitivity_plant(const NormalizedPlant& plant,
                                                                const VelocityHinfWeights& weights);

/// The C7.14 position design: K = K0/s from the position error [φ*, φm] to the torque. Same errors
/// as velocity_hinf. The tuner offers it as hinf-pos (tune.hpp).
[[nodiscard]] HinfDesign position_hinf(const NormalizedPlant& plant, const VelocityHinfWeights& weights);

}  // namespace servotwin::tuning
