#include "servotwin/shaping/lp_shaper.hpp"

#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "servotwin/core/error.hpp"
#include "shaper_checks.hpp"

namespace servotwin::shaping {
namespace {

constexpr int kMaxPulseCount = 100000;
constexpr int kMaxMultiples = 100000;
constexpr double kZeroAmplitude = 1e-12;   // below this an amplitude is solver rounding of 0
constexpr double kCheckTolerance = 1e-9;   // accepted violation of a normalized constraint
constexpr double kPrimalTolerance = 1e-11; // GLPK's tol_bnd: keeps A_i ≥ −1e-11 so clipping is harmless
constexpr double kTwoPi = 2.0 * std::numbers::pi;

using detail::show;

// ---------------------------------------------------------------------------------------- GLPK

/// Owns a glp_prob (GLPK's C API has no destructor of its own).
class GlpProblem {
 public:
  GlpProblem() : problem_(glp_create_prob()) {}
  ~GlpProblem() { glp_delete_prob(problem_); }
  GlpProblem(const GlpProblem&) = delete;
  GlpProblem& operator=(const GlpProblem&) = delete;
  [[nodiscard]] glp_prob* get() const noexcept { return problem_; }

 private:
  glp_prob* problem_;
};

/// The LP of one grid, dense (a few dozen rows), every row normalized to coefficients in [−1, 1].
struct LpProblem {
  int n = 0;
  int equality_rows = 0;             // rows [0, equality_rows) are equalities (sum, then ZV/derivatives)
  std::vector<double> matrix;        // row-major, rows × n
  std::vector<double> lower, upper;  // row bounds
  std::vector<std::string> labels;   // what each row is, for diagnostics
  [[nodiscard]] int rows() const noexcept { return static_cast<int>(lower.size()); }
  [[nodiscard]] const double* row(int r) const noexcept { return matrix.data() + static_cast<std::ptrdiff_t>(r) * n; }
};

double damped_frequency(double omega, double zeta) { return omega * std::sqrt(1.0 - zeta * zeta); }

/// Appends the pair of rows Σ A_i w_i cos(ω_d t_i), Σ A_i w_i sin(ω_d t_i) with the weights
/// w_i = (t_i/t_n)^l e^{−ζω(t_n − t_i)}: the printed rows t_i^l e^{ζω t_i}(…) divided by
/// t_n^l e^{ζω t_n}, so no coefficient exceeds 1 in magnitude.
void add_rotating_rows(LpProblem& lp, double tp, double omega, double zeta, int order, double bound,
                       const std::string& label) {
  const double wd = damped_frequency(omega, zeta);
  const double tn = tp * (lp.n - 1);
  const std::size_t base = lp.matrix.size();
  lp.matrix.resize(base + 2 * static_cast<std::size_t>(lp.n));
  double* c = lp.matrix.data() + base;
  double* s = c + lp.n;
  for (int i = 0; i < lp.n; ++i) {
    const double t = tp * i;
    double weight = std::exp(-zeta * omega * (tn - t));
    if (order > 0) weight *= tn > 0.0 ? std::pow(t / tn, order) : 0.0;
    const double angle = wd * t;
    c[i] = weight * std::cos(angle);
    s[i] = weight * std::sin(angle);
    // The angle carries a rounding error of a few ulps of itself: a cosine or sine below that is
    // zero (e.g. sin(i·π) on a half-period grid). Left in, such noise rows become singleton
    // constraints to GLPK's presolve (1e-16·A_2 = 0 forces A_2 = 0).
    const double noise = 8.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(angle)) * weight;
    if (std::abs(c[i]) <= noise) c[i] = 0.0;
    if (std::abs(s[i]) <= noise) s[i] = 0.0;
  }
  for (const char* part : {" cos", " sin"}) {
    lp.lower.push_back(-bound);
    lp.upper.push_back(bound);
    lp.labels.push_back(label + part);
  }
}

std::vector<double> cost_vector(int n, double k) {
  std::vector<double> c(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) c[static_cast<std::size_t>(i)] = k == 0.0 ? (i == 0 ? 0.0 : 1.0) : k * i + 1.0;
  return c;
}

LpProblem build_problem(const std::vector<LpMode>& modes, const LpShaperOptions& o, double tp, int n) {
  LpProblem lp;
  lp.n = n;
  lp.matrix.assign(static_cast<std::size_t>(n), 1.0);
  lp.lower.push_back(1.0);
  lp.upper.push_back(1.0);
  lp.labels.emplace_back("sum of amplitudes");
  const char* names[] = {"zero vibration", "zero slope", "zero curvature"};
  for (std::size_t k = 0; k < modes.size(); ++k)
    for (int order = 0; order <= o.derivative_order; ++order)
      add_rotating_rows(lp, tp, modes[k].omega, modes[k].zeta, order, 0.0,
                        std::string(names[order]) + " at modes[" + std::to_string(k) + "]");
  lp.equality_rows = lp.rows();
  for (std::size_t b = 0; b < o.bounds.size(); ++b) {
    const SensitivityBound& bound = o.bounds[b];
    add_rotating_rows(lp, tp, bound.omega, bound.zeta, 0, bound.s_max / std::numbers::sqrt2,
                      "sensitivity bound bounds[" + std::to_string(b) + "]");
  }
  return lp;
}

struct LpResult {
  bool feasible = false;
  std::vector<double> x;
  double cost = 0.0;
};

[[noreturn]] void solver_failure(const std::string& what, double tp, int n) {
  throw std::runtime_error("lp_shaper: " + what + " (n = " + std::to_string(n) + ", Tp = " + show(tp) + " s)");
}

/// Solves the LP with GLPK's primal simplex after presolve; `cost` empty = feasibility only.
LpResult solve(const LpProblem& lp, const std::vector<double>& cost, double max_pulse, double tp) {
  GlpProblem problem;
  glp_prob* p = problem.get();
  glp_set_obj_dir(p, GLP_MIN);
  glp_add_rows(p, lp.rows());
  glp_add_cols(p, lp.n);
  for (int r = 0; r < lp.rows(); ++r) {
    const auto ru = static_cast<std::size_t>(r);
    const int type = lp.lower[ru] == lp.upper[ru] ? GLP_FX : GLP_DB;
    glp_set_row_bnds(p, r + 1, type, lp.lower[ru], lp.upper[ru]);
  }
  for (int j = 0; j < lp.n; ++j) {
    glp_set_col_bnds(p, j + 1, GLP_DB, 0.0, max_pulse);
    if (!cost.empty()) glp_set_obj_coef(p, j + 1, cost[static_cast<std::size_t>(j)]);
  }
  // GLPK's arrays are 1-based: element 0 is unused.
  std::vector<int> ia(1, 0), ja(1, 0);
  std::vector<double> ar(1, 0.0);
  ia.reserve(lp.matrix.size() + 1);
  ja.reserve(lp.matrix.size() + 1);
  ar.reserve(lp.matrix.size() + 1);
  for (int r = 0; r < lp.rows(); ++r) {
    const double* row = lp.row(r);
    for (int j = 0; j < lp.n; ++j)
      if (row[j] != 0.0) {
        ia.push_back(r + 1);
        ja.push_back(j + 1);
        ar.push_back(row[j]);
      }
  }
  glp_load_matrix(p, static_cast<int>(ar.size()) - 1, ia.data(), ja.data(), ar.data());

  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_ON;
  parm.tol_bnd = kPrimalTolerance;
  const int code = glp_simplex(p, &parm);
  LpResult result;
  if (code == GLP_ENOPFS) return result;  // presolve proved infeasibility
  if (code != 0) solver_failure("GLPK's simplex failed with code " + std::to_string(code), tp, lp.n);
  const int status = glp_get_status(p);
  if (status == GLP_NOFEAS || status == GLP_INFEAS) return result;
  if (status != GLP_OPT)
    solver_failure("GLPK's simplex ended with status " + std::to_string(status) + " instead of optimal", tp, lp.n);
  result.feasible = true;
  result.cost = glp_get_obj_val(p);
  result.x.resize(static_cast<std::size_t>(lp.n));
  for (int j = 0; j < lp.n; ++j) result.x[static_cast<std::size_t>(j)] = glp_get_col_prim(p, j + 1);
  return result;
}

bool is_feasible(const std::vector<LpMode>& modes, const LpShaperOptions& o, double tp, int n) {
  return solve(build_problem(modes, o, tp, n), {}, o.max_pulse, tp).feasible;
}

/// Clips solver rounding (|A_i| ≤ 1e-12 → 0), renormalizes Σ A = 1 and checks every normalized
/// constraint within 1e-9 (std::runtime_error naming the row otherwise).
void clean_and_check(const LpProblem& lp, std::vector<double>& x, double max_pulse, double tp) {
  double sum = 0.0;
  for (double& a : x) {
    if (a < -kCheckTolerance || a > max_pulse + kCheckTolerance)
      solver_failure("GLPK returned an amplitude " + show(a) + " outside [0, " + show(max_pulse) + "]", tp, lp.n);
    if (a <= kZeroAmplitude) a = 0.0;
    sum += a;
  }
  if (std::abs(sum - 1.0) > kCheckTolerance) solver_failure("GLPK returned amplitudes summing to " + show(sum), tp, lp.n);
  for (double& a : x) a /= sum;
  for (int r = 1; r < lp.rows(); ++r) {
    const double* row = lp.row(r);
    long double value = 0.0L;
    for (int j = 0; j < lp.n; ++j) value += static_cast<long double>(row[j]) * x[static_cast<std::size_t>(j)];
    const auto v = static_cast<double>(value);
    const auto ru = static_cast<std::size_t>(r);
    if (v < lp.lower[ru] - kCheckTolerance || v > lp.upper[ru] + kCheckTolerance)
      solver_failure("the solution violates the " + lp.labels[ru] + " constraint: value " + show(v) + ", allowed [" +
                         show(lp.lower[ru]) + ", " + show(lp.upper[ru]) + "] (normalized)",
                     tp, lp.n);
  }
}

// ------------------------------------------------------------------------------------ checks

void check_omega_zeta(double omega, double zeta, const std::string& where) {
  detail::check_frequency(omega, where + ".omega");
  detail::check_damping(zeta, where + ".zeta");
}

/// Everything except the grid (pulse_spacing, pulse_count).
void check_common(const std::vector<LpMode>& modes, const LpShaperOptions& o) {
  if (modes.empty()) throw core::InputError(core::at_field("modes"), "expected at least one mode to cancel");
  for (std::size_t k = 0; k < modes.size(); ++k)
    check_omega_zeta(modes[k].omega, modes[k].zeta, "modes[" + std::to_string(k) + "]");
  if (o.derivative_order < 0 || o.derivative_order > 2)
    throw core::InputError(core::at_field("derivative_order"),
                           "expected 0 (zero vibration), 1 (plus zero slope) or 2 (plus zero curvature), got " +
                               std::to_string(o.derivative_order));
  for (std::size_t b = 0; b < o.bounds.size(); ++b) {
    const std::string where = "bounds[" + std::to_string(b) + "]";
    check_omega_zeta(o.bounds[b].omega, o.bounds[b].zeta, where);
    if (!std::isfinite(o.bounds[b].s_max) || o.bounds[b].s_max <= 0.0)
      throw core::InputError(core::at_field(where + ".s_max"),
                             "expected a finite vibration bound > 0 (e.g. 0.05 for 5 %), got " + show(o.bounds[b].s_max));
  }
  if (!std::isfinite(o.cost_k) || o.cost_k < 0.0)
    throw core::InputError(core::at_field("cost_k"), "expected a finite k >= 0 (0 selects the cost J1), got " + show(o.cost_k));
  if (!std::isfinite(o.max_pulse) || o.max_pulse <= 0.0)
    throw core::InputError(core::at_field("max_pulse"), "expected a finite bound > 0 on each amplitude, got " + show(o.max_pulse));
  if (!std::isfinite(o.max_duration) || o.max_duration < 0.0)
    throw core::InputError(core::at_field("max_duration"),
                           "expected a finite duration >= 0 s (0 = automatic), got " + show(o.max_duration));
}

void check_spacing(double tp, const char* field) {
  if (!std::isfinite(tp) || tp <= 0.0)
    throw core::InputError(core::at_field(field), "expected a finite pulse spacing > 0 s, got " + show(tp));
}

/// The index of a mode that turns by a multiple of 2π per grid step, or −1. Such a mode sees every
/// impulse in phase: Σ A_i e^{ζω t_i} > 0, so no non-negative shaper on the grid cancels it.
int degenerate_mode(const std::vector<LpMode>& modes, double tp) {
  for (std::size_t k = 0; k < modes.size(); ++k) {
    const double step = damped_frequency(modes[k].omega, modes[k].zeta) * tp;
    if (std::abs(std::remainder(step, kTwoPi)) <= 1e-9 * std::max(1.0, step)) return static_cast<int>(k);
  }
  return -1;
}

double max_duration(const std::vector<LpMode>& modes, const LpShaperOptions& o) {
  if (o.max_duration > 0.0) return o.max_duration;
  double convolution = 0.0;
  for (const LpMode& m : modes) convolution += (o.derivative_order + 1) * std::numbers::pi / damped_frequency(m.omega, m.zeta);
  return 2.0 * convolution;
}

/// Largest n with (n − 1)·Tp ≤ duration (1e-9 relative slack for durations that are exact multiples).
int pulse_cap(double duration, double tp) {
  const double steps = std::floor(duration / tp + 1e-9);
  return steps >= kMaxPulseCount - 1 ? kMaxPulseCount : static_cast<int>(steps) + 1;
}

/// Smallest feasible n in [1, cap], 0 when none. `guess` (0 = none) starts a galloping search;
/// feasibility is monotone in n (a zero impulse appended keeps every constraint), so the bracket
/// found is exact.
int min_pulse_count(const std::vector<LpMode>& modes, const LpShaperOptions& o, double tp, int cap, int guess) {
  int lo = 0;   // infeasible (no impulses)
  int hi = -1;  // feasible, once found
  if (guess >= 1 && guess <= cap) {
    if (is_feasible(modes, o, tp, guess)) {
      hi = guess;
      for (int step = 1;; step *= 2) {
        const int candidate = hi - step;
        if (candidate < 1) break;
        if (!is_feasible(modes, o, tp, candidate)) {
          lo = candidate;
          break;
        }
        hi = candidate;
      }
    } else {
      lo = guess;
      for (int step = 1; hi < 0; step *= 2) {
        const int candidate = std::min(cap, lo + step);
        if (is_feasible(modes, o, tp, candidate)) {
          hi = candidate;
        } else {
          if (candidate == cap) return 0;
          lo = candidate;
        }
      }
    }
  } else {
    if (!is_feasible(modes, o, tp, cap)) return 0;
    hi = cap;
  }
  while (hi - lo > 1) {
    const int mid = lo + (hi - lo) / 2;
    if (is_feasible(modes, o, tp, mid))
      hi = mid;
    else
      lo = mid;
  }
  return hi;
}

/// Optimal shaper on a grid known to be feasible (or reported infeasible by the caller).
LpCandidate solve_grid(const std::vector<LpMode>& modes, const LpShaperOptions& o, double tp, int n, bool* feasible) {
  const LpProblem lp = build_problem(modes, o, tp, n);
  LpResult result = solve(lp, cost_vector(n, o.cost_k), o.max_pulse, tp);
  *feasible = result.feasible;
  LpCandidate candidate;
  if (!result.feasible) return candidate;
  clean_and_check(lp, result.x, o.max_pulse, tp);
  candidate.pulse_spacing = tp;
  candidate.pulse_count = n;
  const std::vector<double> cost = cost_vector(n, o.cost_k);
  for (int i = 0; i < n; ++i) candidate.cost += cost[static_cast<std::size_t>(i)] * result.x[static_cast<std::size_t>(i)];
  Shaper& s = candidate.shaper;
  s.type = "lp";
  s.omega = modes.front().omega;
  s.zeta = modes.front().zeta;
  for (int i = 0; i < n; ++i) {
    const double a = result.x[static_cast<std::size_t>(i)];
    if (i == 0 || a > 0.0) {
      s.times.push_back(tp * i);
      s.amplitudes.push_back(a);
    }
  }
  return candidate;
}

std::string describe(const std::vector<LpMode>& modes, const LpShaperOptions& o) {
  return std::to_string(modes.size()) + " mode(s), derivative order " + std::to_string(o.derivative_order) + ", " +
         std::to_string(o.bounds.size()) + " sensitivity bound(s)";
}

}  // namespace

LpCandidate lp_shaper_design(const std::vector<LpMode>& modes, const LpShaperOptions& options) {
  check_common(modes, options);
  check_spacing(options.pulse_spacing, "pulse_spacing");
  const double tp = options.pulse_spacing;
  if (options.pulse_count < 0 || options.pulse_count > kMaxPulseCount)
    throw core::InputError(core::at_field("pulse_count"), "expected 0 (smallest feasible) or 1.." +
                                                              std::to_string(kMaxPulseCount) + ", got " +
                                                              std::to_string(options.pulse_count));
  if (const int k = degenerate_mode(modes, tp); k >= 0)
    throw core::InputError(core::at_field("pulse_spacing"),
                           "Tp = " + show(tp) + " s is a whole number of damped periods of modes[" + std::to_string(k) +
                               "] (omega_d = " + show(damped_frequency(modes[static_cast<std::size_t>(k)].omega,
                                                                         modes[static_cast<std::size_t>(k)].zeta)) +
                               " rad/s): every impulse on this grid adds in phase there, no shaper cancels it");
  int n = options.pulse_count;
  if (n == 0) {
    const double duration = max_duration(modes, options);
    const int cap = pulse_cap(duration, tp);
    n = min_pulse_count(modes, options, tp, cap, 0);
    if (n == 0)
      throw core::InputError(core::at_field("pulse_count"),
                             "no shaper of up to " + std::to_string(cap) + " impulses (duration <= " + show(duration) +
                                 " s, max_duration) at spacing Tp = " + show(tp) + " s satisfies the constraints (" +
                                 describe(modes, options) + "): the LP is infeasible");
  }
  bool feasible = false;
  LpCandidate candidate = solve_grid(modes, options, tp, n, &feasible);
  if (!feasible)
    throw core::InputError(core::at_field("pulse_count"),
                           "no shaper with n = " + std::to_string(n) + " impulses at spacing Tp = " + show(tp) +
                               " s satisfies the constraints (" + describe(modes, options) +
                               "): the LP is infeasible; more impulses or another spacing are needed (n >= " +
                               std::to_string(2 * modes.size() * static_cast<std::size_t>(options.derivative_order + 1) + 1) +
                               " on a generic grid)");
  return candidate;
}

Shaper lp_shaper(const std::vector<LpMode>& modes, const LpShaperOptions& options) {
  return lp_shaper_design(modes, options).shaper;
}

std::vector<LpCandidate> lp_shaper_search(const std::vector<LpMode>& modes, const LpShaperOptions& base,
                                          const LpSearchOptions& search) {
  check_common(modes, base);
  check_spacing(search.sample_period, "sample_period");
  const double t = search.sample_period;
  if (search.max_multiple < 0 || search.max_multiple > kMaxMultiples)
    throw core::InputError(core::at_field("max_multiple"), "expected 0 (up to pi/omega_d of the lowest mode) or 1.." +
                                                               std::to_string(kMaxMultiples) + ", got " +
                                                               std::to_string(search.max_multiple));
  int multiples = search.max_multiple;
  if (multiples == 0) {
    double lowest = damped_frequency(modes.front().omega, modes.front().zeta);
    for (const LpMode& m : modes) lowest = std::min(lowest, damped_frequency(m.omega, m.zeta));
    const double limit = std::numbers::pi / lowest;
    const double count = std::floor(limit / t + 1e-9);
    if (count < 1.0)
      throw core::InputError(core::at_field("sample_period"),
                             "T = " + show(t) + " s exceeds pi/omega_d = " + show(limit) +
                                 " s of the lowest mode: no spacing to search (give max_multiple to search anyway)");
    if (count > kMaxMultiples)
      throw core::InputError(core::at_field("sample_period"),
                             "T = " + show(t) + " s gives " + show(count) + " spacings up to pi/omega_d = " + show(limit) +
                                 " s; at most " + std::to_string(kMaxMultiples) + " are searched (give max_multiple)");
    multiples = static_cast<int>(count);
  }
  const double duration = max_duration(modes, base);
  std::vector<LpCandidate> candidates;
  double last_duration = 0.0;
  int marginal = 0;  // grids the feasibility pass accepted and the solve with the cost refused
  for (int j = 1; j <= multiples; ++j) {
    const double tp = t * j;
    if (degenerate_mode(modes, tp) >= 0) continue;
    const int cap = pulse_cap(duration, tp);
    const int guess = last_duration > 0.0 ? std::clamp(static_cast<int>(std::lround(last_duration / tp)) + 1, 1, cap) : 0;
    const int n = min_pulse_count(modes, base, tp, cap, guess);
    if (n == 0) continue;
    bool feasible = false;
    LpCandidate candidate = solve_grid(modes, base, tp, n, &feasible);
    if (!feasible) {
      // Feasible within GLPK's tolerance without the cost, infeasible with it: the constraints are
      // nearly dependent (issue 27 §1: 40 modes 0.1 Hz apart). The grid is numerically marginal.
      ++marginal;
      continue;
    }
    candidate.multiple = j;
    last_duration = candidate.grid_duration();
    candidates.push_back(std::move(candidate));
  }
  if (candidates.empty())
    throw core::InputError(core::at_field("sample_period"),
                           "no spacing Tp = j*" + show(t) + " s (j = 1.." + std::to_string(multiples) +
                               ") admits a shaper of duration <= " + show(duration) + " s satisfying the constraints (" +
                               describe(modes, base) + ")" +
                               (marginal > 0 ? "; on " + std::to_string(marginal) +
                                                   " spacing(s) the constraints were numerically dependent, as with "
                                                   "many closely spaced modes: cancel fewer modes (one mode with a "
                                                   "sensitivity bound covers a band), a lower derivative order, or "
                                                   "the convolution of single-mode shapers"
                                             : std::string()));
  // Durations (n − 1)·j·T compare exactly as integers.
  std::sort(candidates.begin(), candidates.end(), [](const LpCandidate& a, const LpCandidate& b) {
    const auto key = [](const LpCandidate& c) {
      return std::make_tuple(static_cast<std::int64_t>(c.pulse_count - 1) * c.multiple, c.pulse_count, c.multiple);
    };
    return key(a) < key(b);
  });
  return candidates;
}

}  // namespace servotwin::shaping
