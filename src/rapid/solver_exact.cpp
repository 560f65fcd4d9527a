// The exact solver: the global minimum of f under the pole bounds, certified by a spatial branch
// and bound over the box x = (ln p, ln wn, zeta).
//
// With theta2 eliminated (solver_reduction.cpp) the objective is F(x) = ||y||^2 (g(x) + c^2/2),
// g(x) = 1/2 ||A theta1~(x) - b||^2, a convex quadratic of theta1~ = s o theta1(p, wn, zeta) (Eq. 3.14).
// Why the returned point is the global minimum to the stated tolerance:
//  1. Every box B of the search space gets a lower bound L(B) <= min_B g that is rigorous
//     (outward-rounded enclosures, duality certificates, rounding margins), the largest of
//     a. hull: the componentwise range of theta1~ over B is attained at B's vertices (each component
//        is monotone in each variable for the others fixed: alpha_2 and alpha_i in all three,
//        alpha_1 in wn always, in p with the sign of 1 - 4 zeta^2, in zeta with the sign of wn - p,
//        cf. Eq. 3.15), so g >= min of the convex quadratic over that box (box_least_squares);
//     b. Taylor model exact in p: for fixed (wn, zeta) the image of p in [p_lo, p_hi] is the straight
//        segment between theta1~(p_lo) and theta1~(p_hi) (theta1 is a linear-fractional function of
//        p with a common denominator), so the image of B is
//          { (1 - mu) E_lo(wn, zeta) + mu E_hi(wn, zeta) : mu in [0, 1] };
//        E_lo and E_hi are expanded to first order about the centre of (ln wn, zeta) with the
//        remainder enclosed by the interval Jacobian (mean-value theorem), the cross term mu d by
//        its magnitude; the affine part gives a three-variable box QP, the remainder box e a
//        distance penalty (||A (z + e) - b|| >= ||A z - b|| - ||A e||). The bound's error is second
//        order in the widths of (ln wn, zeta) and does not depend on the width in p, so weakly
//        identified real poles (flat valleys in p) cost no extra boxes;
//     c. mean value: g(c) + [grad g](B) (x - c) with the gradient enclosed by interval arithmetic.
//  2. Monotonicity: when an enclosure of dg/dx_j over B excludes 0, the minimizer over the whole
//     search space cannot lie in B unless B touches the bound towards which g decreases; then B
//     is reduced to that face (a minimizer over B lies on it), else B is discarded.
//  3. Upper bounds come from points: at each box centre g is minimized exactly over the box's p
//     range along the segment (closed form), and improvements are polished by projected Newton.
//  4. Best-first search: the box with the lowest bound is bisected along the variable whose
//     enclosure is widest in the metric of A. Boxes with L(B) >= g_best - tol are closed; the
//     search ends when the smallest open bound is within tol of g_best. Then
//        min over the bounds of g >= min(L(B) over open and closed boxes) =: certified bound,
//     since every point of the search space lies in such a box or in a discarded one.
// Rounding: enclosures are outward rounded or widened by 1e-13 relative; QP bounds come from weak
// duality with a rounding margin. The certificate refers to the reduced quadratic as computed from
// the factor (a backward-stable QR), and differences below 1e-13 ||y||^2 are not resolved.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <queue>
#include <string>

#include "solver_internal.hpp"

namespace servotwin::rapid::detail {

namespace {

constexpr double kUlp = 0x1.0p-52;
constexpr double kTiny = 1e-300;
constexpr double kSlack = 1e-13;  // relative widening of point evaluations used in enclosures
constexpr double kInf = std::numeric_limits<double>::infinity();

double down(double x) noexcept { return x - (std::abs(x) * kUlp + kTiny); }
double up(double x) noexcept { return x + (std::abs(x) * kUlp + kTiny); }

inline Interval point(double x) noexcept { return {x, x}; }
inline Interval operator+(Interval a, Interval b) noexcept { return {down(a.lo + b.lo), up(a.hi + b.hi)}; }
inline Interval operator-(Interval a) noexcept { return {-a.hi, -a.lo}; }
inline Interval operator*(Interval a, Interval b) noexcept {
  const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
  return {down(std::min(std::min(p1, p2), std::min(p3, p4))), up(std::max(std::max(p1, p2), std::max(p3, p4)))};
}
/// Product of two intervals of non-negative numbers.
inline Interval mul_pp(Interval a, Interval b) noexcept { return {down(a.lo * b.lo), up(a.hi * b.hi)}; }
/// Product of any interval with one of non-negative numbers.
inline Interval mul_gp(Interval a, Interval b) noexcept {
  return {down(a.lo >= 0.0 ? a.lo * b.lo : a.lo * b.hi), up(a.hi >= 0.0 ? a.hi * b.hi : a.hi * b.lo)};
}
/// 2^k a (exact).
inline Interval times_power_of_two(double k, Interval a) noexcept { return {k * a.lo, k * a.hi}; }
/// 1/a for a > 0.
inline Interval reciprocal(Interval a) noexcept { return {down(1.0 / a.hi), up(1.0 / a.lo)}; }
/// a^2 for a >= 0.
inline Interval square_p(Interval a) noexcept { return mul_pp(a, a); }
/// exp over [lo, hi] (libm's exp is within an ulp; two rounding units of margin).
Interval exp_range(double lo, double hi) noexcept {
  return {down(down(std::exp(lo))), up(up(std::exp(hi)))};
}

using IntervalMatrix = std::array<std::array<Interval, 3>, 3>;

/// d theta1~ / d(ln p, ln wn, zeta) over P x W x Z (positive intervals; rows scaled by `scale` >= 0),
/// natural interval extension of the formulas in theta1_log_jacobian, column `only` or all (-1).
IntervalMatrix log_jacobian_enclosure(Interval p, Interval w, Interval z, const Eigen::Vector3d& scale,
                                      int only = -1) noexcept {
  const Interval one = point(1.0);
  const Interval iw = reciprocal(w);
  const Interval s = mul_pp(p, iw);
  const Interval k = one + times_power_of_two(2.0, mul_pp(z, s));
  const Interval ik2 = reciprocal(square_p(k));
  const Interval iwik2 = mul_pp(iw, ik2);
  const Interval iw2ik2 = mul_pp(iw, iwik2);
  const Interval s2 = square_p(s);
  IntervalMatrix j{};
  if (only < 0 || only == 0) {
    j[0][0] = mul_pp(p, ik2);
    j[1][0] = mul_gp(one + -times_power_of_two(4.0, square_p(z)), mul_pp(s, iwik2));
    j[2][0] = -times_power_of_two(2.0, mul_pp(mul_pp(z, s), iw2ik2));
  }
  if (only < 0 || only == 1) {
    j[0][1] = times_power_of_two(2.0, mul_pp(mul_pp(z, s2), mul_pp(w, ik2)));
    j[1][1] = -times_power_of_two(2.0, mul_pp(z + s + mul_pp(s2, z), iwik2));
    j[2][1] = -times_power_of_two(2.0, mul_pp(one + mul_pp(z, s), iw2ik2));
  }
  if (only < 0 || only == 2) {
    j[0][2] = -times_power_of_two(2.0, mul_pp(mul_pp(p, s), ik2));
    j[1][2] = times_power_of_two(2.0, mul_gp(one + -s2, iwik2));
    j[2][2] = -times_power_of_two(2.0, mul_pp(s, iw2ik2));
  }
  for (int r = 0; r < 3; ++r) {
    const Interval sr = point(scale(r));
    for (auto& entry : j[static_cast<std::size_t>(r)]) entry = mul_gp(entry, sr);
  }
  return j;
}

/// The search space and the conversion between x and the physical variables. Points on the
/// boundary of x map exactly to the bounds, so active bounds are reported without rounding.
struct Domain {
  SearchBox box;
  Bounds bounds;

  explicit Domain(const Bounds& b) : bounds(b) {
    box.lo = {std::log(b.p_min), std::log(b.wn_min), b.zeta_min};
    box.hi = {std::log(b.p_max), std::log(b.wn_max), b.zeta_max};
  }
  [[nodiscard]] double p(double u) const noexcept {
    if (u <= box.lo[0]) return bounds.p_min;
    if (u >= box.hi[0]) return bounds.p_max;
    return std::clamp(std::exp(u), bounds.p_min, bounds.p_max);
  }
  [[nodiscard]] double wn(double v) const noexcept {
    if (v <= box.lo[1]) return bounds.wn_min;
    if (v >= box.hi[1]) return bounds.wn_max;
    return std::clamp(std::exp(v), bounds.wn_min, bounds.wn_max);
  }
  [[nodiscard]] Eigen::Vector3d physical(const Eigen::Vector3d& x) const noexcept { return {p(x(0)), wn(x(1)), x(2)}; }
  [[nodiscard]] Eigen::Vector3d clamp(const Eigen::Vector3d& x) const noexcept {
    Eigen::Vector3d c;
    for (int j = 0; j < 3; ++j) c(j) = std::clamp(x(j), box.lo[static_cast<std::size_t>(j)], box.hi[static_cast<std::size_t>(j)]);
    return c;
  }
};

Eigen::Vector3d scaled_theta(const ReducedProblem& rp, double p, double wn, double zeta) noexcept {
  return rp.theta1_scale().cwiseProduct(theta1_from_poles(p, wn, zeta));
}

double excess_at(const ReducedProblem& rp, const Eigen::Vector3d& physical) noexcept {
  return rp.excess(theta1_from_poles(physical(0), physical(1), physical(2)));
}



}  // namespace

double Interval::mag() const noexcept { return std::max(std::abs(lo), std::abs(hi)); }

BoxEnclosure enclose(const SearchBox& box, const Eigen::Vector3d& scale, int column) {
  BoxEnclosure e;
  const double p[2] = {std::exp(box.lo[0]), std::exp(box.hi[0])};
  const double w[2] = {std::exp(box.lo[1]), std::exp(box.hi[1])};
  const double z[2] = {box.lo[2], box.hi[2]};
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = Eigen::Vector3d::Constant(-kInf);
  const int mp = p[0] < p[1] ? 2 : 1, mw = w[0] < w[1] ? 2 : 1, mz = z[0] < z[1] ? 2 : 1;
  for (int corner = 0; corner < 8; ++corner) {
    if ((corner & 1) >= mp || ((corner >> 1) & 1) >= mw || ((corner >> 2) & 1) >= mz) continue;
    const Eigen::Vector3d t = theta1_from_poles(p[corner & 1], w[(corner >> 1) & 1], z[(corner >> 2) & 1]);
    lo = lo.cwiseMin(t);
    hi = hi.cwiseMax(t);
  }
  for (int k = 0; k < 3; ++k) {
    const double slack = kSlack * std::max(std::abs(lo(k)), std::abs(hi(k)));
    e.theta[static_cast<std::size_t>(k)] = {down(scale(k) * (lo(k) - slack)), up(scale(k) * (hi(k) + slack))};
  }
  e.jacobian = log_jacobian_enclosure(exp_range(box.lo[0], box.hi[0]), exp_range(box.lo[1], box.hi[1]),
                                      {box.lo[2], box.hi[2]}, scale, column);
  return e;
}

int hull_points(const SearchBox& box, const Eigen::Vector3d& scale, std::array<Eigen::Vector3d, 12>& points) {
  const double p[2] = {std::exp(box.lo[0]), std::exp(box.hi[0])};
  const double a = std::exp(box.lo[1]), b = std::exp(box.hi[1]);
  const double z[2] = {box.lo[2], box.hi[2]};
  // (w1, w2): the ends of the arc (wn, wn^2) and the intersection of its end tangents.
  const double w1[3] = {a, b, 0.5 * (a + b)};
  const double w2[3] = {a * a, b * b, a * b};
  const int np = p[0] < p[1] ? 2 : 1, nz = z[0] < z[1] ? 2 : 1, nw = a < b ? 3 : 1;
  int count = 0;
  for (int i = 0; i < np; ++i) {
    for (int k = 0; k < nz; ++k) {
      for (int m = 0; m < nw; ++m) {
        const double a2 = w2[m] + 2.0 * p[i] * z[k] * w1[m];
        const Eigen::Vector3d t(p[i] * w2[m] / a2, (p[i] + 2.0 * z[k] * w1[m]) / a2, 1.0 / a2);
        points[static_cast<std::size_t>(count++)] = scale.cwiseProduct(t);
      }
    }
  }
  return count;
}

std::array<Interval, 3> gradient_enclosure(const ReducedProblem& rp, const SearchBox& box, int only) {
  const Eigen::Matrix3d& a = rp.a();
  const Eigen::Vector3d& b = rp.b();
  const BoxEnclosure enc = enclose(box, rp.theta1_scale(), only);
  // w = A^T (A theta1~ - b) over the hull of theta1~, in midpoint-radius form.
  Eigen::Vector3d mid, half;
  for (int k = 0; k < 3; ++k) {
    const Interval& t = enc.theta[static_cast<std::size_t>(k)];
    mid(k) = 0.5 * (t.lo + t.hi);
    half(k) = up(std::max(t.hi - mid(k), mid(k) - t.lo));
  }
  const Eigen::Vector3d residual_mid = a * mid - b;
  const Eigen::Vector3d residual_rad =
      a.cwiseAbs() * half + 16.0 * kUlp * (a.cwiseAbs() * mid.cwiseAbs() + b.cwiseAbs());
  const Eigen::Vector3d w_mid = a.transpose() * residual_mid;
  const Eigen::Vector3d w_rad = a.transpose().cwiseAbs() * residual_rad +
                                16.0 * kUlp * (a.transpose().cwiseAbs() * residual_mid.cwiseAbs());
  std::array<Interval, 3> w;
  for (int k = 0; k < 3; ++k) w[static_cast<std::size_t>(k)] = {down(w_mid(k) - w_rad(k)), up(w_mid(k) + w_rad(k))};
  std::array<Interval, 3> gradient;
  for (std::size_t j = 0; j < 3; ++j) {
    if (only >= 0 && static_cast<int>(j) != only) {
      gradient[j] = {-kInf, kInf};
      continue;
    }
    Interval gj{0.0, 0.0};
    for (std::size_t k = 0; k < 3; ++k) gj = gj + enc.jacobian[k][j] * w[k];
    gradient[j] = gj;
  }
  return gradient;
}

BoxBound bound_box(const ReducedProblem& rp, const SearchBox& box) {
  const Eigen::Matrix3d& a = rp.a();
  const Eigen::Vector3d& b = rp.b();
  const Eigen::Vector3d& scale = rp.theta1_scale();
  BoxBound out;

  // (a) convex hull: g >= 1/2 dist(b, A conv{points})^2.
  {
    std::array<Eigen::Vector3d, 12> points;
    const int count = hull_points(box, scale, points);
    std::array<Eigen::Vector3d, 12> z;
    double error = 0.0;
    for (int i = 0; i < count; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      z[ui] = a * points[ui] - b;
      // The points carry a few rounding units (exp, the rational map): a relative kSlack covers it.
      error = std::max(error, kSlack * (a.cwiseAbs() * points[ui].cwiseAbs() + b.cwiseAbs()).norm());
    }
    const PolytopeDistance d = polytope_distance(z.data(), count);
    const double distance = std::max(d.lower_bound - error, 0.0);
    out.hull = down(0.5 * distance * distance);
  }

  // (b) mean value form g(c) + [grad g](B) (x - c).
  std::array<double, 3> r{};
  Eigen::Vector3d centre;
  for (std::size_t j = 0; j < 3; ++j) {
    centre(static_cast<int>(j)) = 0.5 * (box.lo[j] + box.hi[j]);
    r[j] = up(std::max(box.hi[j] - centre(static_cast<int>(j)), centre(static_cast<int>(j)) - box.lo[j]));
  }
  const double pc = std::exp(centre(0)), wc = std::exp(centre(1)), zc = centre(2);
  {
    out.gradient = gradient_enclosure(rp, box);
    const Eigen::Vector3d tc = scaled_theta(rp, pc, wc, zc);
    const Eigen::Vector3d rc = a * tc - b;
    const double gc = 0.5 * rc.squaredNorm();
    const double gc_error = kSlack * (a.cwiseAbs() * tc.cwiseAbs() + b.cwiseAbs()).norm() * (rc.norm() + kTiny) + kTiny;
    double mv = gc - gc_error;
    for (std::size_t j = 0; j < 3; ++j) {
      // The centre is computed in rounded arithmetic: widen the radius a little.
      mv -= up(out.gradient[j].mag() * (r[j] + kSlack * (std::abs(centre(static_cast<int>(j))) + 1.0)));
    }
    out.mean_value = std::max(down(mv), 0.0);
  }
  out.lower = std::max({out.hull, out.mean_value, 0.0});

  // Split the variable along which theta1~ moves furthest in A's metric over the box (Gauss-Newton
  // estimate of how far g can change): boxes then take the shape of g's level sets, which keeps
  // the hull's bilinear gaps (p with wn, p with zeta) second order near the minimum.
  const Eigen::Matrix3d jc = a * scale.asDiagonal() * theta1_log_jacobian(pc, wc, zc);
  std::array<double, 3> score{};
  for (std::size_t j = 0; j < 3; ++j) score[j] = r[j] * jc.col(static_cast<int>(j)).norm();
  if (box.lo[1] >= box.hi[1] && (box.lo[0] >= box.hi[0] || box.lo[2] >= box.hi[2])) {
    score = {0.0, 0.0, 0.0};  // a segment in p or zeta: the hull is exact
  }
  for (std::size_t j = 0; j < 3; ++j) {
    if (!(box.lo[j] < box.hi[j]) || !std::isfinite(score[j])) score[j] = 0.0;
  }
  out.split = static_cast<int>(std::max_element(score.begin(), score.end()) - score.begin());
  if (!(score[static_cast<std::size_t>(out.split)] > 0.0)) {
    // No second-order estimate. A box wide in p or zeta alone is bounded exactly (a segment);
    // otherwise split the widest variable.
    int wide = 0;
    for (std::size_t j = 0; j < 3; ++j) wide += box.lo[j] < box.hi[j] ? 1 : 0;
    out.split = -1;
    if (wide > 1 || box.lo[1] < box.hi[1]) {
      double widest = 0.0;
      for (std::size_t j = 0; j < 3; ++j) {
        if (box.hi[j] - box.lo[j] > widest) {
          widest = box.hi[j] - box.lo[j];
          out.split = static_cast<int>(j);
        }
      }
    }
  }
  return out;
}

namespace {

/// Exact minimum of g along p in [p(u_lo), p(u_hi)] for fixed (wn, zeta): the image is a segment.
struct LinePoint {
  double u, g;
};
LinePoint line_minimum(const ReducedProblem& rp, const Domain& dom, double u_lo, double u_hi, double wn, double zeta) {
  const double p_lo = dom.p(u_lo), p_hi = dom.p(u_hi);
  const Eigen::Vector3d t_lo = scaled_theta(rp, p_lo, wn, zeta);
  const Eigen::Vector3d t_hi = scaled_theta(rp, p_hi, wn, zeta);
  const Eigen::Vector3d d = rp.a() * (t_hi - t_lo);
  const Eigen::Vector3d r0 = rp.a() * t_lo - rp.b();
  const double dd = d.squaredNorm();
  double mu = dd > 0.0 ? std::clamp(-r0.dot(d) / dd, 0.0, 1.0) : 0.0;
  // theta1 is affine in lambda = wn / (wn + 2 zeta p) along the segment.
  const double l_lo = wn / (wn + 2.0 * zeta * p_lo), l_hi = wn / (wn + 2.0 * zeta * p_hi);
  const double lambda = l_lo + mu * (l_hi - l_lo);
  double u = u_lo;
  if (mu >= 1.0) {
    u = u_hi;
  } else if (mu > 0.0) {
    const double p = std::clamp(wn * (1.0 / lambda - 1.0) / (2.0 * zeta), p_lo, p_hi);
    u = std::clamp(std::log(p), u_lo, u_hi);
  }
  return {u, excess_at(rp, {dom.p(u), wn, zeta})};
}

Eigen::Vector3d gradient_x(const ReducedProblem& rp, const Eigen::Vector3d& phys) {
  const Eigen::Vector3d t = scaled_theta(rp, phys(0), phys(1), phys(2));
  const Eigen::Vector3d w = rp.a().transpose() * (rp.a() * t - rp.b());
  const Eigen::Matrix3d j = rp.theta1_scale().asDiagonal() * theta1_log_jacobian(phys(0), phys(1), phys(2));
  return j.transpose() * w;
}

/// Projected Newton (finite-difference Hessian of the analytic gradient) on the box.
Eigen::Vector3d polish(const ReducedProblem& rp, const Domain& dom, Eigen::Vector3d x, double& gx) {
  const double floor_value = gx + 0.5 * rp.c() * rp.c();
  for (int iteration = 0; iteration < 60; ++iteration) {
    const Eigen::Vector3d phys = dom.physical(x);
    const Eigen::Vector3d grad = gradient_x(rp, phys);
    std::array<bool, 3> free{};
    int free_count = 0;
    for (std::size_t j = 0; j < 3; ++j) {
      const int jj = static_cast<int>(j);
      const bool at_lo = x(jj) <= dom.box.lo[j], at_hi = x(jj) >= dom.box.hi[j];
      free[j] = dom.box.lo[j] < dom.box.hi[j] && !((at_lo && grad(jj) > 0.0) || (at_hi && grad(jj) < 0.0));
      free_count += free[j] ? 1 : 0;
    }
    if (free_count == 0) break;
    Eigen::Matrix3d h;
    for (int j = 0; j < 3; ++j) {
      const double step = j == 2 ? std::min(1e-5, 0.5 * x(2)) : 1e-5;
      Eigen::Vector3d xp = x, xm = x;
      xp(j) += step;
      xm(j) -= step;
      const Eigen::Vector3d pp{std::exp(xp(0)), std::exp(xp(1)), xp(2)};
      const Eigen::Vector3d pm{std::exp(xm(0)), std::exp(xm(1)), xm(2)};
      h.col(j) = (gradient_x(rp, pp) - gradient_x(rp, pm)) / (2.0 * step);
    }
    h = 0.5 * (h + h.transpose()).eval();
    Eigen::Matrix3d hf = Eigen::Matrix3d::Identity();
    Eigen::Vector3d gf = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (!free[static_cast<std::size_t>(i)]) continue;
      gf(i) = grad(i);
      for (int j = 0; j < 3; ++j) {
        if (free[static_cast<std::size_t>(j)]) hf(i, j) = h(i, j);
      }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(hf);
    const double top = std::max(eig.eigenvalues().cwiseAbs().maxCoeff(), kTiny);
    Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(1e-10 * top);
    const Eigen::Vector3d dir =
        -eig.eigenvectors() * (eig.eigenvectors().transpose() * gf).cwiseQuotient(lambda);
    const double predicted = -0.5 * gf.dot(dir);
    if (!(predicted > 1e-17 * floor_value)) break;
    double alpha = 1.0;
    bool accepted = false;
    for (int k = 0; k < 50; ++k, alpha *= 0.5) {
      const Eigen::Vector3d xn = dom.clamp(x + alpha * dir);
      const double gn = excess_at(rp, dom.physical(xn));
      if (gn <= gx + 1e-4 * grad.dot(xn - x)) {
        if (gn < gx) {
          x = xn;
          gx = gn;
          accepted = true;
        }
        break;
      }
    }
    if (!accepted) break;
  }
  return x;
}

struct Node {
  SearchBox box;
  double lower;
  int split;
};
struct NodeOrder {
  bool operator()(const Node& a, const Node& b) const noexcept { return a.lower > b.lower; }
};

std::string format_g(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

ExactResult exact_search(const ReducedProblem& rp, const Bounds& bounds, const SolveOptions& options) {
  const Domain dom(bounds);
  const double half_c2 = 0.5 * rp.c() * rp.c();
  // f = 1/2 ||r||^2 is resolved to about eps ||y|| ||r|| (the residual's rounding error is
  // eps ||y||): differences below 1e-14 ||y|| ||r|| are not asked for.
  auto tolerance = [&](double g_best) {
    const double floor_tolerance = 1e-14 * std::sqrt(2.0 * (g_best + half_c2));
    return std::max(options.abs_tolerance / rp.y_norm_squared(), floor_tolerance) +
           options.rel_tolerance * (g_best + half_c2);
  };

  Eigen::Vector3d best_x(dom.box.lo[0], dom.box.lo[1], dom.box.lo[2]);
  double best_g = excess_at(rp, dom.physical(best_x));
  auto consider = [&](const Eigen::Vector3d& x, double g) {
    if (g < best_g) {
      best_g = g;
      best_x = x;
    }
  };

  // Starting points: exact minimization along p on a grid of (ln wn, zeta), then polishing.
  {
    const int nv = dom.box.hi[1] > dom.box.lo[1] ? 16 : 1;
    const int nz = dom.box.hi[2] > dom.box.lo[2] ? 6 : 1;
    std::vector<std::pair<double, Eigen::Vector3d>> starts;
    for (int i = 0; i < nv; ++i) {
      for (int k = 0; k < nz; ++k) {
        const double v = nv == 1 ? dom.box.lo[1] : dom.box.lo[1] + (dom.box.hi[1] - dom.box.lo[1]) * (i + 0.5) / nv;
        const double z = nz == 1 ? dom.box.lo[2] : dom.box.lo[2] + (dom.box.hi[2] - dom.box.lo[2]) * (k + 0.5) / nz;
        const LinePoint lp = line_minimum(rp, dom, dom.box.lo[0], dom.box.hi[0], dom.wn(v), z);
        starts.emplace_back(lp.g, Eigen::Vector3d(lp.u, v, z));
      }
    }
    std::sort(starts.begin(), starts.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
    for (std::size_t i = 0; i < std::min<std::size_t>(3, starts.size()); ++i) {
      double g = starts[i].first;
      const Eigen::Vector3d x = polish(rp, dom, starts[i].second, g);
      consider(x, g);
    }
  }

  ExactResult result;
  std::priority_queue<Node, std::vector<Node>, NodeOrder> open;
  double closed_min = kInf;
  int polishes = 0;
  std::uint64_t boxes = 0;

  // Bounds a box (after the monotonicity test) and improves the incumbent from its centre.
  struct Child {
    SearchBox box;
    double lower;
    int split;
    bool discarded;
  };
  auto evaluate = [&](SearchBox box, double parent_lower) -> Child {
    ++boxes;
    const Child discarded{box, kInf, -1, true};
    // Monotonicity. Along p and along zeta the image of a line is a segment on which g is convex,
    // so the sign of dg/dx_j on the face x_j = lo (or hi) holds across the box: enclosing the
    // derivative on that face suffices (a much tighter enclosure than over the box). Along wn the
    // derivative is enclosed over the box. Strict signs only: a minimizer then cannot lie in the
    // closed box unless the box touches the bound g decreases towards, and then it lies on that face.
    // +1: g increases along x_j throughout the box; the box collapses to its lower face if that is
    // on the bound, else it is discarded (-1 likewise towards the upper face).
    auto apply = [&](std::size_t j, int direction) {
      if (direction > 0) {
        if (box.lo[j] > dom.box.lo[j]) return false;
        box.hi[j] = box.lo[j];
      } else if (direction < 0) {
        if (box.hi[j] < dom.box.hi[j]) return false;
        box.lo[j] = box.hi[j];
      }
      return true;
    };
    for (const std::size_t j : {std::size_t{0}, std::size_t{2}}) {
      if (!(box.lo[j] < box.hi[j])) continue;
      const int column = static_cast<int>(j);
      SearchBox face = box;
      face.hi[j] = box.lo[j];
      int direction = gradient_enclosure(rp, face, column)[j].lo > 0.0 ? 1 : 0;
      if (direction == 0) {
        face = box;
        face.lo[j] = box.hi[j];
        direction = gradient_enclosure(rp, face, column)[j].hi < 0.0 ? -1 : 0;
      }
      if (!apply(j, direction)) return discarded;
    }
    BoxBound bound = bound_box(rp, box);
    if (box.lo[1] < box.hi[1]) {
      const Interval d = bound.gradient[1];
      const int direction = d.lo > 0.0 ? 1 : (d.hi < 0.0 ? -1 : 0);
      if (!apply(1, direction)) return discarded;
      if (direction != 0) bound = bound_box(rp, box);
    }
    const double lower = std::max(parent_lower, bound.lower);
    // Upper bound from the centre, minimized exactly along p.
    const double v = 0.5 * (box.lo[1] + box.hi[1]), z = 0.5 * (box.lo[2] + box.hi[2]);
    const LinePoint lp = line_minimum(rp, dom, box.lo[0], box.hi[0], dom.wn(v), z);
    if (lp.g < best_g - tolerance(best_g) && polishes < 64) {
      ++polishes;
      double g = lp.g;
      const Eigen::Vector3d x = polish(rp, dom, Eigen::Vector3d(lp.u, v, z), g);
      consider(x, g);
    }
    consider(Eigen::Vector3d(lp.u, v, z), lp.g);
    return {box, lower, bound.split, false};
  };
  auto commit = [&](const Child& c) {
    if (c.discarded) return;
    if (c.lower >= best_g - tolerance(best_g) || c.split < 0) {
      closed_min = std::min(closed_min, c.lower);
      return;
    }
    open.push({c.box, c.lower, c.split});
  };
  auto halves = [](const SearchBox& box, std::size_t j) {
    const double middle = 0.5 * (box.lo[j] + box.hi[j]);
    std::pair<SearchBox, SearchBox> h{box, box};
    h.first.hi[j] = middle;
    h.second.lo[j] = middle;
    return h;
  };

  commit(evaluate(dom.box, 0.0));
  bool exhausted = false;
  while (!open.empty()) {
    const Node node = open.top();
    if (node.lower >= best_g - tolerance(best_g)) break;
    if (boxes >= options.max_boxes) {
      exhausted = true;
      break;
    }
    open.pop();
    const auto [l, r] = halves(node.box, static_cast<std::size_t>(node.split));
    const std::pair<Child, Child> chosen{evaluate(l, node.lower), evaluate(r, node.lower)};
    commit(chosen.first);
    commit(chosen.second);
  }

  double g = best_g;
  best_x = polish(rp, dom, best_x, g);
  // Newton steps stall in valleys that are flat along p (nearly collinear regressors, a pole
  // nearly cancelled by a zero); the exact minimum along the whole p range moves the point to
  // where the Kuhn-Tucker conditions hold, typically onto a bound of p.
  for (int round = 0; round < 4; ++round) {
    const double wn = dom.wn(best_x(1));
    const LinePoint lp = line_minimum(rp, dom, dom.box.lo[0], dom.box.hi[0], wn, best_x(2));
    if (!(lp.g < g)) break;
    g = lp.g;
    best_x(0) = lp.u;
    best_x = polish(rp, dom, best_x, g);
  }
  best_g = g;
  double lower = closed_min;
  if (!open.empty()) lower = std::min(lower, open.top().lower);
  lower = std::min(lower, best_g);
  const Eigen::Vector3d phys = dom.physical(best_x);
  result.p = phys(0);
  result.wn = phys(1);
  result.zeta = phys(2);
  result.excess = best_g;
  result.lower_excess = lower;
  result.boxes = boxes;
  result.certified = !exhausted && best_g - lower <= tolerance(best_g);
  if (exhausted) {
    const double gap = (best_g - lower) * rp.y_norm_squared();
    result.warnings.push_back("exact: stopped after " + std::to_string(boxes) + " boxes (SolveOptions::max_boxes); certified gap " +
                              format_g(gap) + " (" + format_g(gap / ((best_g + half_c2) * rp.y_norm_squared())) +
                              " relative) exceeds the tolerance");
  }
  return result;
}

}  // namespace servotwin::rapid::detail
