#pragma once
// Shared helpers of the regression tests: a realistic synthetic identification capture (random
// trapezoidal moves driving the closed-loop model of thesis Eq. 3.3 with Coulomb friction), an
// independent least-squares solve from a triangular factor, and small matrix comparisons.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid::test {

/// Coefficients of Eq. 3.3: [s^2 + a1 s + a2 + a3/s] x = [b0 s^2 + b1 s + b2 + a3/s] x_r - d(xdot).
struct AxisCoefficients {
  double a1, a2, a3, b0, b1, b2, d0, d1;

  /// theta of Eq. 3.10 (normalized by a2).
  [[nodiscard]] Vector8 theta() const {
    Vector8 t;
    t << a3 / a2, a1 / a2, 1.0 / a2, b2 / a2, b1 / a2, b0 / a2, d0 / a2, d1 / a2;
    return t;
  }
};

/// A PID-controlled axis with acceleration and velocity feed-forward (Eq. 3.5 form): a real pole
/// at 5 Hz, a pair at 40 Hz with damping 0.7, friction of +-2 % / -1.5 % of a2 in length units.
inline AxisCoefficients pid_axis() {
  const double p = 2.0 * M_PI * 5.0;
  const double wn = 2.0 * M_PI * 40.0;
  const double zeta = 0.7;
  AxisCoefficients c{};
  c.a1 = p + 2.0 * zeta * wn;
  c.a2 = wn * wn + 2.0 * p * zeta * wn;
  c.a3 = p * wn * wn;
  c.b0 = 0.8;
  c.b1 = 0.9 * c.a1;
  c.b2 = c.a2;
  c.d0 = 0.02 * c.a2;
  c.d1 = -0.015 * c.a2;
  return c;
}

struct SyntheticCapture {
  double ts = 0.0;
  std::vector<double> command;
  std::vector<double> actual;
};

struct CaptureSettings {
  double ts = 0.001;
  std::size_t samples = 22'000;
  double range = 10.0;           ///< moves within +-range [mm]
  double v_max = 200.0;          ///< [mm/s]
  double a_max = 2000.0;         ///< [mm/s^2]
  double max_dwell = 0.05;       ///< standstill between moves, uniform in [0, max_dwell] [s]
  double resolution = 0.0;       ///< encoder quantization of the actual position [mm], 0 = none
  double noise = 0.0;            ///< Gaussian noise on the actual position [mm]
  int substeps = 20;             ///< RK4 steps per sample period
  unsigned seed = 2007;
  AxisCoefficients axis = pid_axis();
};

/// A command of constant-acceleration pieces (trapezoidal / triangular velocity moves).
class TrapezoidalCommand {
 public:
  TrapezoidalCommand(const CaptureSettings& s, double duration) {
    std::mt19937_64 rng(s.seed);
    std::uniform_real_distribution<double> target(-s.range, s.range);
    std::uniform_real_distribution<double> dwell(0.0, s.max_dwell);
    double t = 0.0, x = 0.0;
    while (t < duration + 1.0) {
      const double goal = target(rng);
      const double distance = std::abs(goal - x);
      const double dir = goal > x ? 1.0 : -1.0;
      const double t_acc = std::min(s.v_max / s.a_max, std::sqrt(distance / s.a_max));
      const double v_peak = s.a_max * t_acc;
      const double t_cruise = (distance - v_peak * t_acc) / s.v_max > 0.0 ? (distance - v_peak * t_acc) / v_peak : 0.0;
      add(t, t_acc, x, 0.0, dir * s.a_max);
      add(t, t_cruise, pieces_.back().end_position(), dir * v_peak, 0.0);
      add(t, t_acc, pieces_.back().end_position(), dir * v_peak, -dir * s.a_max);
      add(t, dwell(rng), goal, 0.0, 0.0);
      x = goal;
    }
  }

  /// Position, velocity and acceleration at time t.
  void evaluate(double t, double& r, double& rd, double& rdd) const {
    while (cursor_ + 1 < pieces_.size() && t >= pieces_[cursor_ + 1].t0) ++cursor_;
    while (cursor_ > 0 && t < pieces_[cursor_].t0) --cursor_;
    const Piece& p = pieces_[cursor_];
    const double tau = t - p.t0;
    r = p.x0 + p.v0 * tau + 0.5 * p.a * tau * tau;
    rd = p.v0 + p.a * tau;
    rdd = p.a;
  }

 private:
  struct Piece {
    double t0, duration, x0, v0, a;
    [[nodiscard]] double end_position() const { return x0 + v0 * duration + 0.5 * a * duration * duration; }
  };
  void add(double& t, double duration, double x0, double v0, double a) {
    pieces_.push_back({t, duration, x0, v0, a});
    t += duration;
  }
  std::vector<Piece> pieces_;
  mutable std::size_t cursor_ = 0;
};

/// The thesis's identification experiment in miniature: random targets within +-range reached
/// with trapezoidal velocity and a random dwell, the axis of Eq. 3.3 integrated with RK4 (friction
/// switching on the sign of the true velocity), sampled every ts.
inline SyntheticCapture simulate_capture(const CaptureSettings& s) {
  std::mt19937_64 rng(s.seed + 1);
  std::normal_distribution<double> normal;
  const AxisCoefficients& c = s.axis;
  const TrapezoidalCommand command(s, static_cast<double>(s.samples) * s.ts);
  SyntheticCapture out;
  out.ts = s.ts;
  out.command.resize(s.samples);
  out.actual.resize(s.samples);
  double z = 0.0, x = 0.0, v = 0.0;  // z = integral of (x_r - x)
  const double h = s.ts / s.substeps;
  auto deriv = [&](double t, double zz, double xx, double vv, double& dz, double& dx, double& dv) {
    double r, rd, rdd;
    command.evaluate(t, r, rd, rdd);
    const double friction = vv > 0.0 ? c.d0 : (vv < 0.0 ? c.d1 : 0.0);
    dz = r - xx;
    dx = vv;
    dv = -c.a1 * vv - c.a2 * xx + c.a3 * zz + c.b0 * rdd + c.b1 * rd + c.b2 * r - friction;
  };
  for (std::size_t k = 0; k < s.samples; ++k) {
    const double tk = static_cast<double>(k) * s.ts;
    double r, rd, rdd;
    command.evaluate(tk, r, rd, rdd);
    out.command[k] = r;
    double y = x;
    if (s.noise > 0.0) y += s.noise * normal(rng);
    if (s.resolution > 0.0) y = s.resolution * std::round(y / s.resolution);
    out.actual[k] = y;
    for (int i = 0; i < s.substeps; ++i) {
      const double t0 = tk + i * h;
      double k1z, k1x, k1v, k2z, k2x, k2v, k3z, k3x, k3v, k4z, k4x, k4v;
      deriv(t0, z, x, v, k1z, k1x, k1v);
      deriv(t0 + h / 2, z + h / 2 * k1z, x + h / 2 * k1x, v + h / 2 * k1v, k2z, k2x, k2v);
      deriv(t0 + h / 2, z + h / 2 * k2z, x + h / 2 * k2x, v + h / 2 * k2v, k3z, k3x, k3v);
      deriv(t0 + h, z + h * k3z, x + h * k3x, v + h * k3v, k4z, k4x, k4v);
      z += h / 6 * (k1z + 2 * k2z + 2 * k3z + k4z);
      x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
  }
  return out;
}

/// Unconstrained least squares from the factor U = [U11 u12; 0 u22]: theta = U11^-1 u12 by back
/// substitution on the column-equilibrated U11 (columns scaled to unit norm), independent of the
/// library's solvers.
inline Vector8 least_squares(const RegressionProblem& problem) {
  const Matrix9& u = problem.factor();
  Vector8 d;
  for (int j = 0; j < kParameterCount; ++j) {
    const double norm = u.col(j).head(j + 1).norm();
    d(j) = norm > 0.0 ? 1.0 / norm : 1.0;
  }
  const Matrix8 t = u.topLeftCorner<kParameterCount, kParameterCount>() * d.asDiagonal();
  Vector8 zs = u.col(kParameterCount).head<kParameterCount>();
  for (int i = kParameterCount - 1; i >= 0; --i) {
    for (int j = i + 1; j < kParameterCount; ++j) zs(i) -= t(i, j) * zs(j);
    zs(i) /= t(i, i);
  }
  return d.asDiagonal() * zs;
}

/// Scales positions by a unit factor (m -> mm: 1e3).
inline std::vector<double> scaled(const std::vector<double>& v, double factor) {
  std::vector<double> out(v.size());
  std::transform(v.begin(), v.end(), out.begin(), [factor](double x) { return x * factor; });
  return out;
}

/// Canonical triangular factor of explicit rows [Phi y] by Eigen's Householder QR.
inline Matrix9 dense_factor(const Eigen::MatrixXd& rows) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(rows);
  Matrix9 r = qr.matrixQR().topRows(kParameterCount + 1).triangularView<Eigen::Upper>();
  for (int i = 0; i <= kParameterCount; ++i) {
    if (r(i, i) < 0.0) r.row(i) *= -1.0;
  }
  return r;
}

/// max |a_ij - b_ij| / sqrt(b_ii b_jj) over the augmented Gram matrices of two problems.
inline double gram_difference(const NormalEquations& a, const Eigen::MatrixXd& b_gram) {
  Eigen::MatrixXd g(kParameterCount + 1, kParameterCount + 1);
  g.topLeftCorner(kParameterCount, kParameterCount) = a.P;
  g.topRightCorner(kParameterCount, 1) = a.R;
  g.bottomLeftCorner(1, kParameterCount) = a.R.transpose();
  g(kParameterCount, kParameterCount) = a.gamma;
  double worst = 0.0;
  for (int i = 0; i <= kParameterCount; ++i) {
    for (int j = 0; j <= kParameterCount; ++j) {
      const double scale = std::sqrt(b_gram(i, i) * b_gram(j, j));
      if (scale > 0.0) worst = std::max(worst, std::abs(g(i, j) - b_gram(i, j)) / scale);
      else worst = std::max(worst, std::abs(g(i, j)));
    }
  }
  return worst;
}

}  // namespace servotwin::rapid::test
