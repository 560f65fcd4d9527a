#pragma once
/// \file
/// The tuned controller as the library hands it to users (and io::controller_json writes it):
/// physical and normalized gains, the 2-DoF controller as a continuous and a discretized state
/// space, the design parameters and the predicted indices.
///
/// The cascade structures of chapter 7 (C7.3–C7.5, C7.10):
///   pi    u = (wp kp + ki/s) ω* − (kp + ki/s) ωm
///   pid   the same plus kd s/(τ s + 1) on the measurement (wd = 0: no torque kick on steps)
///   pi+p  a P position loop ω* = kpp (φ* − φ) over the PI velocity loop
///   lqg   the full-order velocity LQG compensator of C7.13 (inputs [ω*, ωm], 5 states)
///   lqg+p a P position loop over the LQG velocity loop (C7.13's more robust alternative to the
///         full position LQG)
///   hinf  the H-infinity mixed-sensitivity velocity controller of C7.14 (1-DoF, K0/s; inputs
///         [ω*, ωm], 9 states)
///   lqg-pos   the full-order position LQG of C7.13 (inputs [φ*, φm], 6 states) with its reference
///             prefilter 1/(τ s + 1) (one more state)
///   hinf-pos  the H-infinity mixed-sensitivity position controller of C7.14 (K0/s on the position
///             error; inputs [φ*, φm]) with the same kind of prefilter
///   hinf-load the H-infinity velocity controller of C7.17 measuring the LOAD velocity (inputs
///             [ω*, ωl]; a load encoder)
///   lqg-load  the load-side LQG of C7.17: integral action on the load velocity, a Kalman filter
///             measuring both velocities (inputs [ω*, ωm, ωl]; motor and load encoders)

#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/state_space.hpp"
#include "servotwin/tuning/drive_filter.hpp"
#include "servotwin/tuning/loop_analysis.hpp"
#include "servotwin/tuning/hinf.hpp"
#include "servotwin/tuning/lqg.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

/// Controller structure offered by the tuner.
enum class Structure { kPi, kPid, kPiP, kLqg, kLqgP, kHinf, kLqgPos, kHinfPos, kHinfLoad, kLqgLoad };

/// A structure whose controller is a general state space (no PID gains): lqg, lqg+p, hinf,
/// lqg-pos, hinf-pos, hinf-load, lqg-load.
[[nodiscard]] bool is_full_order(Structure structure) noexcept;

/// A structure with a P position loop over its velocity loop: pi+p, lqg+p.
[[nodiscard]] bool has_position_loop(Structure structure) noexcept;

/// A full-order position controller (inputs [φ*, φm], no velocity loop): lqg-pos, hinf-pos.
[[nodiscard]] bool is_position_controller(Structure structure) noexcept;

/// The structure controls the position (its reference is φ*): has_position_loop or
/// is_position_controller.
[[nodiscard]] bool controls_position(Structure structure) noexcept;

/// An H-infinity structure: hinf, hinf-pos, hinf-load.
[[nodiscard]] bool is_hinf(Structure structure) noexcept;

/// The controller measures the load velocity (C7.17): hinf-load, lqg-load.
[[nodiscard]] bool measures_load(Structure structure) noexcept;

/// The controller measures both velocities (inputs [ω*, ωm, ωl]): lqg-load.
[[nodiscard]] bool measures_both(Structure structure) noexcept;

/// An LQG structure: lqg, lqg+p, lqg-pos, lqg-load.
[[nodiscard]] bool is_lqg(Structure structure) noexcept;

/// "pi", "pid", "pi+p", "lqg", "lqg+p", "hinf", "lqg-pos", "hinf-pos", "hinf-load", "lqg-load".
[[nodiscard]] std::string to_string(Structure structure);
/// Inverse of to_string; std::nullopt for an unknown name.
[[nodiscard]] std::optional<Structure> structure_from_string(const std::string& name);

/// The normalization of the plant the controller was designed for (catalog §0).
struct PlantScales {
  double omega_z = 1.0;        ///< first antiresonance [rad/s]
  double motor_inertia = 1.0;  ///< Im in the model's units
  double r = 0.0, zeta_z = 0.0, zeta_p = 0.0, a = 0.0;
};

/// The design choices behind the gains (normalized units; frequencies relative to ωz).
struct DesignParameters {
  double omega_star = 0.0;            ///< assigned pair's natural frequency ω*/ωz (0: full-order, none)
  double zeta_star = 0.0;             ///< assigned pair's damping (0: full-order, none)
  std::optional<double> r_target;     ///< PID: virtual resonance ratio r̄
  std::optional<double> ms, mt;       ///< peak limits the design respected
  std::optional<double> min_damping;  ///< least visible closed-loop damping the design respected (TuneOptions::min_damping)
  std::string omega_star_source;      ///< "given", "J1 (load bandwidth)", "limited by ‖S‖ <= Ms", ...
};

/// Robustness numbers of the design (absent when not evaluated).
struct RobustnessSummary {
  std::optional<double> rs;  ///< ‖W2 T‖∞ (robust stability when < 1)
  std::optional<double> np;  ///< ‖W1 S‖∞ with W1 = 1/Ms (nominal performance when < 1)
  std::optional<double> rp;  ///< sup(|W1 S| + |W2 T|) (robust performance when < 1)
  /// C7.13's sufficient robust tracking test of the 2-DoF loop, sup |W1 F T|(1 + |W2|)/(1 − |W2 T|)
  /// with W1 = 1/Mt and F T = ωm/ω* (< 1: the motor tracking peak stays below Mt for every plant
  /// in the uncertainty set; +inf where |W2 T| >= 1).
  std::optional<double> rp_tracking;
};

/// The weights and optimum of an H-infinity design (C7.14), normalized frequencies.
struct HinfSummary {
  double omega_0s = 0.0;           ///< w0S: dominant closed-loop pole pair
  double omega_0t = 0.0;           ///< w0T: bandwidth cap
  double xi_v = 0.0;               ///< damping of the relocated resonant pair
  double gamma_optimal = 0.0;      ///< optimal gamma of the weighted problem
  double gamma = 0.0;              ///< gamma of the controller (gamma_optimal times the backoff)
  std::string omega_0s_source;     ///< "given", or what limited the automatic w0S
  ModeHandling modes = ModeHandling::kFirstMode;  ///< how the design treated higher modes (C7.16)
  std::optional<double> rolloff;   ///< corner of the controller's roll-off low-pass (normalized; none: biproper)
  int full_order = 0;              ///< states of K = K0/s before the reduction (the compensator has fewer)
  std::vector<double> hankel;      ///< Hankel singular values of K's stable part, descending
  double reduction_error_bound = 0.0;  ///< ||K_full - K||_inf bound of the reduction (0: none)
};

/// A full-order (LQG or H-infinity) design, normalized units (C7.13, C7.14).
struct FullOrderSummary {
  VelocityLqgOptions weights;         ///< lqg: the weights used, with the chosen kbw and kff (unused for hinf)
  std::optional<HinfSummary> hinf;    ///< hinf: the weights and gamma (absent for lqg)
  std::string kbw_source;             ///< "given", or what limited the automatic kbw
  std::string feedforward_source;     ///< "given", "none", or what limited the automatic kff
  /// lqg-pos: the position weights used, with the chosen kbw (absent for the other structures).
  std::optional<PositionLqgOptions> position_weights;
  /// lqg-pos, hinf-pos: the reference prefilter's time constant (normalized; 0: none), C7.13's
  /// smallest keeping the load position free of overshoot (‖φl/φ*‖∞ <= 1). Its state is the
  /// compensator's first.
  double prefilter_tau = 0.0;
  /// normalized: inputs [ω*, ωm] (lqg-pos, hinf-pos: [φ*, φm]; hinf-load [ω*, ωl]; lqg-load
  /// [ω*, ωm, ωl]), output u (time by ωz, torque by
  /// Im ωz, positions by 1/ωz)
  core::StateSpace compensator;
  std::vector<std::complex<double>> controller_poles;  ///< normalized
  bool controller_stable = false;     ///< every compensator pole stable (the integrator excepted)
};

/// The P position loop of a pi+p design (C7.10), normalized units (gains in units of ωz); for
/// lqg-pos and hinf-pos only the indices (the kpp fields are 0 and empty).
struct PositionSummary {
  double kpp_nominal = 0.0;     ///< largest Kpp without overshoot of the load position (‖φl/φ*‖∞ <= 1)
  std::optional<double> kpp_rs;        ///< largest robustly stable Kpp (with W2)
  std::optional<double> kpp_rp_exact;  ///< largest Kpp with the worst-case motor position peak <= 1 (with W2)
  double bandwidth_load = 0.0;  ///< −3 dB bandwidth of φl/φ* at the chosen Kpp (J1)
  double j2 = 0.0;              ///< ‖φl/Tl‖∞ at the chosen Kpp
  double peak_load_tracking = 0.0;  ///< ‖φl/φ*‖∞ at the chosen Kpp
};

/// A tuned cascade controller.
struct Controller {
  Structure structure = Structure::kPi;
  PidGains normalized;                  ///< velocity-loop gains, normalized (kd = tau = 0 for PI; all 0 for lqg)
  PidGains physical;                    ///< the same in the model's units (to_physical)
  std::optional<FullOrderSummary> full_order;  ///< lqg only: the compensator (the gains are then unused)
  std::optional<double> kpp_normalized;  ///< pi+p, lqg+p: position gain, normalized
  std::optional<double> kpp_physical;    ///< pi+p, lqg+p: position gain [1/s]
  PlantScales plant;
  DesignParameters design;
  LoopIndices predicted;                ///< velocity-loop indices, normalized units
  RobustnessSummary robustness;
  std::optional<PositionSummary> position;           ///< pi+p, lqg+p, lqg-pos, hinf-pos only
  /// pi, pid, pi+p: the drive's filters at the controller's output (drive_filter.hpp), physical.
  /// They are part of the controller: normalized_controller(), controller_state_space(),
  /// controller_loop() and discretize_controller() include them.
  std::vector<DriveFilter> drive_filters;
  std::optional<core::DiscreteStateSpace> discrete;  ///< the velocity controller at the drive's period
  std::optional<double> prewarp_rad_s;               ///< Tustin prewarp frequency (physical)
  std::vector<std::string> notes;       ///< warnings and facts a user must see
};

/// The 2-DoF velocity controller as a state space with inputs [ω*, ωm] and output u (physical or
/// normalized, as the gains): a PI has the integrator state, a PID also the derivative filter's.
[[nodiscard]] core::StateSpace controller_state_space(const PidGains& gains);

/// A normalized velocity-loop controller (inputs [ω*, ωm], output u) in the model's units: time
/// scaled by 1/ωz, torque by Im ωz (velocities are not scaled): A ωz, B ωz, C Im ωz, D Im ωz.
/// `position_inputs` (inputs [φ*, φm]): a normalized position is ωz times the physical one (the
/// integral of an unscaled velocity over normalized time), so B and D take one more factor ωz.
[[nodiscard]] core::StateSpace to_physical(const core::StateSpace& normalized, const PlantScales& plant,
                                          bool position_inputs = false);

/// The controller in the model's units: the PID's realization followed by its drive filters, or
/// the full-order compensator de-normalized. Throws std::invalid_argument for a full-order structure without its compensator.
[[nodiscard]] core::StateSpace controller_state_space(const Controller& controller);

/// `controller` followed by the filter `f` at its output: both transfer functions times f (their
/// common denominator stays common).
[[nodiscard]] ControllerTf with_output_filter(const ControllerTf& controller, const core::TransferFunction& f);

/// The normalized velocity controller as the 2-DoF transfer functions a VelocityLoop takes: the
/// PID's (with its drive filters, on the normalized time axis), or the full-order compensator's two_dof_form() (a position controller's in its
/// velocity_form(): the loop's S, T and margins are then the position loop's).
[[nodiscard]] ControllerTf normalized_controller(const Controller& controller);

/// A full-order `structure`'s normalized compensator as the transfer functions a VelocityLoop
/// takes: its two_dof_form(), in velocity_form() for a position controller. std::invalid_argument
/// for a structure measuring both velocities (three inputs: compensator_loop builds its loop).
[[nodiscard]] ControllerTf compensator_form(Structure structure, const core::StateSpace& compensator);

/// The loop of a full-order `structure`'s normalized compensator on `plant`: compensator_form()
/// around the motor, or around the load for a load-measuring structure (VelocityLoop::load_feedback
/// on the first mode), or two_measurement_form() around both (VelocityLoop::two_measurements). `with_hf` and `with_higher_modes` as in VelocityLoop.
[[nodiscard]] VelocityLoop compensator_loop(const NormalizedPlant& plant, Structure structure,
                                           const core::StateSpace& compensator, bool with_hf = true,
                                           bool with_higher_modes = true);

/// The loop of `controller` on `plant` (normalized): the PID's, or compensator_loop(). `with_hf`
/// and `with_higher_modes` as in VelocityLoop (a load-measuring loop always has the first mode only).
[[nodiscard]] VelocityLoop controller_loop(const NormalizedPlant& plant, const Controller& controller,
                                          bool with_hf = true, bool with_higher_modes = true);

/// Tustin discretization of controller_state_space at the drive period ts [s] (physical gains),
/// prewarped at `prewarp_rad_s` when given (it must lie below π/ts). Throws core::InputError
/// (field "ts") when ts is not finite and > 0 or the prewarp frequency lies at or above Nyquist.
[[nodiscard]] core::DiscreteStateSpace discretize_controller(const PidGains& physical, double ts,
                                                             std::optional<double> prewarp_rad_s = std::nullopt);
/// The same for any controller (controller_state_space(controller)); drive filters are discretized
/// each at its own prewarp frequency (make_drive_filter at ts), as a drive runs them.
[[nodiscard]] core::DiscreteStateSpace discretize_controller(const Controller& controller, double ts,
                                                             std::optional<double> prewarp_rad_s = std::nullopt);

}  // namespace servotwin::tuning
