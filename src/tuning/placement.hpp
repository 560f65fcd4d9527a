#pragma once
// Internal: the pole-placement kernel shared by pi_pole_placement(), the admissible-range scan and
// the PID design. The three polynomials of c(s) = c0 + Kp cp + Ki ci do not depend on ω*, so a
// scan builds them once.
#include <optional>

#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning::detail {

/// c(s) = c0 + Kp·cp + Ki·ci for the plant N/Dp with Kd and τ fixed.
struct PlacementProblem {
  core::Polynomial c0;  ///< s(τs + 1)Dp + Kd s² N
  core::Polynomial cp;  ///< s(τs + 1)N
  core::Polynomial ci;  ///< (τs + 1)N
  PlacementProblem(const core::TransferFunction& plant, double kd, double tau);
  /// c(s) for the given gains.
  [[nodiscard]] core::Polynomial closed_loop(const PiGains& gains) const;
};

/// (Kp, Ki) placing s² + 2ζω s + ω² in c(s); std::nullopt when the equilibrated system is
/// singular (condition number > 1e12 or a zero row).
std::optional<PolePlacement> place(const PlacementProblem& problem, double omega, double zeta);

/// Quotient of c(s) by s² + 2ζω s + ω² when it is a quadratic, as its two roots; nullopt when the
/// remainder exceeds `tolerance` times c's scale (the pair is not a factor) or c is not quartic.
std::optional<SecondPair> second_pair_of(const core::Polynomial& c, double omega, double zeta, double tolerance);

}  // namespace servotwin::tuning::detail
