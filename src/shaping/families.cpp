#include "servotwin/shaping/families.hpp"

#include <Eigen/Dense>
#include <unsupported/Eigen/AutoDiff>
#include <array>
#include <memory>
#include <mutex>
#include <utility>
#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "shaper_checks.hpp"

namespace servotwin::shaping {
namespace {

using std::numbers::pi;

constexpr std::array<std::string_view, 8> kTypeNames = {"zv", "zvd", "zvdd", "mzv", "ei", "2hump_ei", "3hump_ei", "zv4"};

Shaper normalized(std::string type, double omega, double zeta, std::vector<double> times,
                  std::vector<double> amplitudes) {
  double sum = 0.0;
  for (double a : amplitudes) sum += a;
  for (double& a : amplitudes) a /= sum;
  return {std::move(type), omega, zeta, std::move(times), std::move(amplitudes)};
}

double damped(double omega, double zeta) { return omega * std::sqrt(1.0 - zeta * zeta); }

// Impulses every half damped period with binomial weights times K^i: the ZV, ZVD, ZVDD family
// (Singer–Seering), K = e^{−ζ ω_n T_d/2} = e^{−ζπ/√(1−ζ²)}.
Shaper binomial_shaper(std::string type, double omega, double zeta, int order) {
  detail::check_design_mode(omega, zeta);
  const double half_period = pi / damped(omega, zeta);
  const double k = std::exp(-zeta * omega * half_period);
  std::vector<double> times;
  std::vector<double> amplitudes;
  double binomial = 1.0;
  double k_power = 1.0;
  for (int i = 0; i <= order; ++i) {
    times.push_back(half_period * i);
    amplitudes.push_back(binomial * k_power);
    binomial = binomial * (order - i) / (i + 1);
    k_power *= k;
  }
  return normalized(std::move(type), omega, zeta, std::move(times), std::move(amplitudes));
}

// ---- EI family: Newton on the defining conditions -------------------------------------------

// cos and sin of one angle with one libm call; for dual numbers the derivatives follow from the
// same two values (Eigen's cos() and sin() of an AutoDiffScalar would each call both).
inline void cos_sin(double angle, double& c, double& s) {
  c = std::cos(angle);
  s = std::sin(angle);
}
template <typename Derivatives>
void cos_sin(const Eigen::AutoDiffScalar<Derivatives>& angle, Eigen::AutoDiffScalar<Derivatives>& c,
             Eigen::AutoDiffScalar<Derivatives>& s) {
  const double cv = std::cos(angle.value());
  const double sv = std::sin(angle.value());
  c = Eigen::AutoDiffScalar<Derivatives>(cv, -sv * angle.derivatives());
  s = Eigen::AutoDiffScalar<Derivatives>(sv, cv * angle.derivatives());
}

enum class Kind { kZero, kHump };
struct Condition {
  Kind kind;
  int frequency;  ///< -1: the design frequency; otherwise index of a free critical frequency
};

// Unknowns (normalized frequency: ω_n = 1): amplitudes A_0..A_{n−1}, times t_1..t_{n−1}
// (t_0 = 0), then the free critical frequencies. Equations: ΣA = 1, then per condition either
// C = S = 0 (zero vibration) or V = V_tol and ∂(C² + S²)/∂ω = 0 (a hump of height V_tol).
template <int Impulses, int Frequencies>
struct EiProblem {
  static constexpr int kUnknowns = 2 * Impulses - 1 + Frequencies;
  static constexpr int kConditions = (kUnknowns - 1) / 2;
  static_assert(2 * kConditions + 1 == kUnknowns);
  using Vector = Eigen::Matrix<double, kUnknowns, 1>;
  using Matrix = Eigen::Matrix<double, kUnknowns, kUnknowns>;

  std::array<Condition, kConditions> conditions;
  double zeta = 0.0;
  double v_tol = 0.0;

  template <typename Scalar>
  void residuals(const Eigen::Matrix<Scalar, kUnknowns, 1>& x, Eigen::Matrix<Scalar, kUnknowns, 1>& f) const {
    const double s = std::sqrt(1.0 - zeta * zeta);
    Scalar sum = x[0];
    for (int i = 1; i < Impulses; ++i) sum += x[i];
    f[0] = sum - 1.0;
    const Scalar& t_last = x[2 * Impulses - 2];
    int row = 1;
    for (const Condition& condition : conditions) {
      const Scalar w = condition.frequency < 0 ? Scalar(1.0) : x[2 * Impulses - 1 + condition.frequency];
      Scalar c(0.0), sn(0.0), c_w(0.0), s_w(0.0);
      for (int i = 0; i < Impulses; ++i) {
        const Scalar t = i == 0 ? Scalar(0.0) : x[Impulses + i - 1];
        const Scalar lag = t_last - t;
        const Scalar weight = x[i] * exp(-zeta * w * lag);
        const Scalar phase = s * w * t;
        Scalar cos_p, sin_p;
        cos_sin(phase, cos_p, sin_p);
        c += weight * cos_p;
        sn += weight * sin_p;
        if (condition.kind == Kind::kHump) {
          c_w += weight * (-zeta * lag * cos_p - s * t * sin_p);
          s_w += weight * (-zeta * lag * sin_p + s * t * cos_p);
        }
      }
      if (condition.kind == Kind::kZero) {
        f[row++] = c;
        f[row++] = sn;
      } else {
        f[row++] = sqrt(c * c + sn * sn) - v_tol;
        f[row++] = c * c_w + sn * s_w;
      }
    }
  }

  Vector value(const Vector& x) const {
    Vector f;
    residuals(x, f);
    return f;
  }

  void value_and_jacobian(const Vector& x, Vector& f, Matrix& jacobian) const {
    using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, kUnknowns, 1>>;
    Eigen::Matrix<Dual, kUnknowns, 1> xd;
    for (int i = 0; i < kUnknowns; ++i) xd[i] = Dual(x[i], kUnknowns, i);
    Eigen::Matrix<Dual, kUnknowns, 1> fd;
    residuals(xd, fd);
    for (int j = 0; j < kUnknowns; ++j) {
      f[j] = fd[j].value();
      jacobian.row(j) = fd[j].derivatives().transpose();
    }
  }

  // Times strictly increasing from 0 and positive frequencies: the domain of the conditions.
  static bool in_domain(const Vector& x) {
    double previous = 0.0;
    for (int i = 1; i < Impulses; ++i) {
      if (!(x[Impulses + i - 1] > previous)) return false;
      previous = x[Impulses + i - 1];
    }
    for (int k = 0; k < Frequencies; ++k)
      if (!(x[2 * Impulses - 1 + k] > 0.0)) return false;
    return true;
  }

  // Damped Newton (step halving on the max-norm of the residuals). After each full Newton step the
  // same LU factors are reused for cheap chord steps while they still shrink the residual tenfold:
  // a Jacobian costs as much as ~15 residual evaluations, and near the solution the chord steps
  // converge almost as fast.
  bool newton(Vector& x) const {
    Vector f;
    Matrix jacobian;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
      value_and_jacobian(x, f, jacobian);
      double norm = f.template lpNorm<Eigen::Infinity>();
      if (norm < kTolerance) return true;
      const Eigen::PartialPivLU<Matrix> lu(jacobian);
      const Vector step = lu.solve(-f);
      if (!step.allFinite()) return false;
      double scale = 1.0;
      bool accepted = false;
      for (int halving = 0; halving < kMaxHalvings && !accepted; ++halving, scale *= 0.5) {
        const Vector trial = x + scale * step;
        if (!in_domain(trial)) continue;
        const double trial_norm = value(trial).template lpNorm<Eigen::Infinity>();
        if (trial_norm < norm) {
          x = trial;
          norm = trial_norm;
          accepted = true;
        }
      }
      if (!accepted) return norm < 1e-11;
      if (scale == 0.5) chord_steps(lu, x, norm);  // only after a full (undamped) step
      if (norm < kTolerance) return true;
    }
    return value(x).template lpNorm<Eigen::Infinity>() < 1e-11;
  }

  static constexpr double kTolerance = 1e-13;
  // Started from a predicted point Newton converges in a few iterations or not at all (the
  // continuation then halves its step): more iterations would only make failures slow.
  static constexpr int kMaxIterations = 15;
  static constexpr int kMaxHalvings = 20;
  static constexpr double kChordContraction = 0.25;

  void chord_steps(const Eigen::PartialPivLU<Matrix>& lu, Vector& x, double& norm, int max_steps = 6) const {
    Vector f = value(x);
    for (int chord = 0; chord < max_steps && norm >= kTolerance; ++chord) {
      const Vector trial = x + lu.solve(-f);
      if (!in_domain(trial)) return;
      const Vector trial_f = value(trial);
      const double trial_norm = trial_f.template lpNorm<Eigen::Infinity>();
      const bool fast = trial_norm < kChordContraction * norm;
      if (trial_norm < norm) {
        x = trial;
        f = trial_f;
        norm = trial_norm;
      }
      if (!fast) return;
    }
  }
};

// Tangent dx/dζ of the solution curve at (x, ζ): −J⁻¹ ∂f/∂ζ, with ∂f/∂ζ by a central difference
// (a predictor only needs a few digits). Also returns the LU factors of J, which the corrector
// reuses for chord steps before it pays for a new Jacobian.
template <int Impulses, int Frequencies>
struct Tangent {
  using Problem = EiProblem<Impulses, Frequencies>;
  typename Problem::Vector direction;
  Eigen::PartialPivLU<typename Problem::Matrix> lu;
};

template <int Impulses, int Frequencies>
Tangent<Impulses, Frequencies> solution_tangent(EiProblem<Impulses, Frequencies> problem,
                                                const typename EiProblem<Impulses, Frequencies>::Vector& x) {
  using Problem = EiProblem<Impulses, Frequencies>;
  typename Problem::Vector f;
  typename Problem::Matrix jacobian;
  problem.value_and_jacobian(x, f, jacobian);
  const double zeta = problem.zeta;
  const double h = 1e-6;
  problem.zeta = zeta + h;
  const typename Problem::Vector f_plus = problem.value(x);
  problem.zeta = zeta - h;
  const typename Problem::Vector f_minus = problem.value(x);
  Tangent<Impulses, Frequencies> tangent{typename Problem::Vector(), Eigen::PartialPivLU<typename Problem::Matrix>(jacobian)};
  tangent.direction = tangent.lu.solve(-(f_plus - f_minus) / (2.0 * h));
  return tangent;
}

// Continues a solution `x` of the conditions at damping `reached` to damping `zeta` with a tangent
// predictor: one step for the usual dampings, halved whenever Newton does not converge from the
// prediction so that every start stays inside the basin of the solution being followed.
template <int Impulses, int Frequencies>
typename EiProblem<Impulses, Frequencies>::Vector continue_in_zeta(EiProblem<Impulses, Frequencies> problem,
                                                                    typename EiProblem<Impulses, Frequencies>::Vector x,
                                                                    double reached, double zeta, const char* label,
                                                                    double min_step = 1e-4) {
  using Problem = EiProblem<Impulses, Frequencies>;
  double step = std::min(zeta - reached, 0.1);
  while (reached < zeta) {
    const double target = std::min(zeta, reached + step);
    problem.zeta = reached;
    const Tangent<Impulses, Frequencies> tangent = solution_tangent(problem, x);
    typename Problem::Vector trial = x + (target - reached) * tangent.direction;
    problem.zeta = target;
    bool converged = false;
    if (Problem::in_domain(trial) && trial.allFinite()) {
      double norm = problem.value(trial).template lpNorm<Eigen::Infinity>();
      problem.chord_steps(tangent.lu, trial, norm, 20);
      converged = norm < Problem::kTolerance || problem.newton(trial);
    }
    if (converged) {
      x = trial;
      reached = target;
      continue;
    }
    step *= 0.5;
    if (step < min_step)
      throw core::InputError(core::at_field("zeta"), std::string("no ") + label + " shaper satisfies its defining conditions at zeta = " +
                                                         detail::show(target) + " (design zeta " + detail::show(zeta) + ")");
  }
  return x;
}

// Exact solutions of one family at dampings k·kSpacing (from ζ = 0 until the continuation fails, an
// impulse turns non-positive, or kMaxZeta), with the tangent dx/dζ and the Jacobian's LU factors at each: a design at any damping
// in range starts from the cubic Hermite interpolation of the two neighbouring nodes (error ~1e-7)
// and converges with a few chord steps on the nearest node's factors — no new Jacobian.
template <int Impulses, int Frequencies>
struct SolutionTable {
  using Problem = EiProblem<Impulses, Frequencies>;
  static constexpr double kSpacing = 0.01;
  static constexpr double kMaxZeta = 0.6;
  std::vector<Tangent<Impulses, Frequencies>> tangents;
  std::vector<typename Problem::Vector> solutions;

  SolutionTable(Problem problem, typename Problem::Vector undamped, const char* label) {
    typename Problem::Vector x = undamped;
    for (int k = 0;; ++k) {
      problem.zeta = k * kSpacing;
      solutions.push_back(x);
      tangents.push_back(solution_tangent(problem, x));
      // Past the first node with a non-positive impulse the family has no shaper (the design
      // refuses it), so the table ends there.
      if ((k + 1) * kSpacing > kMaxZeta || x.head(Impulses).minCoeff() <= 0.0) break;
      try {
        // A coarse minimum step: where the family ends, giving up early costs nothing (designs
        // beyond the table continue from its last node with the fine default).
        x = continue_in_zeta(problem, x, k * kSpacing, (k + 1) * kSpacing, label, kSpacing / 8);
      } catch (const core::InputError&) {
        break;  // the family ends here; designs beyond it report the failure themselves
      }
    }
  }

  // The solution at `zeta`, or false when zeta lies beyond the table or the corrector fails.
  bool solve(Problem problem, double zeta, typename Problem::Vector& x) const {
    const auto k = static_cast<std::size_t>(zeta / kSpacing);
    if (k + 1 >= solutions.size()) return false;
    const double u = zeta / kSpacing - static_cast<double>(k);
    const double u2 = u * u, u3 = u2 * u;
    x = (2 * u3 - 3 * u2 + 1) * solutions[k] + (u3 - 2 * u2 + u) * kSpacing * tangents[k].direction +
        (-2 * u3 + 3 * u2) * solutions[k + 1] + (u3 - u2) * kSpacing * tangents[k + 1].direction;
    problem.zeta = zeta;
    if (!Problem::in_domain(x)) return false;
    double norm = problem.value(x).template lpNorm<Eigen::Infinity>();
    problem.chord_steps(tangents[u < 0.5 ? k : k + 1].lu, x, norm, 20);
    return norm < Problem::kTolerance || problem.newton(x);
  }

  // Continuation from the last node, for dampings beyond the table.
  [[nodiscard]] typename Problem::Vector beyond(Problem problem, double zeta, const char* label) const {
    return continue_in_zeta(problem, solutions.back(), static_cast<double>(solutions.size() - 1) * kSpacing, zeta, label);
  }
};

// The table of a family for a vibration tolerance, built on first use (~0.1–0.5 ms) and shared:
// the few tolerances a program uses each keep their table.
template <int Impulses, int Frequencies>
std::shared_ptr<const SolutionTable<Impulses, Frequencies>> solution_table(
    const EiProblem<Impulses, Frequencies>& problem, const typename EiProblem<Impulses, Frequencies>::Vector& undamped,
    const char* label) {
  static std::mutex mutex;
  static std::vector<std::pair<double, std::shared_ptr<const SolutionTable<Impulses, Frequencies>>>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  for (const auto& [v_tol, table] : tables)
    if (v_tol == problem.v_tol) return table;
  if (tables.size() >= 16) tables.erase(tables.begin());  // bounded: oldest tolerance goes
  tables.emplace_back(problem.v_tol, std::make_shared<const SolutionTable<Impulses, Frequencies>>(problem, undamped, label));
  return tables.back().second;
}

// Solves the family's conditions at `zeta` from the undamped closed form `start` (exact at ζ = 0).
template <int Impulses, int Frequencies>
Shaper solve_ei_family(const char* type, const char* label, double omega, double zeta, double v_tol,
                       const std::array<Condition, EiProblem<Impulses, Frequencies>::kConditions>& conditions,
                       typename EiProblem<Impulses, Frequencies>::Vector start) {
  using Problem = EiProblem<Impulses, Frequencies>;
  const Problem problem{conditions, 0.0, v_tol};
  const auto table = solution_table(problem, start, label);
  typename Problem::Vector x;
  if (!table->solve(problem, zeta, x)) x = table->beyond(problem, zeta, label);
  start = x;
  std::vector<double> times{0.0};
  std::vector<double> amplitudes;
  for (int i = 0; i < Impulses; ++i) {
    if (!(start[i] > 0.0))
      throw core::InputError(core::at_field("zeta"), std::string("the ") + label + " shaper for zeta = " + detail::show(zeta) +
                                                         " would need a negative impulse; use a lower damping or another family");
    amplitudes.push_back(start[i]);
    if (i > 0) times.push_back(start[Impulses + i - 1] / omega);
  }
  return normalized(type, omega, zeta, std::move(times), std::move(amplitudes));
}

void check_tolerance(double v_tol) {
  if (!std::isfinite(v_tol) || v_tol <= 0.0 || v_tol >= 0.5)
    throw core::InputError(core::at_field("v_tol"), "expected a vibration tolerance in (0, 0.5), got " + detail::show(v_tol));
}

}  // namespace

std::string_view to_string(ShaperType type) noexcept { return kTypeNames[static_cast<std::size_t>(type)]; }

ShaperType parse_shaper_type(std::string_view name, std::string_view field) {
  for (std::size_t i = 0; i < kTypeNames.size(); ++i)
    if (kTypeNames[i] == name) return static_cast<ShaperType>(i);
  std::string names;
  for (std::string_view known : kTypeNames) names += (names.empty() ? "" : ", ") + std::string(known);
  throw core::InputError(core::at_field(std::string(field)),
                         "unknown shaper type '" + std::string(name) + "'; expected one of " + names);
}

std::vector<std::string> shaper_type_names() { return {kTypeNames.begin(), kTypeNames.end()}; }

Shaper zv_shaper(double omega, double zeta) { return binomial_shaper("zv", omega, zeta, 1); }
Shaper zvd_shaper(double omega, double zeta) { return binomial_shaper("zvd", omega, zeta, 2); }
Shaper zvdd_shaper(double omega, double zeta) { return binomial_shaper("zvdd", omega, zeta, 3); }

Shaper mzv_shaper(double omega, double zeta) {
  detail::check_design_mode(omega, zeta);
  // Phases 0, 3π/4, 3π/2 of the damped oscillation; a1 = a2/√2 = a3 closes the vector triangle.
  const double spacing = 0.75 * pi / damped(omega, zeta);
  const double k = std::exp(-zeta * omega * spacing);
  const double outer = 1.0 - 1.0 / std::numbers::sqrt2;
  return normalized("mzv", omega, zeta, {0.0, spacing, 2.0 * spacing},
                    {outer, (std::numbers::sqrt2 - 1.0) * k, outer * k * k});
}

Shaper ei_shaper(double omega, double zeta, double v_tol) {
  detail::check_design_mode(omega, zeta);
  check_tolerance(v_tol);
  // Undamped closed form (Singer–Seering): A = [(1+V)/4, (1−V)/2, (1+V)/4] at 0, π, 2π (ω_n = 1);
  // V(θ) = |(1+V)/2 cos θ + (1−V)/2| with θ = πω/ω_n has zeros at cos θ = −(1−V)/(1+V).
  const double delta = std::acos((1.0 - v_tol) / (1.0 + v_tol));
  EiProblem<3, 2>::Vector start;
  start << (1.0 + v_tol) / 4.0, (1.0 - v_tol) / 2.0, (1.0 + v_tol) / 4.0, pi, 2.0 * pi, 1.0 - delta / pi, 1.0 + delta / pi;
  return solve_ei_family<3, 2>("ei", "EI", omega, zeta, v_tol,
                               {{{Kind::kHump, -1}, {Kind::kZero, 0}, {Kind::kZero, 1}}}, start);
}

Shaper two_hump_ei_shaper(double omega, double zeta, double v_tol) {
  detail::check_design_mode(omega, zeta);
  check_tolerance(v_tol);
  // Undamped closed form (Singhose): X = (V²(√(1−V²)+1))^{1/3}, A1 = A4 = (3X² + 2X + 3V²)/(16X),
  // A2 = A3 = 1/2 − A1 at 0, π, 2π, 3π. With u = cos(θ/2), V(θ) = |2u(4A1u² − 3A1 + A2)|: zeros
  // at u² = (3A1 − A2)/(4A1) and humps at u² = (3A1 − A2)/(12A1).
  const double x = std::cbrt(v_tol * v_tol * (std::sqrt(1.0 - v_tol * v_tol) + 1.0));
  const double a1 = (3.0 * x * x + 2.0 * x + 3.0 * v_tol * v_tol) / (16.0 * x);
  const double a2 = 0.5 - a1;
  const double hump = 2.0 * std::acos(std::sqrt((3.0 * a1 - a2) / (12.0 * a1))) / pi;
  const double zero = 2.0 * std::acos(std::sqrt((3.0 * a1 - a2) / (4.0 * a1))) / pi;
  EiProblem<4, 4>::Vector start;
  start << a1, a2, a2, a1, pi, 2.0 * pi, 3.0 * pi, hump, 2.0 - hump, zero, 2.0 - zero;
  return solve_ei_family<4, 4>(
      "2hump_ei", "2-hump EI", omega, zeta, v_tol,
      {{{Kind::kZero, -1}, {Kind::kHump, 0}, {Kind::kHump, 1}, {Kind::kZero, 2}, {Kind::kZero, 3}}}, start);
}

Shaper three_hump_ei_shaper(double omega, double zeta, double v_tol) {
  detail::check_design_mode(omega, zeta);
  check_tolerance(v_tol);
  // Undamped closed form (Singhose): A1 = A5 = (1 + 3V + 2√(2V(V+1)))/16, A2 = A4 = (1−V)/4,
  // A3 = 1 − 2(A1 + A2) at 0, π, ..., 4π. With c = cos θ, V(θ) = |4A1c² + 2A2c + A3 − 2A1|: humps at
  // c = −1 (the mode) and c = −A2/(4A1), zeros at the roots of the quadratic.
  const double a1 = (1.0 + 3.0 * v_tol + 2.0 * std::sqrt(2.0 * v_tol * (v_tol + 1.0))) / 16.0;
  const double a2 = (1.0 - v_tol) / 4.0;
  const double a3 = 1.0 - 2.0 * (a1 + a2);
  const double hump = std::acos(-a2 / (4.0 * a1)) / pi;
  const double root = std::sqrt(4.0 * a2 * a2 - 16.0 * a1 * (a3 - 2.0 * a1));
  const double zero_a = std::acos((-2.0 * a2 + root) / (8.0 * a1)) / pi;
  const double zero_b = std::acos((-2.0 * a2 - root) / (8.0 * a1)) / pi;
  EiProblem<5, 6>::Vector start;
  start << a1, a2, a3, a2, a1, pi, 2.0 * pi, 3.0 * pi, 4.0 * pi, hump, 2.0 - hump, zero_a, 2.0 - zero_a, zero_b,
      2.0 - zero_b;
  return solve_ei_family<5, 6>("3hump_ei", "3-hump EI", omega, zeta, v_tol,
                               {{{Kind::kHump, -1},
                                 {Kind::kHump, 0},
                                 {Kind::kHump, 1},
                                 {Kind::kZero, 2},
                                 {Kind::kZero, 3},
                                 {Kind::kZero, 4},
                                 {Kind::kZero, 5}}},
                               start);
}

Shaper design_shaper(ShaperType type, double omega, double zeta, double v_tol) {
  switch (type) {
    case ShaperType::kZv: return zv_shaper(omega, zeta);
    case ShaperType::kZvd: return zvd_shaper(omega, zeta);
    case ShaperType::kZvdd: return zvdd_shaper(omega, zeta);
    case ShaperType::kMzv: return mzv_shaper(omega, zeta);
    case ShaperType::kEi: return ei_shaper(omega, zeta, v_tol);
    case ShaperType::kTwoHumpEi: return two_hump_ei_shaper(omega, zeta, v_tol);
    case ShaperType::kThreeHumpEi: return three_hump_ei_shaper(omega, zeta, v_tol);
    case ShaperType::kZv4: break;
  }
  throw core::InputError(core::at_field("type"), "the zv4 shaper needs its p-parameters (zv4_shaper), not design_shaper");
}

}  // namespace servotwin::shaping
