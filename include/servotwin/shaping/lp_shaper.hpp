#pragma once
/// \file
/// Multi-mode input shapers by direct linear-programming synthesis (catalog C6.4 option 3,
/// dissertation Sec. 6.3, eqs. 6.78 / 6.79, examples E22 / E23).
///
/// The impulses sit on a uniform grid t_i = (i − 1)·Tp, i = 1..n (Tp a multiple of the control
/// sample period, so the shaper needs no discretization); the amplitudes A_i ≥ 0 are the LP
/// unknowns:
///
///   minimize   J·A,   J2 = [1, k+1, 2k+1, …, k(n−1)+1] (k > 0, favours short shapers),
///                     J1 = [0, 1, 1, …, 1] (k = 0: maximize the first impulse)
///   subject to Σ A_i = 1, 0 ≤ A_i ≤ max_pulse,
///              per mode (ω, ζ), ω_d = ω√(1−ζ²), and per derivative order l = 0..d (C6.3):
///                Σ A_i t_i^l e^{ζω t_i} cos(ω_d t_i) = 0,  Σ A_i t_i^l e^{ζω t_i} sin(ω_d t_i) = 0
///              (l = 0: zero vibration; l = 1: zero slope of V in ω and ζ; l = 2: zero curvature),
///              per sensitivity bound (ω_s, ζ_s, S_max), with C, S the sums above at ω_s, l = 0:
///                |C|, |S| ≤ S_max e^{ζ_s ω_s t_n}/√2  (the square inscribed in the circle, so
///                V(ω_s) ≤ S_max with t_n = (n − 1)·Tp, the grid's end).
///
/// Every row is scaled analytically before it reaches the solver (by e^{−ζω t_n} and t_n^{−l}, so
/// all coefficients lie in [−1, 1] however long or damped the shaper is) and the solution GLPK's
/// simplex returns is checked against the constraints in that normalized form: |C|, |S| of every
/// zero-vibration and derivative row ≤ 1e-9, bounds within 1e-9, Σ A = 1 within 1e-9. GLPK never
/// prints (messages off); its problem object lives in an RAII wrapper.
///
/// Counting (C6.4): the shaper's transform is a polynomial of degree n − 1 in e^{−sTp} that must
/// vanish (d + 1 times) at 2 conjugate points per mode, so generically n ≥ 2m(d + 1) + 1; fewer
/// pulses work only on special grids (ω_d Tp = π: the two-pulse ZV).
///
/// Frequencies in rad/s, times in s. Thread-safe as far as GLPK is (Debian's GLPK 5 keeps its
/// environment per thread).

#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// A mode to cancel.
struct LpMode {
  double omega = 0.0;  ///< natural frequency [rad/s], finite and > 0
  double zeta = 0.0;   ///< damping ratio in [0, 1)
};

/// An upper bound on the residual vibration at one frequency (C6.3): V(omega, zeta) ≤ s_max,
/// imposed conservatively as 4 linear inequalities.
struct SensitivityBound {
  double omega = 0.0;  ///< frequency [rad/s], finite and > 0
  double zeta = 0.0;   ///< damping of the mode at that frequency, [0, 1)
  double s_max = 0.0;  ///< largest admissible V, finite and > 0
};

/// The LP's grid, constraints and cost.
struct LpShaperOptions {
  double pulse_spacing = 0.0;  ///< Tp [s] > 0; grid t_i = (i − 1)·Tp
  /// n ≥ 1; 0 = use the smallest feasible n (C6.4 step 2) with (n − 1)·Tp ≤ max_duration.
  int pulse_count = 0;
  int derivative_order = 0;  ///< d: 0 = zero vibration only; 1 adds zero slope per mode; 2 adds zero curvature
  std::vector<SensitivityBound> bounds;  ///< optional robustness points
  double cost_k = 1.0;    ///< k ≥ 0 of J2; 0 selects J1 (see the file comment)
  double max_pulse = 1.0; ///< upper bound on every A_i, > 0
  /// Longest shaper considered when pulse_count = 0 [s]; 0 = automatic: twice the duration of the
  /// convolution of per-mode ZV^(d+1) shapers, 2·Σ_k (d + 1)·π/ω_dk (for the E22 modes with d = 1,
  /// 2 × 10.98 s — E21's convolution length).
  double max_duration = 0.0;
};

/// One solved LP: the shaper and its grid.
struct LpCandidate {
  /// Type "lp", omega/zeta of the first mode given. Times on the grid; impulses with A_i ≤ 1e-12
  /// are dropped (they are zero up to the solver's rounding), except the first at t = 0, which is
  /// always kept so that times.front() == 0 (at an optimum it is never zero: a solution with
  /// A_1 = 0 shifted one step earlier would be feasible and cheaper). Amplitudes sum to 1.
  Shaper shaper;
  double pulse_spacing = 0.0;  ///< Tp [s]
  int pulse_count = 0;         ///< n, the grid size (the shaper may have fewer nonzero impulses)
  int multiple = 0;            ///< Tp / sample period in lp_shaper_search, 0 otherwise
  double cost = 0.0;           ///< J·A at the optimum
  /// Grid duration (n − 1)·Tp [s] (the bounds refer to it); shaper.duration() is shorter when the
  /// last grid impulse is zero.
  [[nodiscard]] double grid_duration() const noexcept { return pulse_spacing * (pulse_count - 1); }
};

/// Solves the LP of the file comment. Throws core::InputError naming the field for bad options
/// (modes empty; modes[k].omega not finite or ≤ 0; modes[k].zeta outside [0, 1); pulse_spacing not
/// finite or ≤ 0; pulse_count < 0 or > 100000; derivative_order outside 0..2; bounds[k] fields;
/// cost_k < 0; max_pulse ≤ 0; max_duration < 0), when a mode turns by a multiple of 2π per grid
/// step (every impulse then adds in phase: no shaper on this grid cancels it), and when the LP is
/// infeasible (the message gives n and Tp and, for pulse_count = 0, the duration searched). Throws
/// std::runtime_error when GLPK fails or returns a solution that violates the constraints (a
/// numerical failure, not bad input).
LpCandidate lp_shaper_design(const std::vector<LpMode>& modes, const LpShaperOptions& options);

/// lp_shaper_design(modes, options).shaper.
Shaper lp_shaper(const std::vector<LpMode>& modes, const LpShaperOptions& options);

/// The grid search of C6.4 steps 1–4.
struct LpSearchOptions {
  double sample_period = 0.0;  ///< T [s] > 0: candidate spacings Tp = T, 2T, 3T, …
  /// Largest multiple tried; 0 = all with Tp ≤ π/ω_d of the lowest mode (C6.4 step 3).
  int max_multiple = 0;
};

/// For every Tp = j·T (j = 1..max_multiple), the smallest feasible n (with (n − 1)·Tp ≤
/// base.max_duration, see LpShaperOptions) and the optimal shaper of that size; base.pulse_spacing
/// and base.pulse_count are ignored. Spacings where no n fits, or where a mode turns by a multiple
/// of 2π per step, are skipped. Candidates are sorted by grid duration (n − 1)·Tp, then n, then Tp
/// (durations compared exactly as integer multiples of T). Throws core::InputError for bad options
/// (as lp_shaper_design, plus sample_period, max_multiple < 0 or a multiple count over 100000) and
/// when no spacing admits a shaper.
///
/// Feasibility is monotone in n (appending a zero impulse keeps every constraint), so each spacing
/// needs only a few feasibility LPs: a galloping search starting from the previous spacing's
/// duration, then bisection.
std::vector<LpCandidate> lp_shaper_search(const std::vector<LpMode>& modes, const LpShaperOptions& base,
                                          const LpSearchOptions& search);

}  // namespace servotwin::shaping
