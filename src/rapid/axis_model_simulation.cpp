// Time simulation of Eq. 3.3 with Coulomb friction switching on the model's own velocity.
//
// Between samples k and k+1 the inputs are held at their values at the middle of the sample
// (the mean of the sample values at k and k+1 of x_r and its central differences). A hold at the
// start of the sample would delay the command by half a sample, i.e. add v ts/2 of spurious
// tracking error (100 um at 200 mm/s and 1 kHz, more than the error itself); the midpoint hold
// is second-order accurate like a first-order hold and keeps the exact per-mode integration.
// So in each friction mode the state z = (x, x', e_i)
// follows the linear system z' = A z + b with constant b. A whole sample is one step with the
// precomputed zero-order-hold matrices, taken whenever the velocity provably keeps its sign through
// the sample: by the end-point tangents on models slower than the sampling, and for any model by
// the modal bound of velocity_sign_bound.hpp (issue 26: a model faster than the sampling used to
// take the series below on every sample, 1-3 M samples/s). Otherwise the sample is redone on
// the exact solution written as the power series of the sub-step's matrix exponential,
// exp(M s) [z0; 1] = sum_k s^k/k! M^k [z0; 1], in scaled coordinates
//   xi = (x, x' T, e_i / T),  sigma = t / T  (T = ts),
// where M has entries of order (omega T), so 20 terms reach double precision on a piece of
// length 1/||M||. The velocity is then a polynomial in sigma: the first zero crossing is found by
// a scan (with a check of interior minima) and refined by safeguarded Newton/bisection, all
// without allocation.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "velocity_sign_bound.hpp"

namespace servotwin::rapid {

namespace {

constexpr int kTerms = 21;  // series degree 20: truncation below 1/21! ~ 2e-20 on a piece
constexpr int kScanPoints = 4;
constexpr double kEps = std::numeric_limits<double>::epsilon();
// Velocities within this many rounding units of zero count as zero (see velocity_tolerance).
constexpr double kRoundingUnits = 64.0;

enum class Mode { Minus = -1, Stuck = 0, Plus = 1 };

int sign_of(Mode m) { return static_cast<int>(m); }

struct State {
  double x = 0.0, v = 0.0, ei = 0.0;
  Mode mode = Mode::Stuck;
  int last_direction = 0;  // +-1 of the last motion, 0 before the first
};

// Series coefficients of xi(sigma) = sum_k c[.][k] sigma^k over one piece.
struct Series {
  std::array<double, kTerms> x{}, v{}, e{};

  [[nodiscard]] double velocity(double s) const {
    double r = v[kTerms - 1];
    for (int k = kTerms - 2; k >= 0; --k) r = r * s + v[static_cast<std::size_t>(k)];
    return r;
  }
  // The velocity and its derivative in one Horner pass (the scan and Newton need both).
  void velocity_and_slope(double s, double& value, double& slope) const {
    double r = v[kTerms - 1], d = 0.0;
    for (int k = kTerms - 2; k >= 0; --k) {
      d = d * s + r;
      r = r * s + v[static_cast<std::size_t>(k)];
    }
    value = r;
    slope = d;
  }
  // The velocity's derivative and second derivative in one Horner pass (locating its minimum).
  void acceleration_and_jerk(double s, double& value, double& slope) const {
    double r = static_cast<double>(kTerms - 1) * v[kTerms - 1], d = 0.0;
    for (int k = kTerms - 2; k >= 1; --k) {
      d = d * s + r;
      r = r * s + static_cast<double>(k) * v[static_cast<std::size_t>(k)];
    }
    value = r;
    slope = d;
  }
  [[nodiscard]] static double horner(const std::array<double, kTerms>& c, double s) {
    double r = c[kTerms - 1];
    for (int k = kTerms - 2; k >= 0; --k) r = r * s + c[static_cast<std::size_t>(k)];
    return r;
  }
};

// ||M|| = |a2| ts^2 + |a1| ts + |a3| ts^3: how fast the model is against its sampling (the series
// piece is 1/||M|| long, the tangent test needs ||M|| <= 1).
double speed_against_sampling(const ModelCoefficients& c, double ts) {
  return std::abs(c.a2) * ts * ts + std::abs(c.a1) * ts + std::abs(c.a3) * ts * ts * ts;
}

// Everything one simulation needs, derived from the model once per call.
class Integrator {
 public:
  Integrator(const ModelCoefficients& c, double ts, const AxisModel::Kernel& kernel, bool every_sample)
      : c_(c), t_(ts), k_(kernel), bound_(c.a1, c.a2, c.a3, ts), every_sample_(every_sample) {
    a21_ = c.a2 * ts * ts;
    a11_ = c.a1 * ts;
    a31_ = c.a3 * ts * ts * ts;
    const double norm = std::max(1.0, speed_against_sampling(c, ts));
    piece_ = 1.0 / norm;  // ||M|| * piece <= 1
    friction_max_ = std::max(std::abs(c.d0), std::abs(c.d1));
  }

  // Linear model with the constant friction input f (also the d0 == d1 case): one ZOH step.
  void step_linear(State& s, double xr, double drive) const {
    const double x = s.x, v = s.v, e = s.ei;
    s.x = k_.phi[0][0] * x + k_.phi[0][1] * v + k_.phi[0][2] * e + k_.gamma_w[0] * drive + k_.gamma_r[0] * xr;
    s.v = k_.phi[1][0] * x + k_.phi[1][1] * v + k_.phi[1][2] * e + k_.gamma_w[1] * drive + k_.gamma_r[1] * xr;
    s.ei = k_.phi[2][0] * x + k_.phi[2][1] * v + k_.phi[2][2] * e + k_.gamma_w[2] * drive + k_.gamma_r[2] * xr;
  }

  // One sample with friction switching.
  void step(State& s, double xr, double w, SimulationEvents& events) const {
    if (s.mode != Mode::Stuck && s.v != 0.0 && !every_sample_) {
      State next = s;
      const double drive = w - friction(s.mode);
      step_linear(next, xr, drive);
      // The tangent test bounds the velocity by its end-point tangents, which is only sound when
      // the velocity is close to a parabola within the sample (||M|| <= 1); the modal bound holds
      // for any model, faster than the sample rate too (velocity_sign_bound.hpp).
      if ((piece_ >= 1.0 && !crossing_possible(s, next, drive)) || keeps_sign(s, xr, drive)) {
        s = next;
        return;
      }
    }
    step_with_events(s, xr, w, events);
  }

 private:
  [[nodiscard]] double friction(Mode m) const { return m == Mode::Plus ? c_.d0 : c_.d1; }

  // Certified sign of the velocity over the whole sample from the state at its start.
  [[nodiscard]] bool keeps_sign(const State& s, double xr, double drive) const {
    if (!bound_.usable()) return false;
    const double acceleration = -c_.a2 * s.x - c_.a1 * s.v + c_.a3 * s.ei + drive;
    const double jerk = -c_.a2 * s.v - c_.a1 * acceleration + c_.a3 * (xr - s.x);
    return bound_.keeps_sign(sign_of(s.mode), s.v, acceleration * t_, jerk * t_ * t_);
  }
  [[nodiscard]] double net_drive(const State& s, double w) const { return -c_.a2 * s.x + c_.a3 * s.ei + w; }

  // Rounding level of a velocity computed from this state [length/s]: the accelerations that
  // cancel in x'' times T, plus the velocity itself.
  [[nodiscard]] double velocity_tolerance(const State& s, double w) const {
    return kRoundingUnits * kEps *
           (t_ * (std::abs(c_.a2 * s.x) + std::abs(c_.a1 * s.v) + std::abs(c_.a3 * s.ei) + std::abs(w) + friction_max_) +
            std::abs(s.v));
  }

  // After a plain step in a moving mode: may the velocity have reached zero inside the sample?
  // Written so that NaN states (a diverged unstable model) never take the event path.
  [[nodiscard]] bool crossing_possible(const State& s0, const State& s1, double drive) const {
    const double dir = sign_of(s0.mode);
    const double tol = velocity_tolerance(s1, drive);
    const double p0 = dir * s0.v, p1 = dir * s1.v;
    if (p1 < -tol) return true;
    // An interior minimum of dir * v (decelerating at the start, accelerating at the end) could
    // dip below zero and come back. For a convex velocity the tangents at both ends bound the
    // minimum from below; only if that bound is negative is the sample examined exactly.
    const double a0 = dir * (-c_.a2 * s0.x - c_.a1 * s0.v + c_.a3 * s0.ei + drive) * t_;
    const double a1 = dir * (-c_.a2 * s1.x - c_.a1 * s1.v + c_.a3 * s1.ei + drive) * t_;
    if (!(a0 < 0.0 && a1 > 0.0)) return false;
    const double sigma = std::clamp((p1 - a1 - p0) / (a0 - a1), 0.0, 1.0);
    return p0 + a0 * sigma < 0.0;
  }

  // Decision at rest (x' = 0) from the net drive g: Karnopp's stick band [d1, d0]; with an
  // inverted band (d0 < d1) both directions may be consistent and the larger acceleration wins.
  [[nodiscard]] Mode decide(double g) const {
    const bool up = g > c_.d0, down = g < c_.d1;
    if (up && down) return g >= 0.5 * (c_.d0 + c_.d1) ? Mode::Plus : Mode::Minus;
    if (up) return Mode::Plus;
    if (down) return Mode::Minus;
    return Mode::Stuck;
  }

  static void enter_motion(State& s, Mode m, SimulationEvents& events) {
    const int dir = sign_of(m);
    if (s.mode == Mode::Stuck) ++events.breakaways;
    if (s.last_direction != 0 && s.last_direction != dir) ++events.reversals;
    s.last_direction = dir;
    s.mode = m;
  }

  void build(Series& out, const State& s, double xr, double drive) const {
    // xi0 and the first derivative M [xi0; 1]; then c_k = M c_(k-1) / k (the input column only
    // acts on the constant 1, i.e. in c_1).
    double x = s.x, v = s.v * t_, e = s.ei / t_;
    out.x[0] = x;
    out.v[0] = v;
    out.e[0] = e;
    double nx = v, nv = -a21_ * x - a11_ * v + a31_ * e + drive * t_ * t_, ne = xr - x;
    out.x[1] = nx;
    out.v[1] = nv;
    out.e[1] = ne;
    for (std::size_t k = 2; k < static_cast<std::size_t>(kTerms); ++k) {
      const double inv = 1.0 / static_cast<double>(k);
      x = nx;
      v = nv;
      e = ne;
      nx = v * inv;
      nv = (-a21_ * x - a11_ * v + a31_ * e) * inv;
      ne = -x * inv;
      out.x[k] = nx;
      out.v[k] = nv;
      out.e[k] = ne;
    }
  }

  void evaluate(const Series& series, double sigma, State& s) const {
    s.x = Series::horner(series.x, sigma);
    s.v = Series::horner(series.v, sigma) / t_;
    s.ei = Series::horner(series.e, sigma) * t_;
  }

  // Root of a function h in [lo, hi] with h(lo) >= 0 > h(hi), h_and_slope(x, h, h') evaluating
  // it: Newton kept inside the bracket, bisecting whenever its step would leave the bracket or
  // does not at least halve the step before it (Press et al., Numerical Recipes, rtsafe). A
  // bracket-width rule bisected after most Newton steps (one side moves at a time) and took ~50
  // Horner passes where this takes ~5.
  template <typename F>
  static double safeguarded_root(F&& h_and_slope, double lo, double hi) {
    double x = 0.5 * (lo + hi);
    double step_before = hi - lo, step = step_before;
    double h = 0.0, dh = 0.0;
    h_and_slope(x, h, dh);
    for (int it = 0; it < 100; ++it) {
      (h >= 0.0 ? lo : hi) = x;
      const double newton = dh != 0.0 ? x - h / dh : lo;
      if (!(newton > lo && newton < hi) || std::abs(2.0 * h) > std::abs(step_before * dh)) {
        step_before = step;
        step = 0.5 * (hi - lo);
        x = lo + step;
      } else {
        step_before = step;
        step = x - newton;
        x = newton;
      }
      if (std::abs(step) <= 2.0 * kEps * hi || hi - lo <= 4.0 * kEps * hi) break;
      h_and_slope(x, h, dh);
    }
    return std::clamp(x, lo, hi);
  }

  // Root of dir * v(sigma) + tol in [lo, hi], positive at lo and negative at hi.
  static double refine(const Series& series, double dir, double tol, double lo, double hi) {
    return safeguarded_root(
        [&](double x, double& h, double& dh) {
          series.velocity_and_slope(x, h, dh);
          h = dir * h + tol;
          dh *= dir;
        },
        lo, hi);
  }

  // The minimum of dir * v in [lo, hi], where its slope goes from - to +: the root of -dir * v'.
  static double minimum(const Series& series, double dir, double lo, double hi) {
    return safeguarded_root(
        [&](double x, double& h, double& dh) {
          series.acceleration_and_jerk(x, h, dh);
          h *= -dir;
          dh *= -dir;
        },
        lo, hi);
  }

  // First sigma in (0, length] where dir * v < -tol, or NaN when there is none. The polynomial
  // is sampled at kScanPoints points; between two samples that are both non-negative an interior
  // minimum (slope from - to +) is located and checked as well.
  static double first_crossing(const Series& series, double length, double dir, double tol) {
    double s_prev = 0.0;
    if (dir * series.v[0] + tol < 0.0) return 0.0;
    double slope_prev = dir * series.v[1];
    for (int j = 1; j <= kScanPoints; ++j) {
      const double s = length * static_cast<double>(j) / kScanPoints;
      double value = 0.0, derivative = 0.0;
      series.velocity_and_slope(s, value, derivative);
      const double h = dir * value + tol;
      if (h < 0.0) return refine(series, dir, tol, s_prev, s);
      const double slope = dir * derivative;
      if (slope_prev < 0.0 && slope > 0.0) {
        const double s_min = minimum(series, dir, s_prev, s);
        if (dir * series.velocity(s_min) + tol < 0.0) return refine(series, dir, tol, s_prev, s_min);
      }
      s_prev = s;
      slope_prev = slope;
    }
    return std::numeric_limits<double>::quiet_NaN();
  }

  // Moves the state up to `length` (sigma units) in its moving mode; stops at the first velocity
  // zero (v set to exactly 0) and returns the time used, or returns `length` when there is none.
  double advance_moving(State& s, double xr, double w, double length, bool detect) const {
    const double dir = sign_of(s.mode);
    const double drive = w - friction(s.mode);
    double done = 0.0;
    Series series;
    while (done < length) {
      const double piece = std::min(length - done, piece_);
      build(series, s, xr, drive);
      if (detect) {
        const double tol = velocity_tolerance(s, drive) * t_;  // in scaled units (x' T)
        const double hit = first_crossing(series, piece, dir, tol);
        if (!std::isnan(hit)) {
          evaluate(series, hit, s);
          s.v = 0.0;
          return done + hit;
        }
      }
      evaluate(series, piece, s);
      done += piece;
    }
    return length;
  }

  void step_with_events(State& s, double xr, double w, SimulationEvents& events) const {
    double remaining = 1.0;
    bool at_rest = s.v == 0.0;  // decide the mode before moving
    // Every pass that does not return locates one event (a breakaway or a zero crossing).
    for (int located = 0; remaining > 0.0; ++located) {
      if (located >= AxisModel::kMaxEventsPerSample) {
        ++events.event_limit_hits;
        if (s.mode == Mode::Stuck) s.ei += (xr - s.x) * t_ * remaining;
        else advance_moving(s, xr, w, remaining, false);
        return;
      }
      if (at_rest) {
        at_rest = false;
        const Mode m = decide(net_drive(s, w));
        if (m == Mode::Stuck) {
          if (s.mode != Mode::Stuck) ++events.sticks;
          s.mode = Mode::Stuck;
        } else {
          enter_motion(s, m, events);
        }
      }
      if (s.mode == Mode::Stuck) {
        // x and x' = 0 are held; e_i grows linearly, so g = -a2 x + a3 e_i + w is linear in time
        // and leaves the band [d1, d0] at a computable instant.
        const double g = net_drive(s, w);
        const double rate = c_.a3 * (xr - s.x) * t_;  // dg/dsigma
        double until = std::numeric_limits<double>::infinity();
        if (rate > 0.0) until = (c_.d0 - g) / rate;
        else if (rate < 0.0) until = (c_.d1 - g) / rate;
        if (!(until < remaining)) {
          s.ei += (xr - s.x) * t_ * remaining;
          return;
        }
        until = std::max(until, 0.0);
        s.ei += (xr - s.x) * t_ * until;
        remaining -= until;
        enter_motion(s, rate > 0.0 ? Mode::Plus : Mode::Minus, events);
        continue;
      }
      const double used = advance_moving(s, xr, w, remaining, true);
      if (used >= remaining) return;
      remaining -= used;
      at_rest = true;
    }
  }

  // Copies, not references: the compiler may keep them in registers across the output stores.
  ModelCoefficients c_;
  double t_;
  AxisModel::Kernel k_;
  detail::VelocitySignBound bound_;
  bool every_sample_ = false;
  double a21_ = 0.0, a11_ = 0.0, a31_ = 0.0;  // a2 T^2, a1 T, a3 T^3
  double piece_ = 1.0;
  double friction_max_ = 0.0;
};

// The event search integrates a sample in series pieces of length 1/||M|| (||M|| = a2 ts^2 +
// a1 ts + a3 ts^3, the model's speed against the sampling): a model a million times faster than
// its sampling would need a million pieces for every sample with a friction event (issue 26: a
// fit scaled by 1e6 ran for minutes on a 1.3 s program). Such a model is refused; kMaxPieces
// keeps an event sample under a few milliseconds.
constexpr double kMaxPieces = 4096.0;

void require_bounded_event_search(const ModelCoefficients& c, double ts) {
  const double speed = speed_against_sampling(c, ts);
  if (!(speed <= kMaxPieces)) {
    throw core::InputError(core::at_field("a1"),
                           "the model's dynamics are " + std::to_string(static_cast<long long>(std::min(speed, 1e18))) +
                               " times faster than its sample period (a2 ts^2 + a1 ts + a3 ts^3; at most " +
                               std::to_string(static_cast<int>(kMaxPieces)) +
                               " can be simulated with friction): poles this far beyond Nyquist cannot come from "
                               "data sampled at this rate; check the coefficients' units and the sample period");
  }
}

void require_simulable(std::span<const double> command, const ModelSimulationOptions& options,
                       const ModelCoefficients& c, double ts, const AxisModel::Kernel& kernel) {
  for (std::size_t k = 0; k < command.size(); ++k) {
    if (!std::isfinite(command[k]))
      throw core::InputError(core::at_field("command[" + std::to_string(k) + "]"), "command sample must be finite");
  }
  if (options.initial_position && !std::isfinite(*options.initial_position))
    throw core::InputError(core::at_field("initial_position"), "must be finite");
  if (options.initial_integrator && !std::isfinite(*options.initial_integrator))
    throw core::InputError(core::at_field("initial_integrator"), "must be finite");
  if (!kernel.valid) {
    throw core::InputError(core::at_field("ts"), "the model grows by more than exp(700) within one sample period; "
                                        "its zero-order-hold matrices overflow");
  }
  if (c.d0 != c.d1) require_bounded_event_search(c, ts);
}

// The simulation loop shared by simulate_into and simulate_blocks: emit(k, x_k, x'_k) receives
// every output sample and returns false to stop. Returns the number of samples emitted.
template <typename Emit>
std::size_t run(std::span<const double> command, const ModelSimulationOptions& options, const ModelCoefficients& c,
                double ts, const AxisModel::Kernel& kernel, SimulationEvents& events, Emit&& emit) {
  const std::size_t n = command.size();
  if (n == 0) return 0;
  // The driving command, extended by its end values (clamped index) and shifted.
  const auto last = static_cast<std::ptrdiff_t>(n) - 1;
  const std::ptrdiff_t shift = options.command_shift;
  const auto u = [&](std::ptrdiff_t j) { return command[static_cast<std::size_t>(std::clamp(j + shift, std::ptrdiff_t{0}, last))]; };
  const double inv2t = 1.0 / (2.0 * ts);

  State s;
  // Default start: at rest under the first command (x = x_r,0, or b2/a2 x_r,0 without integrator).
  const double rest = (c.a3 == 0.0 && c.a2 != 0.0) ? c.b2 / c.a2 * u(0) : u(0);
  s.x = options.initial_position.value_or(rest);
  s.ei = options.initial_integrator.value_or(c.a3 != 0.0 ? (c.a2 * s.x - c.b2 * u(0)) / c.a3 : 0.0);
  const Integrator integrator(c, ts, kernel, options.event_search_every_sample);
  const bool switching = c.d0 != c.d1;

  // Sliding window u(k-2) .. u(k+3) of the padded, shifted command: one clamped load per sample.
  double um2 = u(-2), um1 = u(-1), u0 = u(0), up1 = u(1), up2 = u(2), up3 = u(3);
  const double inv4t2 = inv2t * inv2t;
  for (std::ptrdiff_t k = 0; k <= last; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (!emit(i, s.x, s.v)) return i + 1;
    if (k == last) break;  // the step after the last sample would produce no output
    // Central differences at k and k+1 (x_r'_j = (x_r,j+1 - x_r,j-1)/(2 ts), x_r''_j = (x_r'_j+1 -
    // x_r'_j-1)/(2 ts)), then their mean: the held values of the sample's midpoint.
    const double xr = 0.5 * (u0 + up1);
    const double xd = 0.5 * ((up1 - um1) + (up2 - u0)) * inv2t;
    const double xdd = 0.5 * ((up2 - 2.0 * u0 + um2) + (up3 - 2.0 * up1 + um1)) * inv4t2;
    const double w = c.b2 * xr + c.b1 * xd + c.b0 * xdd;
    um2 = um1;
    um1 = u0;
    u0 = up1;
    up1 = up2;
    up2 = up3;
    up3 = u(k + 4);
    if (switching) integrator.step(s, xr, w, events);
    else integrator.step_linear(s, xr, w - c.d0);
  }
  return n;
}

}  // namespace

ModelResponse AxisModel::simulate(std::span<const double> command, const ModelSimulationOptions& options) const {
  ModelResponse out;
  simulate_into(command, out, options);
  return out;
}

void AxisModel::simulate_into(std::span<const double> command, ModelResponse& out,
                              const ModelSimulationOptions& options) const {
  require_simulable(command, options, c_, ts_, kernel_);
  const std::size_t n = command.size();
  out.position.resize(n);
  out.velocity.resize(n);
  out.tracking_error.resize(n);
  out.events = SimulationEvents{};
  double* position = out.position.data();
  double* velocity = out.velocity.data();
  double* error = out.tracking_error.data();
  run(command, options, c_, ts_, kernel_, out.events, [&](std::size_t i, double x, double v) {
    position[i] = x;
    velocity[i] = v;
    error[i] = command[i] - x;
    return true;
  });
}

std::size_t AxisModel::simulate_blocks(std::span<const double> command, const ModelSimulationOptions& options,
                                       PositionSink& sink) const {
  require_simulable(command, options, c_, ts_, kernel_);
  std::array<double, kSimulationBlock> block;
  std::size_t first = 0, filled = 0;
  bool go_on = true;
  SimulationEvents events;
  const std::size_t done = run(command, options, c_, ts_, kernel_, events, [&](std::size_t, double x, double) {
    block[filled++] = x;
    if (filled < block.size()) return true;
    go_on = sink.consume(first, std::span<const double>(block.data(), filled));
    first += filled;
    filled = 0;
    return go_on;
  });
  if (go_on && filled > 0) sink.consume(first, std::span<const double>(block.data(), filled));
  return done;
}

}  // namespace servotwin::rapid
