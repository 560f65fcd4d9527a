#pragma once
/// \file
/// Parametric robustness of a PI velocity loop (seed catalog C7.9): Kharitonov's
/// four polynomials, exhaustive gridding of the parameter box, and the largest bandwidth ω* whose
/// nominal design is robustly stable.
///
/// Plant (physical units, velocity output ωm per torque Tm), every parameter in an interval:
///
///   P(s) = K (s² + 2ξz ωz s + ωz²) / ((s + a)(s² + 2ξ ω s + ω²)),
///
/// under the PI law Tm = (Kp + Ki/s)(ω* − ωm). The closed-loop polynomial is the monic quartic
/// c(s) = s(s + a)(s² + 2ξωs + ω²) + K(Kp s + Ki)(s² + 2ξz ωz s + ωz²):
///
///   a3 = 2ξω + a + K Kp
///   a2 = ω² + 2aξω + K Ki + 2K Kp ξz ωz
///   a1 = aω² + K Kp ωz² + 2K Ki ξz ωz
///   a0 = K Ki ωz²
///
/// (the catalog's formulas with ωz written out; they reduce to them for ωz = 1). Every term is a
/// product of non-negative parameters and gains with a positive factor, so for Kp, Ki >= 0 each
/// coefficient is non-decreasing in every parameter and its bounds over the box are attained at
/// the all-lower and all-upper parameter vertices.
///
/// Units: any consistent set (rad/s and N·m, or mm-based, …); frequencies and ω* share one unit.
/// Stability verdicts do not depend on the units.

#include <array>
#include <cstddef>
#include <optional>

#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

/// One parameter's interval with its nominal value.
struct Interval {
  double lo = 0.0;
  double nominal = 0.0;
  double hi = 0.0;
};

/// One point of the parameter box (a plant).
struct PlantParameters {
  double k = 0.0;        ///< high-frequency gain K (1/inertia) [velocity per torque per second]
  double a = 0.0;        ///< rigid pole a [rad/s] (0: pure integrator)
  double xi = 0.0;       ///< resonance (pole) damping ξ
  double xi_z = 0.0;     ///< antiresonance (zero) damping ξz
  double omega = 0.0;    ///< resonance ω [rad/s]
  double omega_z = 0.0;  ///< antiresonance ωz [rad/s]
};

/// The interval plant above. Build it with make_interval_plant() or fill it and call validate().
struct IntervalPlant {
  Interval k, a, xi, xi_z, omega, omega_z;

  [[nodiscard]] PlantParameters nominal() const noexcept;
  [[nodiscard]] PlantParameters lower() const noexcept;  ///< every parameter at lo
  [[nodiscard]] PlantParameters upper() const noexcept;  ///< every parameter at hi
};

/// Throws core::InputError naming the field ("k.lo", "omega_z.nominal", …) unless every value is
/// finite, lo <= nominal <= hi, every lo >= 0, and k.lo, omega.lo, omega_z.lo > 0.
void validate(const IntervalPlant& plant);

/// The box nominal·(1 − spread) … nominal·(1 + spread) per parameter (spread 0.1 = ±10 %),
/// validated. InputError naming "spread.<field>" for a spread outside [0, 1], and as validate().
[[nodiscard]] IntervalPlant make_interval_plant(const PlantParameters& nominal, const PlantParameters& relative_spread);

/// P(s) of one parameter point.
[[nodiscard]] core::TransferFunction plant_transfer_function(const PlantParameters& p);

/// The closed-loop quartic c(s) above (monic, highest power first) for one parameter point.
[[nodiscard]] core::Polynomial closed_loop_polynomial(const PlantParameters& p, const PiGains& gains);

/// Kharitonov's test on the interval closed-loop polynomial.
struct KharitonovResult {
  /// Coefficient bounds by power: lower[k], upper[k] bound a_k (k = 0..3; a4 = 1).
  std::array<double, 4> lower{};
  std::array<double, 4> upper{};
  /// k1 = a0⁻ + a1⁻s + a2⁺s² + a3⁺s³ + s⁴, k2 = a0⁺ + a1⁺s + a2⁻s² + a3⁻s³ + s⁴,
  /// k3 = a0⁺ + a1⁻s + a2⁻s² + a3⁺s³ + s⁴, k4 = a0⁻ + a1⁺s + a2⁺s² + a3⁻s³ + s⁴.
  std::array<core::Polynomial, 4> polynomials;
  std::array<bool, 4> hurwitz{};  ///< core::is_hurwitz (exact Routh signs) of each
  /// Largest real part of each polynomial's roots (core::Polynomial::roots): a diagnostic margin
  /// only, the verdict comes from the Routh test.
  std::array<double, 4> max_real_part{};
  bool robust = false;  ///< all four Hurwitz
};

/// Kharitonov's test. Sufficient, not necessary, for this plant: the coefficients depend on common
/// parameters, so the coefficient box is larger than the set of reachable polynomials and a
/// failure may be conservative (use grid_check()). InputError for an invalid plant or negative or
/// non-finite gains ("gains.kp", "gains.ki"): the monotonicity behind the bounds needs Kp, Ki >= 0.
[[nodiscard]] KharitonovResult kharitonov(const IntervalPlant& plant, const PiGains& gains);

/// Exhaustive gridding of the parameter box.
struct GridResult {
  bool robust = false;                           ///< every case Hurwitz
  std::size_t cases = 0;                         ///< number of parameter combinations tested
  std::size_t failures = 0;                      ///< cases whose closed loop is not Hurwitz
  PlantParameters worst;                         ///< the case with the largest real part of the closed-loop roots
  double worst_max_real_part = 0.0;              ///< that real part (core::Polynomial::roots)
  std::optional<PlantParameters> first_failure;  ///< first non-Hurwitz case in enumeration order
};

/// Every combination of `points_per_parameter` equally spaced values lo … hi per parameter (both
/// ends included, so all 64 vertices are tested; a parameter with lo == hi contributes one value),
/// enumerated with ωz varying fastest after K, a, ξ, ξz, ω (lexicographic in that order). Each case
/// is decided by the Routh first-column signs of its exact closed-loop quartic (the conditions of
/// core::is_hurwitz, evaluated allocation-free). The worst case is tracked exactly without rooting
/// every case: a case can only be worse than the current worst abscissa α when c(s + α) is not
/// Hurwitz, and only then are its roots computed.
/// InputError for an invalid plant, negative gains, or points_per_parameter outside [2, 12].
[[nodiscard]] GridResult grid_check(const IntervalPlant& plant, const PiGains& gains, int points_per_parameter = 5);

/// The robustness criterion of largest_robust_omega_star(): kharitonov(plant, gains).robust, or,
/// when that fails, grid_check(plant, gains, points_per_parameter).robust.
[[nodiscard]] bool robustly_stable(const IntervalPlant& plant, const PiGains& gains, int points_per_parameter = 5);

/// The nominal plant as a NormalizedPlant: ωz = omega_z, Im = 1/K, r = ω/ωz, ζz = ξz, ζp = ξ,
/// normalized a = a/ωz. InputError (from normalized_two_mass) when r <= 1.05.
[[nodiscard]] NormalizedPlant nominal_normalized_plant(const IntervalPlant& plant);

/// Physical PI gains placing s² + 2ζ*ω*s + ω*² on the NOMINAL plant (pi_pole_placement on the
/// normalized design model at ω*/ωz, then to_physical). ω* in the plant's frequency unit.
[[nodiscard]] PiGains nominal_pi_design(const IntervalPlant& plant, double omega_star, double zeta_star);

/// The largest bandwidth ω* (the plant's frequency unit) whose nominal design is robustly stable
/// over the whole box, within the nominal admissible range [ωmin, ωmax]·ωz of admissible_range().
///
/// Method (in normalized ω*, i.e. units of ωz): pass(ω*) = both nominal gains >= 0 and
/// robustly_stable(plant, nominal_pi_design(plant, ω*, ζ*), points). If pass(ωmax) the answer is
/// ωmax. Otherwise the range is scanned downwards at the 23 geometric points
/// l·(ωmax/l)^(j/24), j = 23 … 1, with l = max(ωmin, 1e-3·ωmax); at the first passing point,
/// bisection between it and the failing point above until the bracket is below 1e-5·ωmax returns
/// the passing end (times ωz). The pass set need not be an interval: a passing window narrower
/// than the scan spacing (~12 % for l = 0.07 ωmax) above the returned value can be missed. Returns 0
/// when the admissible range is empty or no scan point passes. InputError for ζ* <= 0, an invalid
/// plant, r <= 1.05, or points_per_parameter outside [2, 12].
[[nodiscard]] double largest_robust_omega_star(const IntervalPlant& plant, double zeta_star,
                                               int points_per_parameter = 5);

}  // namespace servotwin::tuning
