// solve(): bounds, options, dispatch to the methods, and the common description of a solution
// (coefficients, active bounds with Kuhn-Tucker multipliers, Table 3.1 case).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "servotwin/core/error.hpp"
#include "solver_internal.hpp"

namespace servotwin::rapid {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

core::InputError field_error(const std::string& field, const std::string& message) {
  return core::InputError(core::at_field(field), message);
}

std::string format_number(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

void validate_options(const SolveOptions& o, Method method) {
  if (!(o.rel_tolerance >= 0.0) || !std::isfinite(o.rel_tolerance)) {
    throw field_error("rel_tolerance", "must be a finite number >= 0, got " + format_number(o.rel_tolerance));
  }
  if (!(o.abs_tolerance >= 0.0) || !std::isfinite(o.abs_tolerance)) {
    throw field_error("abs_tolerance", "must be a finite number >= 0, got " + format_number(o.abs_tolerance));
  }
  if (o.max_boxes == 0) throw field_error("max_boxes", "must be at least 1");
  if (method != Method::Ga) return;
  if (o.ga.population < 2) throw field_error("ga.population", "must be at least 2");
  if (o.ga.elite > o.ga.population) {
    throw field_error("ga.elite", "must not exceed the population (" + std::to_string(o.ga.population) + ")");
  }
  if (!(o.ga.crossover_rate >= 0.0 && o.ga.crossover_rate <= 1.0)) {
    throw field_error("ga.crossover_rate", "must lie in [0, 1], got " + format_number(o.ga.crossover_rate));
  }
  if (!(o.ga.mutation_rate >= 0.0 && o.ga.mutation_rate <= 1.0)) {
    throw field_error("ga.mutation_rate", "must lie in [0, 1], got " + format_number(o.ga.mutation_rate));
  }
}

bool within(const Bounds& b, double p, double wn, double zeta) {
  return p >= b.p_min && p <= b.p_max && wn >= b.wn_min && wn <= b.wn_max && zeta >= b.zeta_min &&
         zeta <= b.zeta_max;
}

void set_coefficients(Solution& s) {
  if (s.theta.allFinite() && s.theta(2) != 0.0) {
    s.coefficients = coefficients_from_theta(s.theta);
  } else {
    s.coefficients = {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
    s.warnings.push_back("alpha_2 = 1/a2 is zero: the model coefficients are undefined");
  }
}

/// df/d(p, wn, zeta) with theta2 re-optimized.
Eigen::Vector3d physical_gradient(const detail::ReducedProblem& rp, double p, double wn, double zeta) {
  const Eigen::Vector3d g1 = rp.objective_gradient(theta1_from_poles(p, wn, zeta));
  Eigen::Matrix3d j = detail::theta1_log_jacobian(p, wn, zeta);
  j.col(0) /= p;
  j.col(1) /= wn;
  return j.transpose() * g1;
}

/// Active bounds, multipliers and the Table 3.1 case of a point within the bounds.
void describe_constrained(Solution& s, const detail::ReducedProblem& rp, const Bounds& b) {
  s.gradient = physical_gradient(rp, s.p, s.wn, s.zeta);
  const std::array<double, 3> value{s.p, s.wn, s.zeta};
  const std::array<double, 3> lo{b.p_min, b.wn_min, b.zeta_min}, hi{b.p_max, b.wn_max, b.zeta_max};
  const std::array<const char*, 3> name{"p", "wn", "zeta"};
  std::array<int, 3> side{};  // -1 lower active, +1 upper active
  for (std::size_t j = 0; j < 3; ++j) {
    const double d = s.gradient(static_cast<int>(j));
    if (lo[j] == hi[j]) {
      side[j] = d >= 0.0 ? -1 : 1;
    } else if (value[j] == lo[j]) {
      side[j] = -1;
    } else if (value[j] == hi[j]) {
      side[j] = 1;
    }
    if (side[j] != 0) {
      s.active.push_back({std::string(name[j]) + (side[j] < 0 ? "_min" : "_max"), side[j] < 0 ? d : -d});
    }
  }
  std::string list;
  for (std::size_t j = 0; j < 3; ++j) {
    if (side[j] == 0) continue;
    if (!list.empty()) list += ", ";
    list += std::string(name[j]) + " = " + name[j] + (side[j] < 0 ? "_min" : "_max");
  }
  const bool upper_frequency = side[0] > 0 || side[1] > 0;
  const int table_case = 1 + (side[2] < 0 ? 1 : 0) + (side[1] < 0 ? 2 : 0) + (side[0] < 0 ? 4 : 0) + (side[2] > 0 ? 8 : 0);
  if (list.empty()) {
    s.kkt_case = "1: unconstrained";
  } else if (upper_frequency) {
    s.kkt_case = "beyond Table 3.1 (upper frequency bound): " + list;
  } else {
    s.kkt_case = std::to_string(table_case) + ": " + list;
  }
  // On the fold p = wn (zeta +- sqrt(zeta^2 - 1)) the map (p, wn, zeta) -> theta1 is singular and
  // its image has a boundary that is no bound of the box (Eq. 3.16 does not exist there).
  const double fold = (s.p * s.p - 2.0 * s.p * s.zeta * s.wn + s.wn * s.wn) / (s.p * s.p + s.wn * s.wn);
  const Eigen::Vector3d g1 = rp.objective_gradient(theta1_from_poles(s.p, s.wn, s.zeta));
  if (fold < 1e-6 && g1.norm() > 0.0) {
    if (list.empty()) {
      s.kkt_case = "fold: no bound active; p is a real root of the quadratic factor (zeta >= 1), where the pole "
                   "parametrization is singular and the feasible set has an edge";
    } else {
      s.kkt_case += "; on the fold where p is a real root of the quadratic factor";
    }
  }
}

Solution least_squares_solution(const RegressionProblem& problem, const detail::ReducedProblem& rp, const Bounds& b) {
  Solution s;
  s.method = Method::Ls;
  s.warnings = rp.warnings();
  for (auto& note : rp.least_squares_notes()) s.warnings.push_back(std::move(note));
  s.theta = rp.least_squares();
  s.objective = problem.objective(s.theta);
  set_coefficients(s);
  s.p = s.wn = s.zeta = kNaN;
  s.lower_bound = kNaN;
  const std::vector<PoleFactorization> factors = pole_factorizations(s.theta.head<3>());
  for (const auto& f : factors) {
    if (within(b, f.p, f.wn, f.zeta)) {
      s.p = f.p;
      s.wn = f.wn;
      s.zeta = f.zeta;
      s.feasible = true;
      break;
    }
  }
  if (!s.feasible && !factors.empty()) {
    s.p = factors.front().p;
    s.wn = factors.front().wn;
    s.zeta = factors.front().zeta;
  }
  if (s.feasible) {
    s.kkt_case = "1: unconstrained";
  } else if (factors.empty()) {
    s.warnings.push_back("the unconstrained solution's characteristic polynomial has no factor (s + p)(s^2 + 2 zeta wn s + "
                         "wn^2) with real p and wn > 0");
  } else {
    std::string text = "the unconstrained solution violates the bounds:";
    for (const auto& f : factors) {
      text += " (p = " + format_number(f.p) + ", wn = " + format_number(f.wn) + ", zeta = " + format_number(f.zeta) + ")";
    }
    s.warnings.push_back(text);
  }
  return s;
}

Solution constrained_solution(const RegressionProblem& problem, const detail::ReducedProblem& rp, const Bounds& b,
                              Method method, double p, double wn, double zeta) {
  Solution s;
  s.method = method;
  s.warnings = rp.warnings();
  s.p = p;
  s.wn = wn;
  s.zeta = zeta;
  s.theta = rp.theta(theta1_from_poles(p, wn, zeta));
  s.objective = problem.objective(s.theta);
  s.feasible = within(b, p, wn, zeta);
  set_coefficients(s);
  s.lower_bound = kNaN;
  describe_constrained(s, rp, b);
  return s;
}

}  // namespace

Bounds default_bounds(double ts) {
  if (!std::isfinite(ts) || ts <= 0.0) {
    throw field_error("ts", "sample period must be a finite positive number of seconds, got " + format_number(ts));
  }
  const double low = 2.0 * std::numbers::pi * 0.2;
  const double nyquist = std::numbers::pi / ts;
  if (nyquist < low) {
    throw field_error("ts", "sample period " + format_number(ts) + " s puts the Nyquist frequency below the default "
                            "lower frequency bound of 0.2 Hz");
  }
  Bounds b;
  b.p_min = b.wn_min = low;
  b.p_max = b.wn_max = nyquist;
  b.zeta_min = 0.2;
  b.zeta_max = 2.0;
  return b;
}

void validate(const Bounds& b) {
  const std::array<std::pair<const char*, double>, 6> values{{{"p_min", b.p_min},
                                                              {"p_max", b.p_max},
                                                              {"wn_min", b.wn_min},
                                                              {"wn_max", b.wn_max},
                                                              {"zeta_min", b.zeta_min},
                                                              {"zeta_max", b.zeta_max}}};
  for (const auto& [name, v] : values) {
    if (!std::isfinite(v) || v <= 0.0) {
      throw field_error(std::string("bounds.") + name, "must be a finite positive number, got " + format_number(v));
    }
  }
  const std::array<std::pair<const char*, std::pair<double, double>>, 3> pairs{
      {{"p", {b.p_min, b.p_max}}, {"wn", {b.wn_min, b.wn_max}}, {"zeta", {b.zeta_min, b.zeta_max}}}};
  for (const auto& [name, range] : pairs) {
    if (range.first > range.second) {
      throw field_error(std::string("bounds.") + name + "_max",
                        std::string("must not be below ") + name + "_min (" + format_number(range.first) + "), got " +
                            format_number(range.second));
    }
  }
}

const char* method_name(Method m) noexcept {
  switch (m) {
    case Method::Ls:
      return "ls";
    case Method::Exact:
      return "exact";
    case Method::Ga:
      return "ga";
  }
  return "unknown";
}

Solution solve(const RegressionProblem& problem, Method method, const Bounds& bounds, const SolveOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (problem.empty()) throw field_error("problem", "the regression problem has no samples");
  validate(bounds);
  validate_options(options, method);
  const detail::ReducedProblem rp(problem);
  Solution s;
  switch (method) {
    case Method::Ls:
      s = least_squares_solution(problem, rp, bounds);
      break;
    case Method::Exact: {
      Solution ls = least_squares_solution(problem, rp, bounds);
      if (ls.feasible) {
        // Table 3.1 case 1: the unconstrained minimum is feasible, hence the constrained one.
        s = std::move(ls);
        s.method = Method::Exact;
        s.gradient = physical_gradient(rp, s.p, s.wn, s.zeta);
        s.lower_bound = s.objective;
        s.certified = true;
        break;
      }
      const detail::ExactResult r = detail::exact_search(rp, bounds, options);
      s = constrained_solution(problem, rp, bounds, Method::Exact, r.p, r.wn, r.zeta);
      s.lower_bound = std::min(rp.y_norm_squared() * (r.lower_excess + 0.5 * rp.c() * rp.c()), s.objective);
      s.certified = r.certified;
      s.boxes = r.boxes;
      s.warnings.insert(s.warnings.end(), r.warnings.begin(), r.warnings.end());
      break;
    }
    case Method::Ga: {
      detail::GaResult r = detail::genetic_search(rp, bounds, options.ga);
      s = constrained_solution(problem, rp, bounds, Method::Ga, r.p, r.wn, r.zeta);
      s.seed = options.ga.seed;
      s.history = std::move(r.history);
      break;
    }
  }
  s.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace servotwin::rapid
