#pragma once
/// \file
/// Unstructured multiplicative uncertainty of the velocity-loop plant (seed catalog C7.9):
/// P = Pn(1 + Δ W2) with ‖Δ‖∞ < 1, the weight W2 estimated from identification residuals, and
/// the robust-stability / nominal-performance / robust-performance tests of a PI/PID velocity loop
/// together with the largest bandwidth ω* that passes them.
///
///   RS: ‖W2 T‖∞ < 1,   NP: ‖W1 S‖∞ < 1 with W1 = 1/M_S,   RP: sup_ω (|W1 S| + |W2 T|) < 1.
///
/// RS is necessary and sufficient for stability under every stable Δ with ‖Δ‖∞ < 1 (small-gain
/// theorem, nominal loop stable); RP is the exact condition for ‖W1 S_Δ‖∞ < 1 under all such Δ
/// for a SISO loop.

#include <complex>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {

// ---------------------------------------------------------------- W2 from identification residuals

/// One bound of the relative model error: |P(jω)/Pn(jω) − 1| <= bound at ω.
struct ResidualBound {
  double omega = 0.0;  ///< frequency [rad/s] (or normalized, as long as W2 is read in the same unit)
  double bound = 0.0;  ///< >= 0
};

/// w_i = |P̂(jω_i)/Pn(jω_i) − 1| + 2σ_i/|Pn(jω_i)| (the second term only when the point's std_dev
/// is known, i.e. > 0: a two-sigma allowance for the measurement noise), ω_i = 2π·freq_hz.
/// Throws core::InputError naming "measured.points[i].<field>" for a non-finite or non-positive
/// frequency, non-increasing frequencies, a non-finite value or a negative std_dev, and naming
/// "measured.points[i].freq_hz" when the nominal model vanishes or is not finite there; and
/// "measured.points" when there are no points.
[[nodiscard]] std::vector<ResidualBound> relative_residuals(const fit::PlantModel& nominal,
                                                            const core::FrequencyResponse& measured);

/// A fitted envelope and how tight it is.
struct UncertaintyEnvelope {
  /// W2(s), stable and minimum phase, biproper: order 1 k (s + z)/(s + p) (z = 0 gives k s/(s + p)),
  /// order 2 k (s + z1)(s + z2)/((s + p1)(s + p2)); all of k, z, p >= 0, poles > 0.
  core::TransferFunction w2;
  /// Mean of log(|W2(jω_i)|/w_i) over the points with trapezoid weights in log ω (>= 0; 0 means
  /// W2 passes through every point): the "log-area" the fit minimizes.
  double log_area = 0.0;
  /// min_i |W2(jω_i)|/w_i (>= 1: the envelope property; the point that sets k has exactly 1).
  double min_ratio = 0.0;
};

/// The tightest envelope W2 of the given order (1 or 2) above the bounds: |W2(jω_i)| >= w_i at every
/// point with the smallest log-area.
///
/// Method: for fixed corner frequencies the gain is set by the binding point,
/// log k = max_i (log w_i − log|g(jω_i)|), with g = W2/k; this makes every candidate an envelope by
/// construction, and the log-area becomes a function of the corners alone. The corners are
/// searched in log ω: a 2-D grid over (z, p) — z also at 0 — followed by Nelder–Mead on
/// (log z, log p); order 2 starts from the order-1 result times a neutral section and runs
/// Nelder–Mead on the four log corners (keeping whichever order-1/order-2 candidate is tighter).
/// Zero bounds are allowed (they never bind). Points need not be sorted; they must be finite with
/// ω > 0 and bound >= 0, at least 3 of them with a positive bound (InputError naming
/// "residuals[i].omega"/"residuals[i].bound" or "residuals"). InputError naming "order" unless 1
/// or 2.
[[nodiscard]] UncertaintyEnvelope fit_uncertainty_envelope(std::span<const ResidualBound> residuals, int order = 1);

/// W2 from identification data: relative_residuals() then fit_uncertainty_envelope(); in rad/s.
[[nodiscard]] UncertaintyEnvelope uncertainty_weight_from_residuals(const fit::PlantModel& nominal,
                                                                    const core::FrequencyResponse& measured,
                                                                    int order = 1);

/// A weight in physical time rescaled to the normalized time of a NormalizedPlant:
/// W2n(s) = W2(s·ωz), i.e. the coefficient of s^k multiplied by ωz^k (then the denominator made
/// monic). |W2n(jω)| = |W2(jω·ωz)|. InputError naming "omega_z" unless finite and > 0.
[[nodiscard]] core::TransferFunction to_normalized_time(const core::TransferFunction& w2, double omega_z);

// ---------------------------------------------------------------- RS / NP / RP of a velocity loop

/// Frequency grid of the robustness tests (normalized frequencies).
struct RobustnessOptions {
  double omega_min = 1e-3;
  double omega_max = 1e3;
  std::size_t grid_points = 600;  ///< log grid; closed-loop and W2 pole frequencies are added
  double rel_tol = 1e-7;          ///< peak refinement (core::peak_on_grid)
};

/// The three tests; values are sup over the grid (refined), `*_omega` where attained.
struct RobustnessResult {
  double rs = 0.0;  ///< ‖W2 T‖∞
  double np = 0.0;  ///< ‖W1 S‖∞ = ‖S‖∞/M_S
  double rp = 0.0;  ///< sup_ω (|W1 S| + |W2 T|)
  double rs_omega = 0.0, np_omega = 0.0, rp_omega = 0.0;
  bool nominally_stable = false;  ///< VelocityLoop::stable() (rational closed loop, Padé delay)
  bool rs_ok = false;             ///< nominally stable and rs < 1
  bool np_ok = false;             ///< nominally stable and np < 1
  bool rp_ok = false;             ///< nominally stable and rp < 1
};

/// RS, NP and RP of the loop (T and S of VelocityLoop, i.e. with its HF dynamics when it was built
/// with them) for the weight w2 (normalized time, proper, stable) and the sensitivity limit
/// ms = M_S (> 1). The grid is options' log grid plus the damped frequency of every closed-loop
/// pole with damping below 0.5 and the W2 poles' moduli. InputError naming "ms" or "w2" ("w2" when
/// improper or with a pole in the closed right half-plane).
[[nodiscard]] RobustnessResult robustness(const VelocityLoop& loop, const core::TransferFunction& w2, double ms,
                                          const RobustnessOptions& options = {});

/// C7.13's sufficient robust performance test of a 2-DoF loop's tracking (the LQG compensators):
/// with the plant Pm(1 + Δ W2), |Δ| <= 1, the motor tracking ωm/ω* = F T becomes F T (1 + Δ W2)/(1 + Δ W2 T),
/// so sup_ω |F T| (1 + |W2|)/(1 − |W2 T|) / mt < 1 guarantees ‖ωm/ω*‖∞ < mt for every plant of the set.
/// A loop measuring the load (C7.17) controls the load: the same holds for ωl/ω* (the uncertainty
/// multiplies the torque, which reaches either velocity through the same plant), and it is judged.
struct RobustTracking {
  double value = 0.0;  ///< the sup above (+inf when ‖W2 T‖∞ >= 1 or the loop is unstable)
  double omega = 0.0;  ///< where attained (normalized)
  [[nodiscard]] bool ok() const noexcept { return value < 1.0; }
};

/// The test above on robustness()'s grid. InputError naming "mt" (unless finite and >= 1) or "w2".
[[nodiscard]] RobustTracking robust_tracking(const VelocityLoop& loop, const core::TransferFunction& w2, double mt,
                                             const RobustnessOptions& options = {});

/// Which test the ω* search applies.
enum class RobustTest {
  kRobustStability,   ///< RS only
  kRobustPerformance  ///< RP (which implies RS and NP)
};

/// What ended the search.
enum class UncertaintyLimit {
  kAdmissibleRange,      ///< the whole admissible range passes: ω* = its upper end
  kRobustStability,      ///< RS fails just above the returned ω*
  kNominalPerformance,   ///< RS holds, NP fails just above
  kRobustPerformance,    ///< RS and NP hold, RP fails just above
  kNothingPasses,        ///< no scan point passes (ω* = 0), or the admissible range is empty
};
/// "admissible range", "robust stability", "nominal performance", "robust performance",
/// "nothing passes".
[[nodiscard]] std::string to_string(UncertaintyLimit limit);

/// Result of largest_omega_star_with_uncertainty().
struct UncertaintyOmegaStar {
  double omega_star = 0.0;  ///< normalized; 0 when nothing passes
  UncertaintyLimit limit = UncertaintyLimit::kNothingPasses;
  PiGains gains;            ///< the design at omega_star (zero when nothing passes)
  RobustnessResult at_omega_star;
};

/// Settings of the ω* search.
struct UncertaintySearch {
  RobustTest test = RobustTest::kRobustPerformance;
  double kd = 0.0;    ///< ideal-derivative gain of a PID designed by virtual inertia (0: PI)
  double tau = 0.0;   ///< derivative filter (used in the loop; the placement uses kd, tau too)
  bool with_hf = true;  ///< evaluate the loop with plant.hf (the known HF dynamics not covered by W2)
  std::size_t scan_points = 24;
  RobustnessOptions grid;
};

/// The largest ω* in the admissible range (admissible_range(plant, zeta_star, kd)) whose design —
/// pi_pole_placement on plant.motor(false), then a VelocityLoop on `plant` (1-DoF, wp = 1) — passes
/// the test. Method (as largest_robust_omega_star of robustness.hpp): if ωmax passes, return it;
/// else scan downwards on scan_points geometric points from ωmax to max(ωmin, 1e-3 ωmax), and bisect
/// (to 1e-6 ωmax) between the first passing point and the failing one above it. A passing window
/// narrower than the scan spacing can be missed. InputError as admissible_range(), robustness(),
/// and "scan_points" unless in [2, 1000].
[[nodiscard]] UncertaintyOmegaStar largest_omega_star_with_uncertainty(const NormalizedPlant& plant, double zeta_star,
                                                                       const core::TransferFunction& w2, double ms,
                                                                       const UncertaintySearch& search = {});

}  // namespace servotwin::tuning
