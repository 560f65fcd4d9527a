#pragma once
/// \file
/// The one-call tuner that `servotwin tune` runs: from a fitted plant
/// model to a checked cascade controller.
///
/// Pipeline: normalize the model (known HF dynamics set aside: designed without, evaluated with),
/// give the C7.4 advice for its resonance ratio, find the admissible ω* range of the assigned pair
/// (C7.3), then choose ω* — the user's, or automatically the one that maximizes the load bandwidth
/// (J1, C7.8) while the loop evaluated WITH the HF dynamics is stable and keeps ‖S‖∞ <= Ms and the
/// tracking peak ‖ωl/ω*‖∞ <= Mt (‖ωm/ω*‖∞ when there is no load side) — then place the pair (PI)
/// or the virtual-inertia PID (C7.5), add the P position loop (C7.10) for pi+p, and analyse the
/// result (indices, margins, time responses).
///
/// hinf: the mixed-sensitivity controller of C7.14 (hinf.hpp) on the first mode's design plant
/// with the known HF dynamics (the delay as a Padé approximant), W1 = 1/Ms and W2's 1/Mt from the
/// options; w0S scanned from 0.05 to 2r on a log grid, each candidate with the first w0T of r, 2r,
/// 4r, 8r that meets the spec, the best load bandwidth chosen, the boundaries next to it and at the
/// upper end of the feasible w0S refined by bisection; analysed with the exact delay and the
/// higher modes.
///
/// lqg-pos, hinf-pos: the position controllers of C7.13 and C7.14 (inputs [φ*, φm]), searched
/// like lqg and hinf with the loop judged on positions: ‖S‖∞ <= Ms, the tracking peak of φl/φ*
/// (φm/φ* without a load side) <= Mt, and the bandwidth of φl/φ* through C7.13's reference
/// prefilter 1/(τ s + 1), the smallest τ that keeps the position free of overshoot (part of the
/// compensator). The position LQG designs on the first mode's two-mass realization; the position
/// H-infinity treats higher modes as hinf does. The indices of the result judge positions
/// (AnalysisOptions::position_outputs).
///
/// lqg: the velocity LQG of C7.13 on the first mode's two-mass realization (with its viscous
/// friction); kbw scanned from slow (1e3) to fast (1e-4) on a log grid, each candidate with its
/// largest feedforward kff within the spec (doubling, then bisection), the best load bandwidth
/// chosen and its boundary refined by bisection; analysed through its 2-DoF form with the HF
/// dynamics and higher modes included.

#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/controller.hpp"
#include "servotwin/tuning/hinf.hpp"
#include "servotwin/tuning/loop_analysis.hpp"
#include "servotwin/tuning/lqg.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

/// What the user asks for. Frequencies of ω* are normalized (ω*/ωz); HF dynamics and ts physical.
struct TuneOptions {
  Structure structure = Structure::kPi;
  double zeta_star = 0.8;               ///< damping of the assigned pair (C7.3)
  std::optional<double> omega_star;     ///< ω*/ωz; std::nullopt: automatic (J1 under Ms, Mt)
  /// PID: the virtual resonance ratio r̄ (C7.5; C7.15 uses 2). std::nullopt: automatic, the
  /// largest bandwidth over r̄ from 2 toward r (a lag or delay can leave no phase for the
  /// derivative gain that r̄ = 2 needs on a high-r plant).
  std::optional<double> target_r = 2.0;
  std::optional<double> tau;            ///< PID derivative filter [s]; default: default_derivative_time_constant
  bool allow_negative_kd = false;       ///< PID with r < r̄ (acceleration feedback)
  double ms = 1.5;                      ///< ‖S‖∞ limit
  double mt = 1.5;                      ///< tracking peak limit
  /// Least damping of the visible closed-loop poles (loop_analysis.hpp visible_poles), in (0, 1):
  /// automatic ω*/kbw/w0S also requires it. For a plant without a load side (higher modes) the
  /// tracking peak is the motor's, and the loop may leave a pole near an antiresonance barely
  /// damped (the load or the frame rings while the motor stands still): this asks for damping.
  std::optional<double> min_damping;
  /// The plant's higher modes lie in the drive train between motor and load
  /// (NormalizedPlant::chain_load): the searches then maximize the estimated load bandwidth through
  /// them instead of the motor's.
  bool chain_load = false;
  /// Multiplicative uncertainty weight W2(s) in physical s [rad/s]: when given, automatic ω* also
  /// requires robust performance sup(|S|/Ms + |W2 T|) < 1 and the result reports RS/NP/RP.
  std::optional<core::TransferFunction> w2;
  HfDynamics hf;                        ///< known HF dynamics, physical units
  std::optional<double> ts;             ///< drive sample period [s]: discretize the controller
  double setpoint_weight = 1.0;         ///< wp of the 2-DoF PI/PID
  std::size_t scan_points = 24;         ///< automatic ω*: candidates on the admissible range
  /// lqg: the weights of C7.13 (their kbw and feedforward are ignored: see the next two).
  VelocityLqgOptions lqg;
  /// lqg-pos: the position weights of C7.13 (their kbw is ignored: see kbw).
  PositionLqgOptions lqg_position;
  /// lqg: the bandwidth knob; std::nullopt: the kbw whose design, with its feedforward, has the
  /// largest load bandwidth within the spec of automatic ω* (stable with the HF dynamics, ‖S‖∞ <= Ms,
  /// tracking peak <= Mt and, with W2, robust stability and C7.13's robust tracking test).
  std::optional<double> kbw;
  /// lqg: kff; std::nullopt: the largest that keeps the spec above (C7.13: the tracking peak <= Mt).
  std::optional<double> feedforward;
  /// lqg with automatic kbw: when no kbw meets the spec, raise lqg.measurement_noise by decades (up
  /// to 10⁴ times) and search again (a note says so); false: fail with the tuner's message.
  bool raise_measurement_noise = true;
  /// hinf: w0S (normalized); std::nullopt: the automatic search of C7.14 (the largest load
  /// bandwidth within the spec of automatic ω*).
  std::optional<double> omega_0s;
  /// hinf: w0T (normalized); std::nullopt: r, raised to 2r, 4r, 8r while the spec fails (C7.14).
  std::optional<double> omega_0t;
  double xi_v = 0.8;  ///< hinf: damping of the relocated resonant pair, [0.707, 1]
  /// hinf on a plant with higher modes (C7.16): kActive designs on the full model and damps every
  /// mode; kPassive designs on it and cancels the higher ones (a notch); kFirstMode designs on
  /// mode 1 and only checks the full model. lqg/lqg+p: kFirstMode designs on mode 1, the others on
  /// the model extended by the higher modes (velocity_lqg with modes). No effect on a two-mass plant.
  ModeHandling hinf_modes = ModeHandling::kActive;
  /// hinf, hinf-pos: a roll-off low-pass at the controller's output, its corner [rad/s, physical]
  /// (VelocityHinfWeights::rolloff: designed with, the controller strictly proper); std::nullopt:
  /// C7.14's biproper controller.
  std::optional<double> rolloff_rad_s;
  /// pi, pid, pi+p: the drive's filters at the controller's output (drive_filter.hpp), part of the
  /// controller: the PI's pair is placed on the plant followed by them (pi_pole_placement of
  /// plant·F, exact), the PID's gains are chosen by the search evaluating every candidate with
  /// them, and the analysis includes them. hinf, hinf-pos, hinf-load take one first-order
  /// low-pass, their roll-off (rolloff_rad_s, designed with); the LQG structures none. Requires ts.
  std::vector<DriveFilterSpec> drive_filters;
  /// pi, pid, pi+p: `notch:auto`: a notch on the mode the PI cannot damp (auto_notch: a higher
  /// mode, else the first when r lies outside √3..√5), its width chosen by the bandwidth search
  /// among a ladder of candidates (the zeros cancel the mode's poles). Requires ts.
  bool auto_notch = false;
  /// hinf: the compensator's states after balanced truncation (the search designs every candidate
  /// at this order); std::nullopt: the minimal realization (VelocityHinfWeights::controller_order).
  std::optional<int> controller_order;
};

/// Everything the tuner found, for the CLI summary, the controller file and the report.
struct TuneResult {
  NormalizedPlant plant;            ///< the normalized design plant (HF dynamics in hf)
  ResonanceRatioAdvice advice;      ///< C7.4 verdict for r
  AdmissibleRange range;            ///< admissible ω* of the assigned pair
  Controller controller;            ///< the tuned controller (physical and normalized)
  /// Automatic ω* (lqg: kbw, from slow to fast): the scanned candidates (the parameter in
  /// omega_star, load bandwidth, ‖S‖∞, tracking peak, feasible).
  struct Candidate {
    double omega_star = 0.0, bandwidth = 0.0, peak_s = 0.0, peak_tracking = 0.0;
    double min_damping = 0.0;  ///< least visible closed-loop damping (evaluated only with TuneOptions::min_damping)
    bool stable = false, feasible = false;
  };
  std::vector<Candidate> scan;
};

/// Runs the pipeline. Throws core::InputError for a plant that cannot be tuned this way (from
/// normalize(): no mode, unstable, non-minimum-phase, r <= 1.05) with the fix in the message; for
/// options out of range (named by their CLI flag); for r < 1.3 ("recommend passive methods":
/// a notch or input shaper); for an empty admissible range; and when no ω* meets Ms/Mt (the
/// message gives the best achievable peaks).
[[nodiscard]] TuneResult tune(const fit::PlantModel& model, const TuneOptions& options);

}  // namespace servotwin::tuning
