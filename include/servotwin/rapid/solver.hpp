#pragma once
/// \file
/// Solvers of the constrained rapid-identification problem (thesis sections 3.3 and 4.2):
///   minimize f(theta) = 1/2 ||y - Phi theta||^2
/// subject to the characteristic polynomial s^3 + a1 s^2 + a2 s + a3 = (s + p)(s^2 + 2 zeta wn s + wn^2)
/// with p in [p_min, p_max], wn in [wn_min, wn_max], zeta in [zeta_min, zeta_max] (zeta > 1: two real
/// poles), so that the identified twin is stable with bounded damping.
///
/// Methods: `Ls` unconstrained least squares; `Exact` the global minimum under the bounds, with
/// a certified lower bound; `Ga` the thesis's genetic algorithm (section 4.2), seeded.
///
/// All methods share one reduction of the problem (src/rapid/solver_reduction.cpp): the columns of
/// [Phi y] are equilibrated (so nothing depends on length units), the five regressors of
/// theta2 = (beta_0, beta_1, beta_2, delta+, delta-) are eliminated by a column-pivoted QR (the
/// closed form of Eq. 4.9; a regressor that is zero or linearly dependent on the others is reported
/// and its parameter fixed at 0), and what remains is the convex quadratic
///   q(theta1) = min over theta2 of f = 1/2 ||A theta1~ - b||^2 + 1/2 c^2,  theta1 = (alpha_i, alpha_1, alpha_2),
/// in triangular (square-root) form. Eq. 4.12's 4x4 quadratic form is q expanded in
/// mu = (1, alpha_i, alpha_1, alpha_2); the genetic algorithm evaluates it in this factored form.

#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "servotwin/rapid/axis_model.hpp"
#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid {

/// Bounds of the search variables [rad/s and -].
struct Bounds {
  double p_min = 0.0, p_max = 0.0;
  double wn_min = 0.0, wn_max = 0.0;
  double zeta_min = 0.2, zeta_max = 2.0;
};
/// Thesis section 4.3 defaults: 0.2 Hz <= p, wn <= Nyquist (pi/ts), 0.2 <= zeta <= 2.
/// core::InputError (field "ts") unless ts is finite and > 0.
Bounds default_bounds(double ts);
/// core::InputError (field "bounds.<name>") for non-finite, non-positive or inverted bounds.
/// Equal lower and upper bounds are allowed (the variable is fixed).
void validate(const Bounds& bounds);

enum class Method { Ls, Exact, Ga };
const char* method_name(Method m) noexcept;

/// Genetic algorithm settings (thesis section 4.3 defaults). How the thesis's words are read:
///  - crossover_rate: the probability that a randomly matched pair of parents is recombined by SBX
///    (Eq. 4.3, one weighting factor r per pair); otherwise both pass on unchanged;
///  - mutation_rate: the probability that a candidate is perturbed by Eq. 4.4-4.6 after crossover;
///    each of its three variables gets its own N(0,1) (the sign of which picks R_i of Eq. 4.5), the
///    momentum step eta_i = exp(tau' N_t + tau N_i) one candidate-wide N_i and one N_t per generation;
///  - selection: the `elite` best of the mutated pool survive, every other place is filled by a
///    tournament of two candidates drawn uniformly (with replacement) from the mutated pool.
/// The search is uniform in (wn, zeta, p) as in section 4.2.1. Random numbers come from
/// std::mt19937_64 bits transformed by the library's own uniform/normal code, so a seed gives the same
/// stream with every standard library.
struct GaOptions {
  std::size_t population = 4000;
  std::size_t generations = 500;
  double crossover_rate = 0.5;
  double mutation_rate = 0.05;
  std::size_t elite = 5;   ///< "top percent" survivors; the rest by random tournament
  std::uint64_t seed = 1;
  bool record_history = true;
};

/// Best candidate of one GA generation (of the evaluated, mutated pool).
struct GaGeneration {
  double objective;
  double p, wn, zeta;
};

/// A bound that holds with equality at the solution, with its Kuhn-Tucker multiplier
/// (>= 0 for a true minimum; the derivative of f along the variable, pointing into the box).
struct ActiveBound {
  std::string name;  ///< p_min, p_max, wn_min, wn_max, zeta_min, zeta_max
  double multiplier = 0.0;
};

struct SolveOptions {
  GaOptions ga;
  /// Exact: the returned objective is within this of the global minimum:
  /// f - f_global <= abs_tolerance + rel_tolerance * f. Differences below the double-precision
  /// resolution of f (1e-14 ||y|| ||y - Phi theta||) are not resolved.
  double rel_tolerance = 1e-9;
  double abs_tolerance = 0.0;
  /// Exact: the branch and bound stops after this many boxes with a warning and the lower bound
  /// reached so far (it never runs unbounded on flat or degenerate problems).
  std::size_t max_boxes = 200000;
};

/// Result of every method.
struct Solution {
  Method method = Method::Ls;
  Vector8 theta = Vector8::Zero();
  ModelCoefficients coefficients;
  /// Search variables of theta's characteristic polynomial (for Ls: one factorization when it
  /// has the form; NaN otherwise, e.g. for unstable or all-complex-impossible cases).
  double p = 0.0, wn = 0.0, zeta = 0.0;
  double objective = 0.0;        ///< f(theta)
  bool feasible = false;         ///< within the bounds (Ls may not be)
  std::vector<ActiveBound> active;
  /// df/d(p, wn, zeta) at the solution, theta2 re-optimized (Exact, Ga; NaN for Ls). Zero in the
  /// free variables at a Kuhn-Tucker point.
  Eigen::Vector3d gradient = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// Exact: certified lower bound on the constrained global minimum (objective - lower_bound is
  /// the certified gap). Other methods: NaN.
  double lower_bound = 0.0;
  /// Exact: the gap met the tolerance (false only when max_boxes stopped the search).
  bool certified = false;
  std::uint64_t boxes = 0;       ///< Exact: boxes processed by the branch and bound
  std::string kkt_case;          ///< Table 3.1 case (e.g. "1: unconstrained", "4: wn = wn_min, zeta = zeta_min")
  std::vector<std::string> warnings;  ///< rank deficiency, friction not identifiable, ...
  std::uint64_t seed = 0;        ///< Ga
  std::vector<GaGeneration> history;  ///< Ga, when recorded
  double time_ms = 0.0;
};

/// Solves the problem with the given method. core::InputError for an empty problem or bad bounds.
Solution solve(const RegressionProblem& problem, Method method, const Bounds& bounds,
               const SolveOptions& options = {});

/// theta1 = (alpha_i, alpha_1, alpha_2) of the poles -p, -zeta wn +- wn sqrt(zeta^2 - 1) (Eq. 3.14).
Eigen::Vector3d theta1_from_poles(double p, double wn, double zeta) noexcept;

/// One way of writing alpha_2 s^3 + alpha_1 s^2 + s + alpha_i (the characteristic polynomial over
/// a2) as (s + p)(s^2 + 2 zeta wn s + wn^2) / a2 with real p, wn > 0 and zeta (zeta < 0 or p < 0:
/// unstable).
struct PoleFactorization {
  double p, wn, zeta;
};
/// All such factorizations of theta1's polynomial: one for a real root and a complex pair, up to
/// three when all roots are real (each real root can be "p"), none when alpha_2 is zero, theta1 is
/// not finite or no pair of roots has a positive product.
std::vector<PoleFactorization> pole_factorizations(const Eigen::Vector3d& theta1);

}  // namespace servotwin::rapid
