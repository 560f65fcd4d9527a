#pragma once
/// \file
/// Exact sampled motion of the rigid axis plant J x'' + B x' = K u - F(x') under a control signal
/// held constant over each sample (zero-order hold).
///
/// The linear part uses the closed-form solution of the first-order velocity equation. Coulomb
/// friction is piecewise constant in the direction of motion, so a sample is split at the instant
/// the velocity reaches zero (closed form with log1p, exact for B -> 0); at rest the stiction
/// test decides whether the axis stays stuck (static_neg <= K u <= static_pos) or breaks away.
/// Within one sample the velocity changes sign at most once, so a step has at most two phases and
/// never chatters. Construction precomputes the per-sample constants; `step` is allocation- and
/// exception-free.

#include "servotwin/machine/axis_config.hpp"

namespace servotwin::machine {

/// Exact integrator of one rigid axis.
class RigidAxisDynamics {
 public:
  /// Result of one step: whether the velocity reached zero inside the sample and where (the
  /// turning point a play operator needs, since the motion is monotone on each side of it).
  struct Step {
    bool turned = false;
    double turn_position = 0.0;
  };

  /// `friction_enabled = false` integrates the linear plant only. Preconditions (checked by
  /// machine::validate): J > 0, K > 0, B >= 0, ts > 0, friction levels with the documented signs.
  RigidAxisDynamics(const RigidPlant& plant, const Friction& friction, bool friction_enabled, double ts);

  /// Sets position and velocity (a nonzero velocity starts the axis moving in its direction).
  void reset(double position, double velocity = 0.0) noexcept;

  /// Advances one sample with u held.
  Step step(double u) noexcept;

  [[nodiscard]] double position() const noexcept { return x_; }
  [[nodiscard]] double velocity() const noexcept { return v_; }
  /// +1 / -1 while moving, 0 while stuck (friction enabled) or at exact rest.
  [[nodiscard]] int direction() const noexcept { return dir_; }

  /// (1 - exp(-a t)) / a, continuous at a = 0 (= t).
  [[nodiscard]] static double phi1(double a, double t) noexcept;
  /// (a t - 1 + exp(-a t)) / a^2, continuous at a = 0 (= t^2 / 2); series for small a t.
  [[nodiscard]] static double phi2(double a, double t) noexcept;
  /// Time for v' = f - a v to bring v0 to zero (v0 and f of opposite signs):
  /// log1p(a v0 / -f) / a, continuous at a = 0 (= v0 / -f).
  [[nodiscard]] static double time_to_stop(double a, double v0, double f) noexcept;

 private:
  // Stiction test at rest: sets dir_ and returns false when the axis stays stuck.
  bool break_away(double force) noexcept;
  [[nodiscard]] double friction_acceleration(int dir) const noexcept { return dir > 0 ? fpos_ : fneg_; }

  double a_ = 0.0;         // B / J
  double k_over_j_ = 0.0;  // K / J
  double gain_ = 0.0;      // K
  double ts_ = 0.0;
  double e_ = 1.0, p1_ = 0.0, p2_ = 0.0;  // exp(-a ts), phi1(ts), phi2(ts)
  bool friction_ = false;
  double fpos_ = 0.0, fneg_ = 0.0;      // Coulomb levels / J
  double static_pos_ = 0.0, static_neg_ = 0.0;  // stiction force levels [N]
  double x_ = 0.0, v_ = 0.0;
  int dir_ = 0;
};

}  // namespace servotwin::machine
