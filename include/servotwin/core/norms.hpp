#pragma once
/// \file
/// Peak gains and bandwidths of frequency responses: the H-infinity norm of a stable state-space
/// system (Bruinsma–Steinbuch), the supremum of |f(j omega)| for any frequency-domain expression
/// (including delays, which have no state space) on a grid with local refinement, and the -3 dB
/// bandwidth. These are the indices of controller tuning (sensitivity peaks, robustness tests).
///
/// Errors: as in the rest of core, arguments that violate the contract (shapes, non-finite data, an
/// unstable system for hinf_norm, a bad grid) are programming errors and throw
/// std::invalid_argument; a quantity that does not exist for valid input throws std::domain_error.

#include <complex>
#include <functional>
#include <optional>
#include <span>

#include "servotwin/core/state_space.hpp"

namespace servotwin::core {

/// A peak gain and where it is attained.
struct PeakResult {
  double value = 0.0;        ///< the peak gain (largest singular value for MIMO systems)
  double omega_rad_s = 0.0;  ///< frequency of the peak [rad/s]; +infinity when it is the limit at infinity
};

/// H-infinity norm sup_omega sigma_max(G(j omega)) of a stable continuous system of any size.
///
/// Stability test (else std::invalid_argument): every eigenvalue of the balanced A has
/// Re(lambda) < -100 eps ||A_bal||_F, i.e. it is farther left of the imaginary axis than the
/// eigenvalue solver's rounding; a pole on the axis (integrator) makes the norm infinite.
///
/// Method (Bruinsma & Steinbuch 1990, Syst. Control Lett. 14:287): a lower bound gamma_lb from
/// sigma_max at omega = 0, at infinity (sigma_max(D)) and at every pole's |lambda| and |Im lambda|;
/// then repeatedly gamma = (1 + rel_tol) gamma_lb and the eigenvalues of the Hamiltonian
///   M(gamma) = [[A - B R^-1 D^T C, -gamma B R^-1 B^T], [gamma C^T S^-1 C, -A^T + C^T D R^-1 B^T]],
///   R = D^T D - gamma^2 I, S = D D^T - gamma^2 I,
/// whose imaginary eigenvalues j omega_i are the frequencies where some singular value of G(j omega)
/// equals gamma. sigma_max is evaluated at the midpoints of consecutive omega_i (including 0); the
/// largest becomes the new gamma_lb. The iteration stops when no midpoint exceeds gamma (in
/// particular when M has no imaginary eigenvalue), so gamma_lb <= ||G||_inf < (1 + rel_tol)
/// gamma_lb. Because gamma > sigma_max(D) strictly, R and S are always invertible; when the peak
/// is the limit at infinity (gamma_lb = sigma_max(D)) the first test already finds no crossing.
/// Eigenvalues count as imaginary when |Re| <= 1e-6 |lambda| + 1e3 eps ||M||: a loose test is safe,
/// since a spurious candidate only adds an evaluation and the stopping rule relies on evaluated
/// gains, not on the classification.
///
/// Returns value = sigma_max(G(j omega)) at the returned omega (an attained lower bound within
/// rel_tol of the norm); omega = +inf when the peak is sigma_max(D) approached at infinity.
/// A zero transfer matrix gives {0, 0}. rel_tol must lie in [1e-12, 0.1]. States are balanced
/// and B, C scaled to equal norms first (the norm is invariant), so the result does not depend on
/// the state units.
PeakResult hinf_norm(const StateSpace& sys, double rel_tol = 1e-6);

/// ||G||_inf < gamma for a stable sys, decided with one Hamiltonian eigenvalue problem (the bounded
/// real lemma: with sigma_max(D) < gamma the norm reaches gamma only where M of hinf_norm has an
/// imaginary eigenvalue) instead of hinf_norm's iteration: what a gamma-iteration asks of each
/// candidate. Gains at DC and the poles' frequencies are tried first (a cheap "no"); eigenvalues
/// counted as imaginary by hinf_norm's loose test are confirmed by the gain between them, so a
/// rounding artefact does not reject a system below gamma. std::invalid_argument for gamma not
/// finite and > 0, for shapes as hinf_norm, and for an unstable system (as hinf_norm).
bool hinf_norm_below(const StateSpace& sys, double gamma);

/// Supremum of |f(omega)| over [grid.front(), grid.back()]: |f| on every grid point, then each
/// local maximum of the grid values (a point above its left and not below its right neighbour;
/// the end points count) is refined by golden-section search in log omega over the bracket of its
/// two neighbours until the bracket is narrower than rel_tol (relative, in omega); at a smooth
/// maximum the value is then accurate to about rel_tol^2. The largest value seen is returned with
/// its frequency. A bracket starting at omega = 0 is searched linearly in omega.
///
/// A peak narrower than the grid spacing can be stepped over: put the frequencies of lightly
/// damped poles into the grid. The grid must be non-empty, finite, >= 0 and strictly increasing;
/// rel_tol in [1e-12, 0.1] (else std::invalid_argument). f returning NaN throws
/// std::invalid_argument; +inf (a pole on the axis) is returned as the peak at once.
PeakResult peak_on_grid(const std::function<std::complex<double>(double)>& f, std::span<const double> omega_grid,
                        double rel_tol = 1e-6);

/// First frequency where |f| falls below the low-frequency reference |f(grid[0])| by level_db
/// (|f| < |f(grid[0])| 10^(level_db/20); default -3 dB as MATLAB's `bandwidth`). Same definition
/// as rapid::AxisModel::bandwidth_hz, whose reference is the exact DC gain: pass grid[0] = 0 to
/// use f(0), or start the grid well below the dynamics (|f| within rounding of its DC value).
/// The first grid point below the level brackets the crossing with its predecessor; bisection
/// (geometric once the bracket excludes 0) narrows it to 1e-9 relative and the bracket midpoint is
/// returned [rad/s]. nullopt when |f| never falls below the level on the grid.
///
/// The grid must hold at least two points, be finite, >= 0 and strictly increasing; level_db must
/// be finite and < 0; f must not return NaN (all std::invalid_argument). A zero or non-finite
/// reference |f(grid[0])| throws std::domain_error (no bandwidth is defined).
std::optional<double> bandwidth(const std::function<std::complex<double>(double)>& f, std::span<const double> grid,
                                double level_db = -3.0);

}  // namespace servotwin::core
