#include "servotwin/machine/rigid_axis.hpp"

#include <algorithm>
#include <cmath>

namespace servotwin::machine {

double RigidAxisDynamics::phi1(double a, double t) noexcept {
  const double y = a * t;
  return y == 0.0 ? t : -std::expm1(-y) / a;
}

double RigidAxisDynamics::phi2(double a, double t) noexcept {
  const double y = a * t;
  if (std::abs(y) < 0.5) {
    // sum_{n>=0} (-y)^n / (n+2)!: the closed form below cancels catastrophically for small a t.
    // 18 terms: 0.5^18 / 20! < 1e-23, far below the rounding of the leading term.
    double term = 0.5;  // 1/2!
    double sum = term;
    for (int n = 1; n < 18; ++n) {
      term *= -y / static_cast<double>(n + 2);
      sum += term;
    }
    return sum * t * t;
  }
  return (y + std::expm1(-y)) / (a * a);
}

double RigidAxisDynamics::time_to_stop(double a, double v0, double f) noexcept {
  // v(t) = v0 e^{-a t} + f (1 - e^{-a t}) / a = 0  =>  t = log1p(a v0 / -f) / a.
  const double ratio = v0 / -f;  // > 0: the time to stop without damping
  const double z = a * ratio;
  return z == 0.0 ? ratio : ratio * (std::log1p(z) / z);
}

RigidAxisDynamics::RigidAxisDynamics(const RigidPlant& plant, const Friction& friction, bool friction_enabled,
                                     double ts)
    : a_(plant.damping / plant.inertia),
      k_over_j_(plant.gain / plant.inertia),
      gain_(plant.gain),
      ts_(ts),
      e_(std::exp(-a_ * ts)),
      p1_(phi1(a_, ts)),
      p2_(phi2(a_, ts)),
      friction_(friction_enabled),
      fpos_(friction.coulomb_pos / plant.inertia),
      fneg_(friction.coulomb_neg / plant.inertia),
      static_pos_(friction.static_pos.value_or(friction.coulomb_pos)),
      static_neg_(friction.static_neg.value_or(friction.coulomb_neg)) {}

void RigidAxisDynamics::reset(double position, double velocity) noexcept {
  x_ = position;
  v_ = velocity;
  dir_ = velocity > 0.0 ? 1 : (velocity < 0.0 ? -1 : 0);
}

bool RigidAxisDynamics::break_away(double force) noexcept {
  if (force > static_pos_) {
    dir_ = 1;
  } else if (force < static_neg_) {
    dir_ = -1;
  } else {
    dir_ = 0;
  }
  return dir_ != 0;
}

RigidAxisDynamics::Step RigidAxisDynamics::step(double u) noexcept {
  Step result;
  if (!friction_) {
    const double f = k_over_j_ * u;
    const double x0 = x_;
    const double v0 = v_;
    x_ += p1_ * v0 + p2_ * f;
    v_ = e_ * v0 + p1_ * f;
    if ((v0 > 0.0 && v_ < 0.0) || (v0 < 0.0 && v_ > 0.0)) {
      const double tc = std::min(time_to_stop(a_, v0, f), ts_);
      result.turned = true;
      result.turn_position = x0 + phi1(a_, tc) * v0 + phi2(a_, tc) * f;
    }
    dir_ = v_ > 0.0 ? 1 : (v_ < 0.0 ? -1 : 0);
    return result;
  }

  const double force = gain_ * u;
  if (dir_ == 0 && !break_away(force)) return result;  // stuck for the whole sample

  double f = k_over_j_ * u - (dir_ > 0 ? fpos_ : fneg_);
  const double v_end = e_ * v_ + p1_ * f;
  if (static_cast<double>(dir_) * v_end > 0.0) {
    x_ += p1_ * v_ + p2_ * f;
    v_ = v_end;
    return result;
  }

  // The velocity reaches zero inside the sample (it is monotone there, so only once): move to
  // the stop, then apply the stiction test with the same u for the rest of the sample.
  const double tc = std::min(time_to_stop(a_, v_, f), ts_);
  x_ += phi1(a_, tc) * v_ + phi2(a_, tc) * f;
  v_ = 0.0;
  dir_ = 0;
  result.turned = true;
  result.turn_position = x_;
  const double remaining = ts_ - tc;
  if (remaining <= 0.0 || !break_away(force)) return result;
  // Breaking away after a stop is always against the previous motion (the decelerating force
  // exceeded the stiction level on the other side), so no second stop can follow.
  f = k_over_j_ * u - (dir_ > 0 ? fpos_ : fneg_);
  x_ += phi2(a_, remaining) * f;
  v_ = phi1(a_, remaining) * f;
  return result;
}

}  // namespace servotwin::machine
