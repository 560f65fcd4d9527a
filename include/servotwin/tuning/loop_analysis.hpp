#pragma once
/// \file
/// Indices of a PI/PID velocity loop (catalog C7.8, C7.15): bandwidths,
/// sensitivity peaks, gain/phase/modulus margins, the load-disturbance index J2, step overshoot and
/// settling, the ITAE of a load-torque step, the controller's high-frequency gain, and the choice
/// of ω* from J1/J2. All quantities in normalized units (time scaled by ωz).
///
/// Frequency indices use the exact frequency functions of VelocityLoop (delay e^{−jωT}); time
/// indices and the closed-loop poles use its rational closed loop (delay as a Padé approximant).
///
/// Method of the frequency indices: one pass over the grid evaluates every function; each local
/// maximum of a sampled |f| (a point above its left and not below its right neighbour, end points
/// included) whose value is at least half the sampled maximum is refined by core::peak_on_grid on
/// the bracket of its two neighbours (golden section in log ω to rel_tol). A refined peak cannot
/// gain more than the grid's resolution allows, so a local maximum below half of the largest
/// sample cannot become the supremum unless its peak was stepped over entirely; the grid contains
/// the |Im| of every lightly damped closed-loop pole (ζ < 0.5) and `extra_frequencies` to prevent
/// that.
///
/// Time indices: one exact zero-order-hold simulation (core::discretize_zoh; a step is constant
/// between samples, so the samples are exact) of all step responses, which share the
/// characteristic polynomial Δ. Step dt = 0.02/max|p| over the closed-loop poles p (50 samples
/// per time constant of the fastest pole), horizon = horizon_time_constants/min(−Re p) (15 time
/// constants of the slowest pole: its residue decays to e^{−15} ≈ 3e-7) over visible_poles (a
/// nearly cancelled mode would ask for a run of hours and shows in no response); when that needs more than
/// max_samples samples, dt = horizon/max_samples instead (still exact at the samples; only the
/// resolution of the overshoot, the settling-time interpolation and the ITAE quadrature drops).

#include <complex>
#include <cstddef>
#include <string>
#include <vector>

#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {

/// Frequency grid and simulation settings of the analysis.
struct AnalysisOptions {
  double omega_min = 1e-3;    ///< grid start (normalized, > 0)
  double omega_max = 1e3;     ///< grid end (normalized, > omega_min)
  std::size_t grid_points = 2000;  ///< log-spaced points (>= 16)
  double rel_tol = 1e-6;      ///< peak refinement (core::peak_on_grid), in [1e-12, 0.1]
  double settling_band = 0.02;  ///< settling-time band (2 %), in (0, 1)
  /// Frequencies added to the grid (inside [omega_min, omega_max]): plant resonances and
  /// antiresonances, so that their narrow peaks are not stepped over. The plant overload of
  /// analyse() adds 1 (ωz), r and the higher modes' frequencies.
  std::vector<double> extra_frequencies;
  /// Where hf_controller_gain is evaluated. <= 0: 10·r in the plant overload of analyse(); in the
  /// VelocityLoop overload (which does not know r) the limit |C(j∞)| (= |kp + kd/τ| for a PID) instead.
  double hf_gain_omega = 0.0;
  double horizon_time_constants = 15.0;  ///< simulation horizon in time constants of the slowest pole
  std::size_t max_samples = 20000;      ///< cap on the simulation samples (>= 100)
  /// The loop is a position controller's velocity_form (lqg.hpp): its reference is φ* and the
  /// indices judge positions, the tracking and disturbance outputs integrated once: bandwidths,
  /// tracking peaks and step indices of φm/φ* and φl/φ*, peak_load_disturbance ‖φl/Tl‖∞ and
  /// itae_load_step ∫ t |φl(t) − φl(∞)| dt (the load position keeps the shaft's static twist under
  /// motor-position feedback). S, T, margins, the torque and j2 (C7.8's ratio of the weighted load
  /// VELOCITY per torque: the uncontrolled load position has a double integrator W does not
  /// remove) are the loop's as they are.
  bool position_outputs = false;
};

/// Throws core::InputError naming the field ("omega_min", "grid_points", …) for options outside the
/// ranges documented above.
void validate(const AnalysisOptions& options);

/// The closed loop of a position controller's velocity form with its outputs as positions (φm/φ*,
/// φl/φ*, φm/Tl, φl/Tl: each divided by s, the numerator deflated where its constant term vanishes
/// to rounding, as a loop that holds its position gives). S, T and the effort are unchanged.
[[nodiscard]] ClosedLoopTransfer integrated_outputs(ClosedLoopTransfer closed_loop);

/// The indices of one loop. Peaks are sup over the grid (refined).
///
/// Unstable closed loop (Routh test of Δ, Padé delay included): closed_loop_stable = false, the
/// poles and hf_controller_gain are reported, the bandwidths and margins are NaN, the peaks, J2
/// and the time indices +infinity, the modulus margin 0. No exception.
/// Without a load side (higher modes): bandwidth_load, peak_tl, peak_load_disturbance, j2 and
/// itae_load_step are NaN, and overshoot/settling_time are the motor's.
struct LoopIndices {
  bool closed_loop_stable = false;
  /// −3 dB bandwidth of ωm/ω* (core::bandwidth: level 10^(−3/20) of the exact DC gain of the
  /// rational closed loop, 1 with integral action); +inf when |ωm/ω*| stays above it up to omega_max.
  double bandwidth_motor = 0.0;
  double bandwidth_load = 0.0;          ///< the same for ωl/ω* (J1's quantity)
  double peak_s = 0.0;                  ///< ‖S‖∞
  double peak_s_omega = 0.0;            ///< where ‖S‖∞ is attained
  double peak_t = 0.0;                  ///< ‖T‖∞
  double peak_tm = 0.0;                 ///< ‖ωm/ω*‖∞
  double peak_tl = 0.0;                 ///< ‖ωl/ω*‖∞
  double peak_load_disturbance = 0.0;   ///< ‖ωl/Tl‖∞ (closed loop)
  double j2 = 0.0;                      ///< ‖(ωl/Tl)_cl W‖∞ / ‖(ωl/Tl)_ol W‖∞, W = s/(s+1)
  /// Gain margin [dB] at the phase crossing (L(jω) real and negative) with the smallest |margin|
  /// (MATLAB `margin`'s choice; negative: a gain reduction destabilizes); +inf when there is none.
  double gain_margin_db = 0.0;
  double phase_crossover = 0.0;         ///< ω of that crossing (+inf when none)
  /// Phase margin [deg] = arg L(jωc) + 180° wrapped to (−180°, 180°] at the gain crossing
  /// (|L| = 1) with the smallest |margin|; +inf when |L| never crosses 1.
  double phase_margin_deg = 0.0;
  double gain_crossover = 0.0;          ///< ωc of that crossing (+inf when none)
  double modulus_margin = 0.0;          ///< 1/‖S‖∞
  double overshoot = 0.0;               ///< load-velocity (else motor) setpoint step: max y/y∞ − 1, >= 0
  double settling_time = 0.0;           ///< last exit from the settling band (interpolated); +inf if not settled
  double overshoot_motor = 0.0;         ///< the same for the motor velocity
  double settling_time_motor = 0.0;     ///< the same for the motor velocity
  double itae_load_step = 0.0;          ///< ∫ t |ωl(t)| dt for a unit load-torque step (trapezoidal)
  double peak_torque_step = 0.0;        ///< max |u| for a unit setpoint step
  double hf_controller_gain = 0.0;      ///< |C(jω)| at AnalysisOptions::hf_gain_omega (noise amplification)
  double min_damping = 0.0;             ///< min −Re p/|p| over the visible closed-loop poles (visible_poles)
  double sample_time = 0.0;             ///< simulation step used (normalized time)
  double horizon = 0.0;                 ///< simulation horizon used
  std::vector<std::complex<double>> closed_loop_poles;  ///< roots of Δ (Padé delay included)
};

/// The closed-loop poles a response can show: all but a lightly damped pole (ζ < 0.1) within
/// 1e-3·|p| of both a zero and a pole of the plant Pm, or of both of the feedback controller. Such
/// a pole belongs to a nearly cancelled pole-zero pair of one block, a mode the loop neither drives
/// nor sees (the third mode of C7.19's flexible frame: pole and zero 0.02 % apart), and its residue
/// in each of the four closed-loop functions (T, S, PS, CS) is of the size of that distance. A
/// plant pole cancelled by a controller zero (a notch, C7.16 passive) stays visible: the
/// disturbance response PS keeps it. All poles when every one is cancelled.
[[nodiscard]] std::vector<std::complex<double>> visible_poles(const VelocityLoop& loop,
                                                              const std::vector<std::complex<double>>& poles);
/// min −Re p/|p| over visible_poles (+inf for none).
[[nodiscard]] double least_visible_damping(const VelocityLoop& loop, const std::vector<std::complex<double>>& poles);

/// All indices of the loop. InputError for invalid options (validate()). The grid pass keeps its
/// sample buffers in a thread_local workspace (reused between calls; ~150 kB for 2000 points).
[[nodiscard]] LoopIndices analyse(const VelocityLoop& loop, const AnalysisOptions& options = {});

/// analyse() of VelocityLoop(plant, gains) (HF dynamics and higher modes included, Padé order 6),
/// with 1, r and the higher modes' frequencies added to the grid and hf_gain_omega defaulting to
/// 10·r.
[[nodiscard]] LoopIndices analyse(const NormalizedPlant& plant, const PidGains& gains,
                                  const AnalysisOptions& options = {});
/// The same for any 2-DoF controller (an LQG's two_dof_form()).
[[nodiscard]] LoopIndices analyse(const NormalizedPlant& plant, const ControllerTf& controller,
                                  const AnalysisOptions& options = {});
/// analyse() of a loop on `plant`, with the plant's frequencies (1 = ωz, r, the higher modes) added
/// to the grid and the HF gain taken at 10 r unless given (as the PidGains/ControllerTf overloads).
[[nodiscard]] LoopIndices analyse(const NormalizedPlant& plant, const VelocityLoop& loop, const AnalysisOptions& options);

/// J1/J2 search settings (C7.8).
struct IndexOptions {
  double peak_limit = 1.5;        ///< M_T: ‖ωl/ω*‖∞ must not exceed it for J1 (> 0)
  double zeta_star = 0.8;         ///< damping of the assigned pair
  double kd = 0.0;                ///< derivative gain of a PID (virtual inertia), 0 for PI
  double tau = 0.0;               ///< derivative filter (> 0 when kd ≠ 0)
  std::size_t omega_star_points = 40;  ///< log scan of the admissible range before refinement (>= 3)
  AnalysisOptions analysis;
};

/// The recommended ω* interval [argmin J2, argmax J1] and the setpoint weight wp that maximizes J1.
struct OmegaChoice {
  double omega_j1 = 0.0;   ///< ω* maximizing the load bandwidth under the peak limit (NaN: none feasible)
  double omega_j2 = 0.0;   ///< ω* minimizing J2
  double wp = 1.0;         ///< setpoint weight at omega_j1
  double j1 = 0.0;         ///< the load bandwidth at omega_j1 (0 when no ω* meets the peak limit)
  double j2 = 0.0;         ///< J2 at omega_j2
  bool interval_empty = false;  ///< omega_j2 > omega_j1, or no ω* meets the peak limit
  double range_min = 0.0;  ///< the scanned ω* range (admissible_range(), lower end raised to
  double range_max = 0.0;  ///< 0.02·upper end when it is open down to 0)
};

/// J1/J2 search (C7.8) over the admissible ω* range of the plant (admissible_range(plant,
/// zeta_star, kd)). Each ω* gets the gains of pi_pole_placement(plant.motor(false), ω*, ζ*, kd, τ)
/// (w_d = 0) and is evaluated on VelocityLoop(plant, gains) (HF dynamics and higher modes
/// included). J2 does not depend on wp. J1(ω*) = max over wp ∈ [0, 1] of the load bandwidth among
/// the wp with ‖ωl/ω*‖∞ <= peak_limit: wp ∈ {0, 0.1, …, 1}, then golden section (24 steps) on the
/// two intervals around the best feasible wp, an infeasible wp scoring −1 (so the search converges
/// onto the constraint boundary when the bandwidth grows towards it). An unstable ω* scores J1 = 0,
/// J2 = +inf. Both optima are then refined by golden section (40 steps) on the bracket of the best
/// scan point's neighbours.
///
/// InputError: the plant has no load side (higher modes or no two-mass realization: "J1/J2 need
/// the load velocity"), the admissible range is empty, or an option is out of range.
[[nodiscard]] OmegaChoice choose_omega_star(const NormalizedPlant& plant, const IndexOptions& options = {});

}  // namespace servotwin::tuning
