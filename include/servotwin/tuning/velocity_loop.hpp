#pragma once
/// \file
/// The closed velocity loop of a cascade PI/PID drive on a normalized flexible plant (catalog C7.2,
/// C7.5, C7.8): every transfer function the indices, the
/// robustness tests and the position loop need, both as exact frequency functions (the delay of
/// the known HF dynamics evaluated as e^{−jωT}) and as rational transfer functions for time
/// simulation and stability tests (the delay replaced by a Padé approximant).
///
/// Signals (normalized units, catalog §0): ω* velocity reference, Tm motor torque, Tl load torque
/// (a disturbance that opposes the motion, as the dissertation writes Il ω̇l = Ts − Tl), ωm, ωl
/// motor and load velocity. The 2-DoF controller is u = R(s) ω* − C(s) y with y the motor velocity
/// seen through the feedback filter F(s), and the motor torque is Tm = A(s) u with A the actuator
/// dynamics (current-loop lag, lag pole, delay):
///
///   C(s) = kp + ki/s + kd s/(τ s + 1),   R(s) = wp kp + ki/s + wd kd s/(τ s + 1),
///   L = C·F·A·Pm,  S = 1/(1 + L),  T = L/(1 + L).
///
/// Load-side functions exist only for a plant with a two-mass realization
/// (two_mass_realization(); an estimate when it is not passive); with higher modes only the load
/// tracking of a drive-train chain exists (NormalizedPlant::chain_load, load_estimate()) and the
/// load-torque functions are std::nullopt.

#include <complex>
#include <optional>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

/// A 2-DoF controller as two transfer functions over one denominator: u = reference·ω* − feedback·y.
/// The PID below, or any linear compensator with inputs [ω*, y] (an LQG's, via two_dof_form()).
struct ControllerTf {
  core::TransferFunction feedback;   ///< C(s)
  core::TransferFunction reference;  ///< R(s) (same denominator as C)
};

/// A controller measuring both velocities (C7.17's load-side LQG, inputs [ω*, ωm, ωl]):
/// u = R ω* − Cm ωm − Cl ωl over one denominator.
struct TwoMeasurementController {
  ControllerTf motor;           ///< R (reference) and Cm (feedback, on ωm)
  core::TransferFunction load;  ///< Cl on ωl (the denominator of motor.feedback)
};

/// C(s) and R(s) of the gains above. τ = 0 with kd ≠ 0 is an improper (ideal) derivative and is
/// refused (std::invalid_argument); kd = 0 gives the PI s-denominator only.
[[nodiscard]] ControllerTf pid_controller(const PidGains& gains);

/// Plant transfer functions of the two-mass realization with viscous friction in normalized units
/// (Im = 1): from motor torque Tm and load torque Tl to motor and load velocity. With the shaft
/// coupling c(s) = b s + k and D'(s) = [(s² + bm s + c)(Il s² + bl s + c) − c²]/s (the determinant
/// of the two equations of motion, which has the factor s, divided by it):
///   ωm/Tm = (Il s² + bl s + c)/D',  ωl/Tm = c/D',  ωm/Tl = −c/D',  ωl/Tl = −(s² + bm s + c)/D'.
struct TwoMassTransfer {
  core::TransferFunction motor_from_torque;       ///< ωm/Tm (equals NormalizedPlant::motor(false))
  core::TransferFunction load_from_torque;        ///< ωl/Tm
  core::TransferFunction motor_from_load_torque;  ///< ωm/Tl
  core::TransferFunction load_from_load_torque;   ///< ωl/Tl
};

/// The four plant functions above; std::nullopt when the plant has no two-mass realization.
[[nodiscard]] std::optional<TwoMassTransfer> two_mass_transfer(const NormalizedPlant& plant);

/// (N, N) Padé approximant of e^{−sT}: all-pass, unit DC gain, phase error below 1e-3 rad for
/// ω T <= N (roughly). T = 0 gives 1; N in [1, 10] (else std::invalid_argument).
[[nodiscard]] core::TransferFunction pade_delay(double delay, int order);

/// Rational closed-loop transfer functions, all over the one characteristic polynomial
/// Δ = dC dA dF dP + nC nA nF nP (no common factor is cancelled). HF dynamics enter with their
/// rational parts and the delay as a Padé approximant of the order passed to VelocityLoop.
struct ClosedLoopTransfer {
  core::Polynomial characteristic;                ///< Δ(s)
  core::TransferFunction sensitivity;             ///< S = 1/(1 + L)
  core::TransferFunction complementary;           ///< T = L/(1 + L)
  core::TransferFunction motor_tracking;          ///< ωm/ω*
  core::TransferFunction effort;                  ///< u/ω* (controller output)
  std::optional<core::TransferFunction> load_tracking;           ///< ωl/ω*
  std::optional<core::TransferFunction> motor_from_load_torque;  ///< ωm/Tl
  std::optional<core::TransferFunction> load_from_load_torque;   ///< ωl/Tl (closed loop)
  std::optional<core::TransferFunction> effort_from_load_torque;  ///< u/Tl
};

/// A PI/PID velocity loop on a normalized plant. Construction precomputes the plant and controller
/// polynomials; the frequency functions are then allocation-free.
class VelocityLoop {
 public:
  /// `with_hf`: include plant.hf (evaluation) or design on the bare model (false). `with_higher_modes`:
  /// use NormalizedPlant::motor(true) (with modes, only the load tracking of a chain exists).
  /// `pade_order` is used by closed_loop() only. std::invalid_argument unless plant.r > 1 (a
  /// NormalizedPlant from normalize() always has r > 1.05).
  VelocityLoop(const NormalizedPlant& plant, const PidGains& gains, bool with_hf = true,
               bool with_higher_modes = true, int pade_order = 6);
  /// The same loop around any proper 2-DoF controller (normalized units); `controller.reference`
  /// must have the denominator of `controller.feedback` (std::invalid_argument otherwise).
  VelocityLoop(const NormalizedPlant& plant, ControllerTf controller, bool with_hf = true,
               bool with_higher_modes = true, int pade_order = 6);

  /// The loop around `controller` measuring the LOAD velocity (C7.17 load-side feedback): the
  /// feedback path sees Pl = ωl/Tm of the two-mass realization (with its HF dynamics), so L, S, T
  /// and the margins are those of the load loop; the tracking and load-torque functions keep their
  /// meaning (ωm/ω*, ωl/ω*, ωm/Tl = Gmd − Pm·CAF·Gld·S, ωl/Tl = Gld·S). std::invalid_argument for a
  /// plant without a two-mass realization (higher modes, or negative shaft damping).
  [[nodiscard]] static VelocityLoop load_feedback(const NormalizedPlant& plant, ControllerTf controller,
                                                  bool with_hf = true, int pade_order = 6);
  /// The loop around a controller measuring both velocities: L = (Cm Pm + Cl Pl)·A·F (broken at
  /// the plant input), ωm/Tl = (Gml·(1 + A F Cl Pl) − Pm A F Cl Gll)·S, ωl/Tl the same with the
  /// roles swapped (both from the two-mass identity; see the .cpp). The measurement filter and
  /// delay act on both channels. std::invalid_argument as load_feedback, or when the load channel
  /// does not share the controller's denominator.
  [[nodiscard]] static VelocityLoop two_measurements(const NormalizedPlant& plant, TwoMeasurementController controller,
                                                     bool with_hf = true, int pade_order = 6);
  /// The loop measures the load velocity (load_feedback or two_measurements).
  [[nodiscard]] bool measures_load() const noexcept { return measured_ != Measured::kMotor; }
  /// The loop measures the motor velocity too (two_measurements).
  [[nodiscard]] bool measures_both() const noexcept { return measured_ == Measured::kBoth; }

  [[nodiscard]] const ControllerTf& controller_tf() const noexcept { return controller_; }
  /// Pm = plant_num/plant_den (without the HF dynamics; higher modes as constructed).
  [[nodiscard]] const core::Polynomial& plant_num() const noexcept { return plant_num_; }
  /// The measured plant's numerator over plant_den: plant_num (motor) or Pl's (load_feedback).
  [[nodiscard]] const core::Polynomial& measured_num() const noexcept {
    return measured_ == Measured::kLoad ? load_num_ : plant_num_;
  }
  [[nodiscard]] const core::Polynomial& plant_den() const noexcept { return plant_den_; }
  /// |C(j∞)|: the controller's high-frequency gain (the ratio of leading coefficients).
  [[nodiscard]] double controller_hf_limit() const noexcept;
  /// The load side of the two-mass realization: load tracking and the load-torque functions.
  [[nodiscard]] bool has_load() const noexcept { return has_load_; }
  /// The load tracking ωl/ω* exists: has_load(), or a plant whose higher modes are in the drive
  /// train (NormalizedPlant::chain_load and load_estimate(); the load-torque functions stay NaN).
  [[nodiscard]] bool has_load_tracking() const noexcept { return has_load_tracking_; }

  /// Frequency functions at s = jω (normalized ω >= 0), delay exact.
  [[nodiscard]] std::complex<double> controller(double omega) const noexcept;     ///< C(jω)
  [[nodiscard]] std::complex<double> plant(double omega) const noexcept;          ///< Pm(jω) without HF
  [[nodiscard]] std::complex<double> loop_gain(double omega) const noexcept;      ///< L(jω)
  [[nodiscard]] std::complex<double> sensitivity(double omega) const noexcept;    ///< S
  [[nodiscard]] std::complex<double> complementary(double omega) const noexcept;  ///< T
  [[nodiscard]] std::complex<double> motor_tracking(double omega) const noexcept; ///< ωm/ω*
  [[nodiscard]] std::complex<double> effort(double omega) const noexcept;         ///< u/ω*
  /// ωl/ω* (NaN when !has_load_tracking()), ωm/Tl and ωl/Tl (NaN when !has_load()).
  [[nodiscard]] std::complex<double> load_tracking(double omega) const noexcept;
  [[nodiscard]] std::complex<double> motor_from_load_torque(double omega) const noexcept;
  [[nodiscard]] std::complex<double> load_from_load_torque(double omega) const noexcept;
  /// ωl/Tl of the open plant (no control): the reference of the J2 index.
  [[nodiscard]] std::complex<double> open_loop_load_from_load_torque(double omega) const noexcept;

  /// Every function above at one frequency from one evaluation of the block polynomials (the
  /// analyses' grid pass). Load-side members are NaN when !has_load() (load_tracking: when
  /// !has_load_tracking()).
  struct Responses {
    std::complex<double> loop_gain, sensitivity, complementary, motor_tracking, effort;
    std::complex<double> load_tracking, motor_from_load_torque, load_from_load_torque, open_loop_load_from_load_torque;
  };
  [[nodiscard]] Responses responses(double omega) const noexcept;

  /// The plant's resonance ratio r (frequencies of interest: 1 = ωz and r).
  [[nodiscard]] double resonance_ratio() const noexcept { return r_; }

  /// The rational closed loop (see ClosedLoopTransfer).
  [[nodiscard]] ClosedLoopTransfer closed_loop() const;
  /// Δ(s) with the Padé delay: closed_loop().characteristic without building the numerators.
  [[nodiscard]] const core::Polynomial& characteristic_polynomial() const noexcept { return characteristic_; }
  /// Routh test of Δ (with the Padé delay).
  [[nodiscard]] bool stable() const;

 private:
  /// The polynomial values of every block at s = jω (E = e^{−jωT} the exact delay).
  struct Values;
  [[nodiscard]] Values values(double omega) const noexcept;
  [[nodiscard]] ClosedLoopTransfer rational(const core::Polynomial& delay_num, const core::Polynomial& delay_den) const;
  /// Δ alone (what stable() needs), without the closed-loop numerators.
  [[nodiscard]] core::Polynomial characteristic(const core::Polynomial& delay_num, const core::Polynomial& delay_den) const;

  ControllerTf controller_;
  core::Polynomial plant_num_, plant_den_;        // Pm = plant_num/plant_den (den monic)
  core::Polynomial act_num_{1.0}, act_den_{1.0};  // rational actuator part
  core::Polynomial fb_num_{1.0}, fb_den_{1.0};    // feedback filter
  double delay_ = 0.0;
  bool has_load_ = false;
  bool has_load_tracking_ = false;
  // Two-mass numerators over plant_den: ωl/Tm (with higher modes in the chain: of load_estimate()), ωm/Tl, ωl/Tl; load_inertia Il (normalized).
  core::Polynomial load_num_, motor_dist_num_, load_dist_num_;
  double load_inertia_ = 1.0;
  /// What the feedback reads: the motor (controller_.feedback on ωm), the load (on ωl), or both
  /// (controller_.feedback on ωm, load_channel_ on ωl).
  enum class Measured { kMotor, kLoad, kBoth };
  Measured measured_ = Measured::kMotor;
  core::Polynomial load_channel_;  // Cl's numerator over controller_.feedback.den() (kBoth)
  /// The feedback numerators on ωm and on ωl (a zero polynomial for a channel not measured).
  [[nodiscard]] core::Polynomial motor_channel_num() const;
  [[nodiscard]] core::Polynomial load_channel_num() const;
  /// Σ channel·plant numerator: the loop's open numerator without A and F (ncm·np + ncl·nl).
  [[nodiscard]] core::Polynomial measured_combination() const;
  int pade_order_ = 6;
  double r_ = 0.0;
  core::Polynomial characteristic_;  // Δ with the Padé delay
};

}  // namespace servotwin::tuning
