// Exact rigid-axis integration with Coulomb friction and stiction, checked against a fine-step
// RK4 reference with event location and against closed forms.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "servotwin/machine/rigid_axis.hpp"

namespace servotwin::machine {
namespace {

// Fadal X-like axis: J = 0.1 N s^2/mm, B/J = 2.55 1/s, K = 100 N/V, F+ = 44.1 N, F- = -30.2 N.
RigidPlant fadal_plant() { return {0.1, 0.255, 100.0}; }
Friction fadal_friction() {
  Friction f;
  f.coulomb_pos = 44.1;
  f.coulomb_neg = -30.2;
  return f;
}

// Independent reference: RK4 on x' = v, v' = (K u - F(v) - B v)/J with `substeps` steps per
// sample. When a step would change the sign of v, the crossing instant is located by bisection
// on the RK4 step length (to 1e-15 s); at rest the stiction rule decides what happens next.
struct Rk4Reference {
  RigidPlant plant;
  Friction friction;
  double x = 0.0, v = 0.0;
  int dir = 0;

  double accel(double vel, int d, double u) const {
    const double f = d > 0 ? friction.coulomb_pos : (d < 0 ? friction.coulomb_neg : 0.0);
    return (plant.gain * u - f - plant.damping * vel) / plant.inertia;
  }
  void rk4(double& px, double& pv, int d, double u, double h) const {
    const double k1x = pv, k1v = accel(pv, d, u);
    const double k2x = pv + 0.5 * h * k1v, k2v = accel(pv + 0.5 * h * k1v, d, u);
    const double k3x = pv + 0.5 * h * k2v, k3v = accel(pv + 0.5 * h * k2v, d, u);
    const double k4x = pv + h * k3v, k4v = accel(pv + h * k3v, d, u);
    px += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    pv += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  void advance(double u, double duration, int substeps) {
    const double h = duration / substeps;
    const double force = plant.gain * u;
    const double s_pos = friction.static_pos.value_or(friction.coulomb_pos);
    const double s_neg = friction.static_neg.value_or(friction.coulomb_neg);
    for (int i = 0; i < substeps; ++i) {
      double remaining = h;
      while (remaining > 0.0) {
        if (dir == 0) {
          if (force > s_pos) {
            dir = 1;
          } else if (force < s_neg) {
            dir = -1;
          } else {
            v = 0.0;  // stuck for the rest of the substep
            remaining = 0.0;
            continue;
          }
        }
        double tx = x, tv = v;
        rk4(tx, tv, dir, u, remaining);
        if (tv * dir > 0.0) {
          x = tx;
          v = tv;
          remaining = 0.0;
          continue;
        }
        double lo = 0.0, hi = remaining;  // sign change inside: bisect on the step length
        while (hi - lo > 1e-15) {
          const double mid = 0.5 * (lo + hi);
          double mx = x, mv = v;
          rk4(mx, mv, dir, u, mid);
          (mv * dir > 0.0 ? lo : hi) = mid;
        }
        rk4(x, v, dir, u, hi);
        v = 0.0;
        dir = 0;
        remaining -= hi;
      }
    }
  }
};

TEST(RigidAxis, PhiFunctionsAreAccurateAndContinuous) {
  // Long-double references (an independent evaluation with 64-bit mantissa).
  for (double y : {1e-9, 1e-4, 0.01, 0.3, 0.4999, 0.5, 0.5001, 2.0, 30.0}) {
    const double t = 1e-3;
    const double a = y / t;
    const long double yl = y;
    const long double p1 = -std::expm1(-yl) / static_cast<long double>(a);
    const long double p2 = (yl + std::expm1(-yl)) / (static_cast<long double>(a) * a);
    EXPECT_NEAR(RigidAxisDynamics::phi1(a, t) / static_cast<double>(p1), 1.0, 1e-15) << y;
    // The long-double closed form itself loses ~log10(1/y) digits of its 19 for small y.
    const double tol = y < 1e-3 ? 1e-8 : 1e-15;
    EXPECT_NEAR(RigidAxisDynamics::phi2(a, t) / static_cast<double>(p2), 1.0, tol) << y;
  }
  EXPECT_DOUBLE_EQ(RigidAxisDynamics::phi1(0.0, 2e-3), 2e-3);
  EXPECT_DOUBLE_EQ(RigidAxisDynamics::phi2(0.0, 2e-3), 2e-6);
  // Series and closed form agree across the switch at a t = 0.5.
  const double below = RigidAxisDynamics::phi2(0.5 * (1 - 1e-12), 1.0);
  const double above = RigidAxisDynamics::phi2(0.5 * (1 + 1e-12), 1.0);
  EXPECT_NEAR(below / above, 1.0, 1e-11);
  // time_to_stop: no damping = v0/|f|; with damping the closed form log1p(a v0/|f|)/a.
  EXPECT_DOUBLE_EQ(RigidAxisDynamics::time_to_stop(0.0, 10.0, -441.0), 10.0 / 441.0);
  EXPECT_NEAR(RigidAxisDynamics::time_to_stop(2.55, 10.0, -441.0), std::log(1.0 + 2.55 * 10.0 / 441.0) / 2.55,
              1e-16);
}

TEST(RigidAxis, FrictionlessStepIsTheExactZohSolution) {
  const RigidPlant p = fadal_plant();
  RigidAxisDynamics axis(p, fadal_friction(), false, 1e-3);
  axis.reset(1.0, 20.0);
  const double a = p.damping / p.inertia, kj = p.gain / p.inertia, u = -0.7;
  double x = 1.0, v = 20.0;
  for (int k = 0; k < 500; ++k) {
    axis.step(u);
    const double t = 1e-3;
    const double e = std::exp(-a * t);
    const double xn = x + v * (1 - e) / a + kj * u * (a * t - 1 + e) / (a * a);
    v = v * e + kj * u * (1 - e) / a;
    x = xn;
  }
  EXPECT_NEAR(axis.position(), x, 1e-11);
  EXPECT_NEAR(axis.velocity(), v, 1e-11);
}

TEST(RigidAxis, FreeDecelerationMatchesFineStepReference) {
  for (double v0 : {50.0, -50.0}) {
    RigidAxisDynamics axis(fadal_plant(), fadal_friction(), true, 1e-3);
    axis.reset(0.0, v0);
    Rk4Reference ref{fadal_plant(), fadal_friction()};
    ref.v = v0;
    ref.dir = v0 > 0 ? 1 : -1;
    int turns = 0;
    for (int k = 0; k < 200; ++k) {
      turns += axis.step(0.0).turned ? 1 : 0;
      ref.advance(0.0, 1e-3, 500);  // 1e5 substeps over the 0.2 s
      ASSERT_NEAR(axis.position(), ref.x, 1e-10) << "v0 " << v0 << " sample " << k;
      ASSERT_NEAR(axis.velocity(), ref.v, 1e-9) << "v0 " << v0 << " sample " << k;
    }
    EXPECT_EQ(turns, 1);  // stops once and stays stuck (|K u| = 0 inside the stiction band)
    EXPECT_EQ(axis.direction(), 0);
    EXPECT_EQ(axis.velocity(), 0.0);
  }
}

TEST(RigidAxis, ReversalUnderConstantForceMatchesReferenceWithoutChatter) {
  Friction f = fadal_friction();
  f.static_pos = 60.0;
  f.static_neg = -45.0;
  RigidAxisDynamics axis(fadal_plant(), f, true, 1e-3);
  axis.reset(0.0, 30.0);
  Rk4Reference ref{fadal_plant(), f};
  ref.v = 30.0;
  ref.dir = 1;
  int sign_changes = 0, last_sign = 1;
  for (int k = 0; k < 100; ++k) {
    axis.step(-2.0);  // K u = -200 N: decelerate, stop, break away in -
    ref.advance(-2.0, 1e-3, 1000);
    ASSERT_NEAR(axis.position(), ref.x, 1e-10) << k;
    ASSERT_NEAR(axis.velocity(), ref.v, 1e-9) << k;
    const int sign = axis.velocity() > 0 ? 1 : (axis.velocity() < 0 ? -1 : 0);
    if (sign != 0 && sign != last_sign) {
      ++sign_changes;
      last_sign = sign;
    }
  }
  EXPECT_EQ(sign_changes, 1);
  EXPECT_LT(axis.velocity(), 0.0);
}

TEST(RigidAxis, AsymmetricStoppingDistancesMatchClosedForm) {
  const RigidPlant p = fadal_plant();
  const Friction f = fadal_friction();
  const double a = p.damping / p.inertia;
  for (double v0 : {40.0, -40.0}) {
    RigidAxisDynamics axis(p, f, true, 1e-3);
    axis.reset(0.0, v0);
    for (int k = 0; k < 300; ++k) axis.step(0.0);
    const double d = (v0 > 0 ? f.coulomb_pos : f.coulomb_neg) / p.inertia;  // friction deceleration
    // v' = -d - a v: stops at t* = ln(1 + a v0/d)/a, after x* = (v0 - d t*)/a.
    const double t_stop = std::log1p(a * v0 / d) / a;
    const double x_stop = (v0 - d * t_stop) / a;
    EXPECT_NEAR(axis.position(), x_stop, 1e-12 * std::abs(x_stop)) << v0;
  }
  // 441 vs 302 mm/s^2: the + motion stops sooner.
  RigidAxisDynamics pos(p, f, true, 1e-3), neg(p, f, true, 1e-3);
  pos.reset(0.0, 40.0);
  neg.reset(0.0, -40.0);
  for (int k = 0; k < 300; ++k) {
    pos.step(0.0);
    neg.step(0.0);
  }
  EXPECT_LT(pos.position(), -neg.position());
}

TEST(RigidAxis, NoDampingLimitIsExact) {
  // B = 0: uniform deceleration, x* = v0^2 / (2 d) exactly; B = 1e-12 J is continuous with it.
  Friction f;
  f.coulomb_pos = 50.0;
  f.coulomb_neg = -50.0;
  for (double damping : {0.0, 1e-13}) {
    RigidAxisDynamics axis({0.1, damping, 100.0}, f, true, 1e-3);
    axis.reset(0.0, 25.0);
    for (int k = 0; k < 100; ++k) axis.step(0.0);
    EXPECT_NEAR(axis.position(), 25.0 * 25.0 / (2.0 * 500.0), 1e-12) << damping;
    EXPECT_EQ(axis.velocity(), 0.0);
  }
}

TEST(RigidAxis, StictionHoldsBelowTheBreakawayForce) {
  Friction f = fadal_friction();
  f.static_pos = 60.0;
  f.static_neg = -40.0;
  const RigidPlant p = fadal_plant();
  for (double u : {0.59, 0.0, -0.39, 0.6, -0.4}) {  // K u = 59, 0, -39, 60, -40 N: all stuck
    RigidAxisDynamics axis(p, f, true, 1e-3);
    axis.reset(3.0);
    for (int k = 0; k < 1000; ++k) axis.step(u);
    EXPECT_EQ(axis.position(), 3.0) << u;
    EXPECT_EQ(axis.velocity(), 0.0) << u;
  }
  // Just above the stiction level it breaks away and then feels the Coulomb level:
  // x(t) = (K u - F) / J * phi2(t).
  for (double u : {0.61, -0.41}) {
    RigidAxisDynamics axis(p, f, true, 1e-3);
    axis.reset(3.0);
    for (int k = 0; k < 10; ++k) axis.step(u);
    const double fc = u > 0 ? f.coulomb_pos : f.coulomb_neg;
    const double expected = 3.0 + (p.gain * u - fc) / p.inertia * RigidAxisDynamics::phi2(2.55, 0.01);
    EXPECT_NEAR(axis.position(), expected, 1e-13) << u;
  }
}

TEST(RigidAxis, ReportsTheTurningPointForThePlayOperator) {
  RigidAxisDynamics axis(fadal_plant(), Friction{}, false, 1e-3);
  axis.reset(0.0, 1.0);
  // Frictionless: v' = 1000 u - 2.55 v with u = -10: stops after ~1e-4 s, within the sample.
  const RigidAxisDynamics::Step step = axis.step(-10.0);
  ASSERT_TRUE(step.turned);
  const double a = 2.55, f = -10000.0;
  const double tc = std::log1p(a * 1.0 / -f) / a;
  const double x_turn = RigidAxisDynamics::phi1(a, tc) * 1.0 + RigidAxisDynamics::phi2(a, tc) * f;
  EXPECT_NEAR(step.turn_position, x_turn, 1e-16);
  EXPECT_GT(step.turn_position, 0.0);
  EXPECT_LT(axis.position(), step.turn_position);
}

}  // namespace
}  // namespace servotwin::machine
