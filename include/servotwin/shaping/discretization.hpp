#pragma once
/// \file
/// Discrete-time input shapers (dissertation Sec. 6.2, catalog C6.5): a continuous pulse train
/// IS(s) = Σ A_i e^{-t_i s} moved onto the sample grid t = k Ts of a controller.
///
/// **Exact vector decomposition** (DiscretizationMethod::Exact). With the design pole
/// s = -σ + jω_d (σ = ζω, ω_d = ω sqrt(1 - ζ²)) the zero-vibration condition is IS(s) = 0, i.e.
/// Σ a_i e^{-jκ_i} = 0 with a_i = A_i e^{σ t_i}, κ_i = ω_d t_i: the vectors close a polygon. A
/// pulse with k Ts < t_i < (k+1) Ts is replaced by two grid pulses whose vectors add up to its own:
///   a⁻ e^{-jκ⁻} + a⁺ e^{-jκ⁺} = a_i e^{-jκ_i},  κ⁻ = ω_d k Ts, κ⁺ = ω_d (k+1) Ts.
/// The real and imaginary parts are two linear equations; Cramer's rule with the determinant
/// sin(κ⁺ - κ⁻) = sin(ω_d Ts) gives
///   a⁻ = a_i sin(κ⁺ - κ_i) / sin(ω_d Ts),  a⁺ = a_i sin(κ_i - κ⁻) / sin(ω_d Ts),
///   A⁻ = a⁻ e^{-σ k Ts},  A⁺ = a⁺ e^{-σ (k+1) Ts}.
/// Every pulse's vector is preserved, so IS(s) is unchanged: a zero-vibration shaper stays exactly
/// zero-vibration (up to rounding). Pulses landing on the same sample are summed. The value at
/// s = 0 (the static gain Σ A) is not preserved by the split, so the amplitudes are divided by
/// their sum afterwards; IS(s) = 0 is homogeneous and survives the scaling. A 4-pulse shaper gives
/// at most 7 discrete pulses (t_1 = 0 is on the grid).
///
/// **Signs.** For 0 < ω_d Ts < π both sine ratios lie in (0, 1/sin(ω_d Ts)] for every κ_i inside
/// the interval, so the split of a positive pulse is two positive pulses: the decomposition never
/// creates negative amplitudes (a shaper with only positive pulses keeps its monotone step
/// response). Negative input amplitudes (allowed for e.g. LP-synthesized shapers) are split
/// linearly and stay negative; DiscreteShaper::min_amplitude reports them.
///
/// **Degenerate cases.** ω_d Ts ≥ π (the sample period is half a damped period or more) makes the
/// determinant vanish or change sign: the grid cannot represent the mode (it is at or above the
/// Nyquist frequency) and discretize() throws core::InputError naming "ts" with both values. The
/// same guard applies to rounding, whose result would be meaningless there.
///
/// **Rounding** (DiscretizationMethod::Round) moves each t_i to the nearest k Ts (halves up),
/// keeps A_i and sums merged pulses: the filter is not zero-vibration any more and
/// DiscreteShaper::residual quantifies it (E17: 8.78 % for E16's shaper at Ts = 0.5).
///
/// **Multi-mode shapers** are decomposed against the design pole (`omega`, `zeta`) only; the
/// values at the other modes' poles are approximated, and `residual` is reported for the design
/// pole alone.

#include <cstddef>
#include <vector>

#include "servotwin/shaping/shaper.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::shaping {

/// How pulse times off the sample grid are handled.
enum class DiscretizationMethod {
  Exact,  ///< vector decomposition onto the two neighbouring samples (zero vibration preserved)
  Round   ///< nearest sample (residual vibration reported)
};

/// "exact" or "round".
const char* discretization_method_name(DiscretizationMethod method) noexcept;

/// A pulse train on the sample grid: y[k] = Σ amplitudes[i] u[k - delays[i]].
struct DiscreteShaper {
  std::string type;                ///< family of the continuous shaper it came from
  double omega = 0.0;              ///< design natural frequency [rad/s]
  double zeta = 0.0;               ///< design damping
  double ts = 0.0;                 ///< sample period [s]
  std::vector<std::size_t> delays; ///< pulse delays [samples], strictly increasing, front() == 0
  std::vector<double> amplitudes;  ///< A_i, Σ A_i = 1
  /// Relative residual vibration at the design pole (catalog C6.3):
  /// Ar = e^{-ζω t_n} |Σ A_i e^{ζω t_i} e^{-jω_d t_i}|; ~1e-16 for Exact.
  double residual = 0.0;
  double min_amplitude = 0.0;      ///< smallest A_i (< 0: the step response is not monotone)

  /// Largest delay [samples] (the ring buffer of a real-time shaper holds max_delay() + 1 values).
  [[nodiscard]] std::size_t max_delay() const noexcept { return delays.empty() ? 0 : delays.back(); }
  /// Delay the shaper adds to a move [s].
  [[nodiscard]] double duration() const noexcept { return static_cast<double>(max_delay()) * ts; }
  /// The same pulses as a continuous Shaper (times k Ts).
  [[nodiscard]] Shaper to_shaper() const;
};

/// Discretizes `shaper` at sample period `ts` [s]. Throws core::InputError (naming the field) for:
/// ts not finite or <= 0; a shaper without pulses, with times not starting at 0 or not strictly
/// increasing, with as many amplitudes as times violated, non-finite values; omega <= 0 or zeta
/// outside [0, 1); ω_d ts >= π; more than 10^7 samples of delay; amplitudes summing to <= 0 after
/// the decomposition.
DiscreteShaper discretize(const Shaper& shaper, double ts, DiscretizationMethod method = DiscretizationMethod::Exact);

/// Relative residual vibration of a discrete shaper at a mode (ω, ζ): residual_vibration() of its
/// pulses at times k Ts (catalog C6.3).
double discrete_residual(const DiscreteShaper& shaper, double omega, double zeta);

/// Result of adjusting ZV4's p1 so that its pulses fall on the sample grid (catalog C6.5 option 2).
struct GridP1 {
  double p1 = 0.0;          ///< adjusted p1 in [-1, 1]
  std::size_t samples = 0;  ///< pulse spacing T = samples * ts
  double spacing = 0.0;     ///< T [s]
};

/// ZV4 pulse spacing is T = (π - α)/ω_d with α = p1 2π/3 (catalog C6.2), so p1 = 3 (π - ω_d T)/(2π).
/// Returns the p1 in [-1, 1] nearest to `p1` whose T is a whole number m >= 1 of samples (ties: the
/// larger m, the longer and more robust filter). The ZV4 designed with it has exact grid times, so
/// rounding is lossless. Note: p1 = 0 selects ZV4's third parameter p3 (C6.2); an adjusted p1 is in
/// general not 0, and the p1 != 0 branch ignores p3. Throws core::InputError naming the field for
/// omega <= 0, zeta outside [0, 1), p1 outside [-1, 1], ts not finite or <= 0, and when no
/// m satisfies π/(3ω_d) <= m ts <= 5π/(3ω_d) (ts longer than the shortest ZV4, naming "ts").
GridP1 adjust_p1_to_grid(double omega, double zeta, double p1, double ts);

/// ZV4 (zv4_shaper) with p1 replaced by adjust_p1_to_grid(omega, zeta, parameters.p1, ts).p1, so
/// its pulses lie on the grid k ts and discretize(..., Round) is exact. When the adjusted p1 is not
/// 0, p3 is set to 0 (it only exists in the p1 = 0 branch). Times are snapped to multiples of ts
/// (they are within rounding of them). Errors: those of adjust_p1_to_grid and zv4_shaper.
Shaper zv4_on_grid(double omega, double zeta, const Zv4Parameters& parameters, double ts);

}  // namespace servotwin::shaping
