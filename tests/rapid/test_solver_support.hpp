#pragma once
// Problems for the solver tests, built without the library's regression code: a simulated Eq. 3.3
// axis (RK4 on x'' = b0 xr'' + b1 xr' + b2 xr - a1 x' - a2 x + a3 int(xr - x) - d(x')) driven by random
// trapezoidal moves, its Eq. 3.9 regressors, and the factor of [Phi y] by Eigen's Householder QR;
// random least-squares problems; and an independent brute-force reference for the constrained
// minimum (its own elimination of theta2 by a complete orthogonal decomposition, a 60^3 grid and
// polishing).

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "servotwin/rapid/regression.hpp"
#include "servotwin/rapid/solver.hpp"

namespace servotwin::rapid::test {

inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// [Phi y] -> problem, through Eigen's Householder QR (independent of the library's accumulator).
inline RegressionProblem problem_from_rows(const Eigen::MatrixXd& phi, const Eigen::VectorXd& y, double ts) {
  Eigen::MatrixXd m(phi.rows(), kParameterCount + 1);
  m.leftCols(kParameterCount) = phi;
  m.col(kParameterCount) = y;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(m);
  Matrix9 r = Matrix9::Zero();
  const Eigen::Index rows = std::min<Eigen::Index>(m.rows(), kParameterCount + 1);
  r.topRows(rows) = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
  return RegressionProblem(r, static_cast<std::uint64_t>(phi.rows()), ts);
}

/// Trapezoidal point-to-point moves, evaluated at any time.
class MoveProfile {
 public:
  MoveProfile(int moves, double range, double feed, double accel, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> target(-range, range), dwell(0.0, 0.05);
    double x = 0.0, t = 0.05;
    for (int i = 0; i < moves; ++i) {
      Segment s;
      s.start = t;
      s.x0 = x;
      const double goal = target(rng);
      const double d = std::abs(goal - x);
      s.sign = goal >= x ? 1.0 : -1.0;
      s.accel = accel;
      s.ta = feed / accel;
      s.vp = feed;
      s.tc = (d - accel * s.ta * s.ta) / feed;
      if (s.tc < 0.0) {
        s.ta = std::sqrt(d / accel);
        s.vp = accel * s.ta;
        s.tc = 0.0;
      }
      s.length = d;
      s.duration = 2.0 * s.ta + s.tc;
      segments_.push_back(s);
      t += s.duration + dwell(rng);
      x = goal;
    }
    end_ = t + 0.05;
  }
  [[nodiscard]] double duration() const { return end_; }
  /// position, velocity, acceleration at time t
  [[nodiscard]] Eigen::Vector3d at(double t) const {
    double x = 0.0;
    for (const auto& s : segments_) {
      if (t < s.start) return {x, 0.0, 0.0};
      const double tau = t - s.start;
      if (tau >= s.duration) {
        x = s.x0 + s.sign * s.length;
        continue;
      }
      double p, v, a;
      if (tau < s.ta) {
        p = 0.5 * s.accel * tau * tau, v = s.accel * tau, a = s.accel;
      } else if (tau < s.ta + s.tc) {
        p = 0.5 * s.accel * s.ta * s.ta + s.vp * (tau - s.ta), v = s.vp, a = 0.0;
      } else {
        const double r = s.duration - tau;
        p = s.length - 0.5 * s.accel * r * r, v = s.accel * r, a = -s.accel;
      }
      return {s.x0 + s.sign * p, s.sign * v, s.sign * a};
    }
    return {x, 0.0, 0.0};
  }

 private:
  struct Segment {
    double start, x0, sign, accel, ta, tc, vp, length, duration;
  };
  std::vector<Segment> segments_;
  double end_ = 0.0;
};

struct AxisData {
  std::vector<double> command, actual;
};

/// Simulates Eq. 3.3 (coefficients of ModelCoefficients) with smooth Coulomb friction, samples at
/// ts, adds Gaussian noise and encoder quantization to x.
inline AxisData simulate_axis(const ModelCoefficients& c, const MoveProfile& profile, double ts, double noise,
                              double quantum, std::uint64_t seed) {
  constexpr int substeps = 4;
  const double h = ts / substeps;
  const double v_smooth = 0.05;  // length/s over which friction switches
  auto rhs = [&](double t, const Eigen::Vector3d& s) {
    const Eigen::Vector3d r = profile.at(t);
    const double d = c.d0 / (1.0 + std::exp(-s(1) / v_smooth)) + c.d1 / (1.0 + std::exp(s(1) / v_smooth));
    const double acc = c.b0 * r(2) + c.b1 * r(1) + c.b2 * r(0) - c.a1 * s(1) - c.a2 * s(0) + c.a3 * s(2) - d;
    return Eigen::Vector3d(s(1), acc, r(0) - s(0));
  };
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  AxisData out;
  Eigen::Vector3d state = Eigen::Vector3d::Zero();  // x, x', int(xr - x)
  const auto samples = static_cast<std::size_t>(profile.duration() / ts);
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * ts;
    out.command.push_back(profile.at(t)(0));
    double x = state(0) + noise * gauss(rng);
    if (quantum > 0.0) x = quantum * std::round(x / quantum);
    out.actual.push_back(x);
    for (int i = 0; i < substeps; ++i) {
      const double ti = t + i * h;
      const Eigen::Vector3d k1 = rhs(ti, state);
      const Eigen::Vector3d k2 = rhs(ti + 0.5 * h, state + 0.5 * h * k1);
      const Eigen::Vector3d k3 = rhs(ti + 0.5 * h, state + 0.5 * h * k2);
      const Eigen::Vector3d k4 = rhs(ti + h, state + h * k3);
      state += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
  }
  return out;
}

/// Eq. 3.9 regressor rows (columns e_i, -x', -x'', x_r, x_r', x_r'', -PV, -NV; y = x) with central
/// differences and the integrated tracking error; `scale` multiplies all lengths.
inline RegressionProblem problem_from_axis(const AxisData& data, double ts, double deadband, double scale = 1.0) {
  const std::size_t n = data.actual.size();
  std::vector<double> x(n), xr(n);
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = scale * data.actual[k];
    xr[k] = scale * data.command[k];
  }
  auto diff = [&](const std::vector<double>& s) {
    std::vector<double> d(n, 0.0);
    for (std::size_t k = 1; k + 1 < n; ++k) d[k] = (s[k + 1] - s[k - 1]) / (2.0 * ts);
    return d;
  };
  const std::vector<double> v = diff(x), a = diff(v), vr = diff(xr), ar = diff(vr);
  std::vector<double> ei(n, 0.0);
  double sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    sum += ts * (xr[k] - x[k]);
    ei[k] = sum;
  }
  const std::size_t first = 2, last = n - 2;
  Eigen::MatrixXd phi(static_cast<Eigen::Index>(last - first), kParameterCount);
  Eigen::VectorXd y(phi.rows());
  for (std::size_t k = first; k < last; ++k) {
    const auto row = static_cast<Eigen::Index>(k - first);
    phi.row(row) << ei[k], -v[k], -a[k], xr[k], vr[k], ar[k], v[k] > scale * deadband ? -1.0 : 0.0,
        v[k] < -scale * deadband ? -1.0 : 0.0;
    y(row) = x[k];
  }
  return problem_from_rows(phi, y, ts);
}

/// Table 4.1's PID-controlled virtual drive ("Actual" column).
inline ModelCoefficients thesis_pid_drive() {
  ModelCoefficients c;
  c.a1 = 192.65;
  c.a2 = 44356.23;
  c.a3 = 316830.21;
  c.b0 = 0.0;
  c.b1 = 190.1;
  c.b2 = 44356.23;
  c.d0 = 441.0;
  c.d1 = -302.0;
  return c;
}

/// Coefficients of (s + p)(s^2 + 2 zeta wn s + wn^2) with a zero pair and friction.
inline ModelCoefficients drive_from_poles(double p, double wn, double zeta, double b1_ratio, double d0, double d1) {
  ModelCoefficients c;
  c.a1 = p + 2.0 * zeta * wn;
  c.a2 = wn * wn + 2.0 * p * zeta * wn;
  c.a3 = p * wn * wn;
  c.b0 = 0.0;
  c.b1 = b1_ratio * c.a1;
  c.b2 = c.a2;
  c.d0 = d0;
  c.d1 = d1;
  return c;
}

/// A thesis-like identification problem (about 10 s at 1 kHz, +-10 mm moves at up to 200 mm/s).
inline RegressionProblem thesis_like_problem(const ModelCoefficients& c, std::uint64_t seed, double quantum = 1e-3,
                                             double noise = 0.0, double scale = 1.0, int moves = 60) {
  const double ts = 1e-3;
  const MoveProfile profile(moves, 10.0, 200.0, 2000.0, seed);
  const AxisData data = simulate_axis(c, profile, ts, noise, quantum, seed + 1);
  return problem_from_axis(data, ts, 0.3, scale);  // deadband off the 0.5 mm/s velocity quantum
}

/// Random problem: y = Phi theta + noise with theta from given poles and Phi's columns mixed so that
/// they are correlated like the real regressors.
inline RegressionProblem random_problem(std::mt19937_64& rng, double p, double wn, double zeta, double noise,
                                        double collinearity = 0.0, int rows = 120) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::MatrixXd phi(rows, kParameterCount);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < kParameterCount; ++j) phi(i, j) = gauss(rng);
  }
  // Scale the columns like e_i, x', x'', ... (different units) and correlate x' with x_r'.
  const double col_scale[kParameterCount] = {1e-2, 1e2, 1e4, 10.0, 1e2, 1e4, 1.0, 1.0};
  phi.col(1) = phi.col(4) + (1.0 - collinearity) * phi.col(1);
  phi.col(2) = phi.col(5) + (1.0 - collinearity) * phi.col(2);
  for (int j = 0; j < kParameterCount; ++j) phi.col(j) *= col_scale[j];
  Vector8 theta;
  theta.head<3>() = theta1_from_poles(p, wn, zeta);
  for (int j = 3; j < kParameterCount; ++j) theta(j) = gauss(rng) * 0.5 / col_scale[j];
  theta(3) = 1.0;
  Eigen::VectorXd y = phi * theta;
  const double y_rms = std::sqrt(y.squaredNorm() / rows);
  for (int i = 0; i < rows; ++i) y(i) += noise * y_rms * gauss(rng);
  return problem_from_rows(phi, y, 1e-3);
}

/// theta1 -> min over theta2 of f, computed independently of the library's reduction: a complete
/// orthogonal decomposition of the theta2 columns of the factor (Eigen's rank decision), whose
/// orthogonal complement carries what theta2 cannot fit; f = 1/2 ||M_y - M_1 theta1||^2.
class ReferenceObjective {
 public:
  explicit ReferenceObjective(const RegressionProblem& problem) {
    const Matrix9& u = problem.factor();
    const Eigen::MatrixXd u2 = u.block<9, 5>(0, 3);
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(u2);
    Eigen::MatrixXd rest(9, 4);
    rest.leftCols(3) = u.leftCols<3>();
    rest.col(3) = u.col(kParameterCount);
    const Eigen::MatrixXd q = cod.householderQ();
    m_ = (q.transpose() * rest).bottomRows(9 - cod.rank());
  }
  [[nodiscard]] double operator()(const Eigen::Vector3d& theta1) const {
    return 0.5 * (m_.col(3) - m_.leftCols<3>() * theta1).squaredNorm();
  }

 private:
  Eigen::Matrix<double, Eigen::Dynamic, 4, 0, 9, 4> m_;
};

/// Independent reference for the constrained minimum: ReferenceObjective on a 60^3 grid in
/// (ln p, ln wn, zeta), then the 8 best grid points polished by a projected coordinate search with
/// shrinking steps. Its value can only be above the true minimum (it is attained at its point).
struct BruteForce {
  double objective;
  double p, wn, zeta;
};
inline BruteForce brute_force_minimum(const RegressionProblem& problem, const Bounds& b, int grid = 60) {
  const ReferenceObjective f(problem);
  const double lo[3] = {std::log(b.p_min), std::log(b.wn_min), b.zeta_min};
  const double hi[3] = {std::log(b.p_max), std::log(b.wn_max), b.zeta_max};
  auto phys = [&](const std::array<double, 3>& x) {
    return Eigen::Vector3d(std::clamp(std::exp(x[0]), b.p_min, b.p_max), std::clamp(std::exp(x[1]), b.wn_min, b.wn_max),
                           x[2]);
  };
  auto eval = [&](const std::array<double, 3>& x) {
    const Eigen::Vector3d v = phys(x);
    return f(theta1_from_poles(v(0), v(1), v(2)));
  };
  auto at = [&](int i, int dim) { return grid == 1 ? lo[dim] : lo[dim] + (hi[dim] - lo[dim]) * i / (grid - 1); };
  std::vector<std::pair<double, std::array<double, 3>>> points;
  points.reserve(static_cast<std::size_t>(grid * grid * grid));
  for (int i = 0; i < grid; ++i) {
    for (int j = 0; j < grid; ++j) {
      for (int k = 0; k < grid; ++k) {
        const std::array<double, 3> x{at(i, 0), at(j, 1), at(k, 2)};
        points.emplace_back(eval(x), x);
      }
    }
  }
  const std::size_t starts = std::min<std::size_t>(8, points.size());
  std::partial_sort(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(starts), points.end(),
                    [](const auto& a, const auto& c) { return a.first < c.first; });
  BruteForce best{points[0].first, 0, 0, 0};
  std::array<double, 3> best_x = points[0].second;
  for (std::size_t start = 0; start < starts; ++start) {
    std::array<double, 3> x = points[start].second;
    double fx = points[start].first;
    std::array<double, 3> step{(hi[0] - lo[0]) / grid, (hi[1] - lo[1]) / grid, (hi[2] - lo[2]) / grid};
    for (int round = 0; round < 4000; ++round) {
      bool moved = false;
      for (int j = 0; j < 3; ++j) {
        for (const double sign : {1.0, -1.0}) {
          std::array<double, 3> y = x;
          y[static_cast<std::size_t>(j)] =
              std::clamp(y[static_cast<std::size_t>(j)] + sign * step[static_cast<std::size_t>(j)], lo[j], hi[j]);
          const double fy = eval(y);
          if (fy < fx) {
            x = y;
            fx = fy;
            moved = true;
          }
        }
      }
      if (!moved) {
        for (auto& st : step) st *= 0.5;
        if (std::max({step[0], step[1], step[2]}) < 1e-12) break;
      }
    }
    if (fx < best.objective) {
      best.objective = fx;
      best_x = x;
    }
  }
  const Eigen::Vector3d v = phys(best_x);
  best.p = v(0);
  best.wn = v(1);
  best.zeta = v(2);
  return best;
}

}  // namespace servotwin::rapid::test
