#pragma once
/// \file
/// PI and PID velocity-loop design for flexible drives by partial pole placement (seed catalog
/// C7.1–C7.7).
///
/// Control law (2DoF, catalog C7.2): Tm = Kp(w_p ω* − ωm) + (Ki/s)(ω* − ωm) + (Kd s/(τ s + 1))(w_d ω* − ωm).
/// The weights w_p, w_d shape the reference response only; the closed-loop poles are the roots of
///
///   c(s) = s (τ s + 1) Dp(s) + [(Kp s + Ki)(τ s + 1) + Kd s²] N(s)      for the plant N/Dp = ωm/Tm.
///
/// The designer assigns one pair s² + 2ζ*ω* s + ω*² (ω* the bandwidth knob, ζ* its damping);
/// the remaining poles follow. Functions taking a NormalizedPlant work in normalized units (time
/// scaled by ωz, torque by Im·ωz); to_physical() converts the gains. pi_pole_placement() works
/// in whatever units its plant is given in.
///
/// Errors: out-of-range user values (ω* <= 0, ζ* <= 0, r <= 1, …) throw core::InputError naming
/// the parameter.

#include <array>
#include <complex>
#include <string>
#include <vector>

#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/normalized_plant.hpp"

namespace servotwin::tuning {

/// PI gains Kp, Ki.
struct PiGains {
  double kp = 0.0;
  double ki = 0.0;
};

/// PID gains of the 2DoF law above (τ: derivative filter time constant, 0 = ideal derivative).
struct PidGains {
  double kp = 0.0;
  double ki = 0.0;
  double kd = 0.0;
  double tau = 0.0;
  double wp = 1.0;  ///< proportional setpoint weight w_p ∈ [0, 1]
  double wd = 0.0;  ///< derivative setpoint weight w_d ∈ [0, 1] (0: no torque kick on steps)
};

// ---------------------------------------------------------------- rigid-body tunings (C7.1)

/// Symmetric optimum on the rigid model 1/(J s (τ s + 1)): Kp = J/(2τ), Ki = J/(8τ²).
/// InputError unless inertia > 0 and lag_time_constant > 0.
[[nodiscard]] PiGains pi_symmetric_optimum(double inertia, double lag_time_constant);
/// PI pole placement on the rigid model 1/(J s): Kp = 2ζ*ω* J, Ki = J ω*².
[[nodiscard]] PiGains pi_rigid_pole_placement(double inertia, double omega_star, double zeta_star);

// ---------------------------------------------------------------- closed forms (test oracles, limit analysis)

/// Eq. 7.36: PI gains on the undamped normalized two-mass plant (1/s)(s² + 1)/(s² + r²).
[[nodiscard]] PiGains pi_closed_form_undamped(double omega_star, double zeta_star, double r);
/// Eq. 7.63: PI gains on the damped frictionless normalized plant (1/s)(s² + 2ζz s + 1)/(s² + 2ζz r² s + r²).
/// InputError when the assigned pair coincides with the antiresonance zeros (denominator 0:
/// ζ* = ζz and ω* = 1).
[[nodiscard]] PiGains pi_closed_form_damped(double omega_star, double zeta_star, double r, double zeta_z);
/// The upper end of the positive-gain range of eq. 7.63 in (0, 1]: the smallest real root of
/// num_p·num_i in (0, 1] (from core::Polynomial::roots), or 1 when there is none (catalog C7.3).
[[nodiscard]] double frictionless_gain_limit(double r, double zeta_z, double zeta_star);

// ---------------------------------------------------------------- numeric pole placement (production path)

/// Result of a numeric partial pole placement.
struct PolePlacement {
  PiGains gains;
  /// ‖M⁻¹‖₂ of the 2×2 placement system M with each column scaled to the coefficient magnitude
  /// Σ|c_k|ω*^k of its polynomial: how much relative errors of the plant coefficients are
  /// amplified in the gains. O(1–100) normally; large when the pair sits near plant zeros.
  double condition_number = 0.0;
};

/// Numeric partial pole placement for any plant ωm/Tm = N/Dp (catalog C7.3 "numerical
/// equivalent"): (Kp, Ki) such that s² + 2ζ*ω* s + ω*² divides c(s), with Kd and τ
/// given (0, 0 for a PI). The two real conditions are the coefficients of the remainder of
/// c(s) modulo the pair, computed on the frequency axis scaled by ω* (so the rows are O(1)); for
/// ζ* < 1 they are equivalent to Re/Im of c(s1) = 0, for ζ* = 1 to c(−ω*) = c′(−ω*) = 0, and
/// they are continuous across ζ* = 1 (ζ* > 1 places two real poles). The columns are scaled
/// to their polynomials' coefficient magnitudes before solving (see PolePlacement).
///
/// InputError for ω* <= 0, ζ* <= 0, τ < 0, non-finite values, a plant whose c(s) has degree < 2,
/// or a singular system (condition number > 1e12: the pair coincides with plant zeros).
[[nodiscard]] PolePlacement pi_pole_placement(const core::TransferFunction& plant, double omega_star,
                                              double zeta_star, double kd = 0.0, double tau = 0.0);

/// The closed-loop characteristic polynomial c(s) above for the plant N/Dp and PID gains (w_p,
/// w_d do not enter).
[[nodiscard]] core::Polynomial closed_loop_polynomial(const core::TransferFunction& plant, const PidGains& gains);

/// The poles left after the assigned pair: c(s) = (lead) (s² + 2ζ*ω* s + ω*²)(s² + 2ζ2ω2 s + ω2²)
/// for a PI (or ideal-derivative PID) on the two-mass design model.
struct SecondPair {
  double omega = 0.0;       ///< ω2 = sqrt(product of the two roots) (NaN when the product is < 0)
  double zeta = 0.0;        ///< ζ2 (> 1: two real roots)
  double min_radius = 0.0;  ///< smallest root modulus: ω2 for a complex pair, ω2(ζ2 − sqrt(ζ2² − 1)) when real
  bool real = false;        ///< the two roots are real
  bool stable = false;      ///< both roots in the open left half-plane
  std::array<std::complex<double>, 2> roots{};  ///< the roots (upper member of a complex pair first)
};

/// Second pair of the PI (plus ideal derivative `kd`) loop on plant.motor(false), by exact
/// division of c(s) by the assigned pair. InputError when the gains do not place the pair (the
/// division remainder exceeds 1e-6 of c's scale).
[[nodiscard]] SecondPair second_pair(const NormalizedPlant& plant, const PiGains& gains, double omega_star,
                                     double zeta_star, double kd = 0.0);

// ---------------------------------------------------------------- admissible range and limits (C7.3, C7.4)

/// What ends an admissible ω* interval.
enum class RangeLimit {
  kNone,               ///< lower end open: admissible down to ω* → 0 (frictionless plants)
  kFullBandwidth,      ///< upper end at ω* = 1 (= ωz), the bandwidth cap of C7.4
  kIntegralGain,       ///< Ki <= 0 beyond this point
  kProportionalGain,   ///< Kp <= 0 (with friction: below ω*min, Kp → −r²a as ω* → 0)
  kStability,          ///< closed loop not Hurwitz (Routh test on c(s))
  kSecondPairRadius,   ///< the second pair's smallest root modulus falls below ω* (not dominant)
  kPlacement,          ///< the pair cannot be placed (singular system)
};
/// "none", "full bandwidth", "Ki <= 0", "Kp <= 0", "closed loop unstable", "second pair radius",
/// "pair cannot be placed".
[[nodiscard]] std::string to_string(RangeLimit limit);

/// The admissible bandwidths [omega_min, omega_max] (normalized) of a PI (or ideal-derivative
/// PID) on the design model: Kp > 0, Ki > 0 (stable, minimum-phase controller), closed loop
/// Hurwitz, and the second pair's smallest root modulus >= ω*·(1 − 1e-9) (the assigned pair
/// dominates; equality holds at ω* = 1 when r <= sqrt(4ζ* + 1)). Capped at ω* = 1.
struct AdmissibleRange {
  double omega_min = 0.0;  ///< 0 when admissible down to ω* → 0
  double omega_max = 0.0;
  RangeLimit lower = RangeLimit::kNone;
  RangeLimit upper = RangeLimit::kNone;
  [[nodiscard]] bool empty() const noexcept { return !(omega_max > omega_min); }
};

/// The first admissible interval of ω* ∈ (0, 1] for ζ* and an ideal derivative gain `kd`
/// (normalized). Method: a log grid of 96 points over [1e-3, 1] (lower end a/100 when the rigid
/// pole is smaller), each point a numeric pole placement + Routh test + second pair, then 60
/// bisection steps on each boundary. For an exactly frictionless plant (a = 0, ζp = r ζz to 1e-12)
/// the positive-gain limit comes from frictionless_gain_limit() on the virtual plant of `kd`.
/// An admissible window narrower than the grid spacing (~7 %) can be missed. Empty
/// (omega_max = 0) when no grid point is admissible; `upper` then names the first point's failure.
[[nodiscard]] AdmissibleRange admissible_range(const NormalizedPlant& plant, double zeta_star, double kd = 0.0);

/// The best second-pair damping a PI can give (catalog C7.4 table "ξ2max").
struct DampingLimit {
  double zeta2_max = 0.0;   ///< max over ω* of ζ2 (values > 1: the pair is real)
  double omega_star = 0.0;  ///< where it is attained
};
/// Max of ζ2 over ω* ∈ (0, 1] where the gains are positive and the loop is stable (the dominance
/// condition of admissible_range() is not applied: that is the C7.4 table's definition). Grid of
/// 96 points, then golden-section refinement to 1e-10 around the best point. InputError when no
/// such ω* exists.
[[nodiscard]] DampingLimit max_second_pair_damping(const NormalizedPlant& plant, double zeta_star);

/// Classes of catalog C7.4 / Ch. 9 (damping-based range ⟨√3, √5⟩, misprint 21).
enum class RatioClass {
  kUncontrollable,  ///< r < 1.3
  kUnderdamped,     ///< 1.3 <= r < √3
  kSweetSpot,       ///< √3 <= r <= √5
  kSluggish,        ///< r > √5
};

/// The verdict printed to the user.
struct ResonanceRatioAdvice {
  double r = 0.0;
  double r_full_bandwidth = 0.0;  ///< sqrt(4ζ* + 1): ω* = ωz reachable iff r <= this
  bool full_bandwidth = false;    ///< r <= r_full_bandwidth
  RatioClass kind = RatioClass::kSweetSpot;
  std::string verdict;            ///< one line, see advise()
};

/// C7.4 rules: r < 1.3 "practically uncontrollable with motor feedback, use passive methods
/// (shaping)"; r < √3 "cannot be damped to ξ ≥ 0.707 by PI"; √3 <= r <= √5 "PI sweet spot, r ≈ 2
/// gives ≈ 150 % of ωz"; r > √5 "PI sluggish; PID to r̄ = 2 (+≈45 %) or full order (≈ 200 % of
/// ωz)". InputError unless r > 1 and ζ* > 0 (finite).
[[nodiscard]] ResonanceRatioAdvice advise(double r, double zeta_star);

// ---------------------------------------------------------------- PID as virtual inertia (C7.5)

/// Kd (normalized, i.e. in units of Im) that makes the motor look like Im(1 + Kd), so that the
/// virtual plant has resonance ratio r̄: Kd = (r² − 1)/(r̄² − 1) − 1. Negative for r < r̄.
/// InputError unless r > 1 and r_target > 1.
[[nodiscard]] double virtual_inertia_kd(double r, double r_target);

/// The smallest derivative filter bandwidth we allow: 1/τ = max(r, 5 ω*) (normalized:
/// above the resonance and five times the assigned bandwidth). Noise may call for less.
[[nodiscard]] double default_derivative_time_constant(double r, double omega_star);

/// A PID design with its diagnostics.
struct PidDesign {
  PidGains gains;                        ///< normalized; w_p = 1, w_d = 0
  double r_virtual = 0.0;                ///< the target r̄
  double condition_number = 0.0;         ///< of the pole placement
  bool closed_loop_stable = false;       ///< on the design model, with the filter τ
  bool controller_minimum_phase = true;  ///< zeros of (Kp s + Ki)(τ s + 1) + Kd s² in the open LHP
  std::vector<std::string> warnings;     ///< e.g. negative Kd consequences
};

/// PID by virtual inertia (C7.5): Kd = virtual_inertia_kd(r, r̄), then the PI pair placed on the
/// design model with that Kd and the filter τ included (numeric pole placement; with τ = 0 this
/// equals the r̄ PI design times 1 + Kd, the closed-loop poles being exactly the r̄ design's). w_d
/// = 0. A negative Kd (r < r̄: positive acceleration feedback, RHP-zero risk) is refused with an
/// InputError giving the reason unless allow_negative_kd; when allowed it is reported in
/// `warnings`.
[[nodiscard]] PidDesign pid_design(const NormalizedPlant& plant, double r_target, double omega_star, double zeta_star,
                                   double tau, bool allow_negative_kd = false);

// ---------------------------------------------------------------- de-normalization (catalog §0)

/// Kp = Kp_n·Im·ωz, Ki = Ki_n·Im·ωz².
[[nodiscard]] PiGains to_physical(const PiGains& normalized, const NormalizedPlant& plant) noexcept;
/// Also Kd = Kd_n·Im, τ = τ_n/ωz (weights unchanged).
[[nodiscard]] PidGains to_physical(const PidGains& normalized, const NormalizedPlant& plant) noexcept;
/// Inverse of to_physical (for analysing given drive gains).
[[nodiscard]] PiGains to_normalized(const PiGains& physical, const NormalizedPlant& plant) noexcept;
/// Inverse of to_physical.
[[nodiscard]] PidGains to_normalized(const PidGains& physical, const NormalizedPlant& plant) noexcept;

}  // namespace servotwin::tuning
