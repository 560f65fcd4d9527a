// Indices of a PI/PID velocity loop and the J1/J2 choice of ω* (loop_analysis.hpp; catalog C7.8,
// C7.15).
#include "servotwin/tuning/loop_analysis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/core/state_space.hpp"

namespace servotwin::tuning {
namespace {

using Complex = std::complex<double>;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Poles with less damping than this get their |Im| into the grid (narrow peaks).
constexpr double kLightDamping = 0.5;
/// Local maxima of a sampled |f| below this fraction of the sampled maximum are not refined.
constexpr double kRefineFraction = 0.5;

double level_3db() { return std::pow(10.0, -3.0 / 20.0); }

// ----------------------------------------------------------------------------- frequency grid

/// The log grid plus the extra frequencies and the |Im| of the lightly damped poles, sorted, with
/// points closer than 1e-12 relative merged (peak_on_grid needs a strictly increasing grid).
std::vector<double> analysis_grid(const AnalysisOptions& o, std::span<const Complex> poles) {
  std::vector<double> g = core::log_space(o.omega_min, o.omega_max, o.grid_points);
  const auto add = [&](double w) {
    if (std::isfinite(w) && w > o.omega_min && w < o.omega_max) g.push_back(w);
  };
  for (const double w : o.extra_frequencies) add(w);
  for (const Complex& p : poles) {
    const double m = std::abs(p);
    if (m > 0.0 && -p.real() / m < kLightDamping) add(std::abs(p.imag()));
  }
  std::sort(g.begin(), g.end());
  std::vector<double> out;
  out.reserve(g.size());
  for (const double w : g)
    if (out.empty() || w > out.back() * (1.0 + 1e-12)) out.push_back(w);
  return out;
}

/// Supremum of |f| given its samples on the grid: the local maxima within kRefineFraction of the
/// sampled maximum refined by core::peak_on_grid on their neighbours' bracket.
core::PeakResult refined_peak(const std::function<Complex(double)>& f, std::span<const double> grid,
                              std::span<const double> mags, double rel_tol) {
  const std::size_t n = grid.size();
  const auto top = std::max_element(mags.begin(), mags.end());
  core::PeakResult best{*top, grid[static_cast<std::size_t>(top - mags.begin())]};
  if (!std::isfinite(best.value)) return {kInf, best.omega_rad_s};
  for (std::size_t i = 0; i < n; ++i) {
    const bool above_left = i == 0 || mags[i] > mags[i - 1];
    const bool not_below_right = i + 1 == n || mags[i] >= mags[i + 1];
    if (!above_left || !not_below_right || mags[i] < kRefineFraction * best.value) continue;
    const std::size_t lo = i == 0 ? 0 : i - 1;
    const std::size_t hi = i + 1 == n ? i : i + 1;
    const core::PeakResult r = core::peak_on_grid(f, grid.subspan(lo, hi - lo + 1), rel_tol);
    if (r.value > best.value) best = r;
  }
  return best;
}

/// −3 dB bandwidth of f against its DC value `dc` (exact, from the rational closed loop), given
/// its samples: the first sample below the level brackets the crossing with its predecessor (or
/// with ω = 0), core::bandwidth bisects. +inf when |f| stays above the level on the grid.
double bandwidth_from_samples(const std::function<Complex(double)>& f, double dc, std::span<const double> grid,
                              std::span<const double> mags) {
  const double level = level_3db() * std::abs(dc);
  std::size_t i = 0;
  while (i < grid.size() && mags[i] >= level) ++i;
  if (i == grid.size()) return kInf;
  const std::function<Complex(double)> g = [&](double w) { return w == 0.0 ? Complex(dc, 0.0) : f(w); };
  std::array<double, 3> bracket{0.0, i == 0 ? grid[0] : grid[i - 1], grid[i]};
  const std::span<const double> sub = i == 0 ? std::span<const double>(bracket.data(), 2) : std::span<const double>(bracket);
  return core::bandwidth(g, sub).value_or(kNaN);
}

// ----------------------------------------------------------------------------- margins

/// Root of the sign change of h between lo and hi (h(lo) has sign `lo_positive`) by geometric
/// bisection to 1e-14 relative.
double bisect(const std::function<double(double)>& h, double lo, double hi) {
  const bool lo_positive = h(lo) >= 0.0;
  for (int k = 0; k < 200 && hi > lo * (1.0 + 1e-14); ++k) {
    const double mid = std::sqrt(lo * hi);
    if ((h(mid) >= 0.0) == lo_positive)
      lo = mid;
    else
      hi = mid;
  }
  return std::sqrt(lo * hi);
}

/// Phase of L + 180° wrapped to (−180°, 180°].
double phase_margin_at(Complex l) {
  double pm = std::arg(l) * 180.0 / std::numbers::pi + 180.0;
  if (pm > 180.0) pm -= 360.0;
  return pm;
}

void margins(const VelocityLoop& loop, std::span<const double> grid, std::span<const Complex> l, LoopIndices& out) {
  out.gain_margin_db = kInf;
  out.phase_crossover = kInf;
  out.phase_margin_deg = kInf;
  out.gain_crossover = kInf;
  const std::function<double(double)> gain = [&](double w) { return std::abs(loop.loop_gain(w)) - 1.0; };
  const std::function<double(double)> imag = [&](double w) { return loop.loop_gain(w).imag(); };
  for (std::size_t i = 0; i + 1 < grid.size(); ++i) {
    if ((std::norm(l[i]) >= 1.0) != (std::norm(l[i + 1]) >= 1.0)) {
      const double w = bisect(gain, grid[i], grid[i + 1]);
      const double pm = phase_margin_at(loop.loop_gain(w));
      if (std::abs(pm) < std::abs(out.phase_margin_deg)) {
        out.phase_margin_deg = pm;
        out.gain_crossover = w;
      }
    }
    if ((l[i].imag() >= 0.0) != (l[i + 1].imag() >= 0.0) && (l[i].real() < 0.0 || l[i + 1].real() < 0.0)) {
      const double w = bisect(imag, grid[i], grid[i + 1]);
      const Complex v = loop.loop_gain(w);
      if (v.real() >= 0.0 || !std::isfinite(std::abs(v))) continue;
      const double gm = -20.0 * std::log10(std::abs(v));
      if (std::abs(gm) < std::abs(out.gain_margin_db)) {
        out.gain_margin_db = gm;
        out.phase_crossover = w;
      }
    }
  }
}

// ----------------------------------------------------------------------------- frequency indices

enum Channel : std::size_t { kS, kT, kTm, kTl, kLoadDist, kLoadDistW, kOpenW, kChannels };

Complex weight(double w) { return Complex(0.0, w) / Complex(1.0, w); }

/// A velocity output as the indices judge it: itself, or its position v/(jω) when the loop is a
/// position controller's velocity form (AnalysisOptions::position_outputs).
Complex judged(Complex v, double w, bool position) { return position ? v / Complex(0.0, w) : v; }

Complex channel(const VelocityLoop& loop, Channel c, double w, bool position) {
  switch (c) {
    case kS: return loop.sensitivity(w);
    case kT: return loop.complementary(w);
    case kTm: return judged(loop.motor_tracking(w), w, position);
    case kTl: return judged(loop.load_tracking(w), w, position);
    case kLoadDist: return judged(loop.load_from_load_torque(w), w, position);
    // J2 stays C7.8's velocity ratio: the uncontrolled load position per torque has a double
    // integrator that W = s/(s + 1) does not remove.
    case kLoadDistW: return loop.load_from_load_torque(w) * weight(w);
    case kOpenW: return loop.open_loop_load_from_load_torque(w) * weight(w);
    case kChannels: break;
  }
  return {kNaN, kNaN};
}

/// g/s: the numerator deflated by s when its constant term vanishes (to rounding: a velocity
/// output of a loop that holds its position), else a pole at 0 added.
core::TransferFunction integrated(const core::TransferFunction& g) {
  const std::span<const double> c = g.num().coefficients();
  double largest = 0.0;
  for (const double v : c) largest = std::max(largest, std::abs(v));
  constexpr double kVanishing = 1e-10;
  if (c.size() > 1 && std::abs(c.back()) <= kVanishing * largest)
    return {core::Polynomial(std::vector<double>(c.begin(), c.end() - 1)), g.den()};
  return {g.num(), g.den() * core::Polynomial{1.0, 0.0}};
}



/// |z| without hypot's overflow guard (the loop functions stay far from the double range), which
/// is most of the sampling cost otherwise.
double magnitude(Complex z) { return std::sqrt(std::norm(z)); }

/// Sample buffers reused by the analyses of one thread: the grid pass of every analyse() call
/// would otherwise allocate and return ~150 kB, which glibc hands back to the kernel each time.
struct Workspace {
  std::vector<double> mags;
  std::vector<Complex> l;
};
Workspace& workspace() {
  thread_local Workspace w;
  return w;
}

void frequency_indices(const VelocityLoop& loop, const ClosedLoopTransfer& cl, std::span<const double> grid,
                       const AnalysisOptions& o, LoopIndices& out) {
  const std::size_t n = grid.size();
  const bool load = loop.has_load();
  const bool tracking = loop.has_load_tracking();
  // The load channels follow kTm: kTl alone for a modal plant's estimated load tracking.
  const std::size_t channels = load ? kChannels : tracking ? kTl + 1 : kTl;
  Workspace& ws = workspace();
  ws.mags.resize(kChannels * n);
  ws.l.resize(n);
  std::span<double> mags(ws.mags);
  std::span<Complex> l(ws.l.data(), n);
  const bool position = o.position_outputs;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = grid[i];
    const VelocityLoop::Responses r = loop.responses(w);
    // A position is the velocity over jω: its magnitude over ω.
    const double to_judged = position ? 1.0 / w : 1.0;
    l[i] = r.loop_gain;
    mags[kS * n + i] = magnitude(r.sensitivity);
    mags[kT * n + i] = magnitude(r.complementary);
    mags[kTm * n + i] = magnitude(r.motor_tracking) * to_judged;
    if (tracking) mags[kTl * n + i] = magnitude(r.load_tracking) * to_judged;
    if (!load) continue;
    mags[kLoadDist * n + i] = magnitude(r.load_from_load_torque) * to_judged;
    mags[kLoadDistW * n + i] = magnitude(r.load_from_load_torque * weight(w));
    mags[kOpenW * n + i] = magnitude(r.open_loop_load_from_load_torque * weight(w));
  }
  std::array<core::PeakResult, kChannels> peaks{};
  for (std::size_t c = 0; c < channels; ++c) {
    const std::function<Complex(double)> f = [&loop, c, position](double w) {
      return channel(loop, static_cast<Channel>(c), w, position);
    };
    peaks[c] = refined_peak(f, grid, mags.subspan(c * n, n), o.rel_tol);
  }
  out.peak_s = peaks[kS].value;
  out.peak_s_omega = peaks[kS].omega_rad_s;
  out.peak_t = peaks[kT].value;
  out.peak_tm = peaks[kTm].value;
  out.modulus_margin = 1.0 / out.peak_s;
  out.bandwidth_motor = bandwidth_from_samples([&loop, position](double w) { return channel(loop, kTm, w, position); },
                                               cl.motor_tracking.dc_gain(), grid,
                                               mags.subspan(kTm * n, n));
  out.peak_tl = out.peak_load_disturbance = out.j2 = out.bandwidth_load = kNaN;
  if (tracking) {
    out.peak_tl = peaks[kTl].value;
    out.bandwidth_load = bandwidth_from_samples([&loop, position](double w) { return channel(loop, kTl, w, position); },
                                                cl.load_tracking->dc_gain(), grid,
                                                mags.subspan(kTl * n, n));
  }
  if (load) {
    out.peak_load_disturbance = peaks[kLoadDist].value;
    out.j2 = peaks[kLoadDistW].value / peaks[kOpenW].value;
  }
  margins(loop, grid, l, out);
}

// ----------------------------------------------------------------------------- time indices

/// Streaming step-response indices of one output: no storage per sample.
class StepAccumulator {
 public:
  /// `itae_about_final`: the ITAE of y − final (a load position keeps a static twist), else of y.
  StepAccumulator(double final_value, double band, bool itae_about_final = false)
      : final_(final_value), band_(band * std::abs(final_value)), itae_offset_(itae_about_final ? final_value : 0.0) {}

  void add(std::size_t k, double t, double y, double dt) noexcept {
    max_ = std::max(max_, y);
    max_abs_ = std::max(max_abs_, std::abs(y));
    const double ty = t * std::abs(y - itae_offset_);
    if (k > 0) itae_ += 0.5 * dt * (previous_ty_ + ty);
    previous_ty_ = ty;
    const double excess = std::abs(y - final_) - band_;
    if (excess > 0.0) {
      last_outside_ = k;
      excess_out_ = excess;
      t_out_ = t;
      waiting_ = true;
      any_outside_ = true;
    } else if (waiting_) {
      excess_in_ = excess;
      waiting_ = false;
    }
  }

  [[nodiscard]] double overshoot() const noexcept {
    if (!(std::abs(final_) > 0.0)) return kNaN;
    return std::max(0.0, (max_ - final_) / std::abs(final_));
  }
  [[nodiscard]] double settling_time(double dt) const noexcept {
    if (!any_outside_) return 0.0;
    if (waiting_) return kInf;
    return t_out_ + dt * excess_out_ / (excess_out_ - excess_in_);
  }
  [[nodiscard]] double itae() const noexcept { return itae_; }
  [[nodiscard]] double max_abs() const noexcept { return max_abs_; }

 private:
  double final_;
  double band_;
  double itae_offset_;
  double max_ = -kInf;
  double max_abs_ = 0.0;
  double itae_ = 0.0;
  double previous_ty_ = 0.0;
  std::size_t last_outside_ = 0;
  double excess_out_ = 0.0, excess_in_ = 0.0, t_out_ = 0.0;
  bool waiting_ = false;
  bool any_outside_ = false;
};

/// Unit-step responses of several transfer functions over one characteristic polynomial: one
/// realization (controller canonical form depends on the denominator only) with the numerators as
/// output rows; separate realizations when the denominators differ.
void simulate_steps(std::span<const core::TransferFunction> tfs, double dt, std::size_t samples,
                    std::span<StepAccumulator> acc) {
  std::vector<core::StateSpace> parts;
  parts.reserve(tfs.size());
  for (const core::TransferFunction& g : tfs) parts.push_back(core::to_state_space(g));
  bool shared = true;
  for (const core::StateSpace& p : parts) shared = shared && p.A == parts.front().A && p.B == parts.front().B;
  std::vector<std::pair<core::StateSpace, std::vector<std::size_t>>> systems;
  if (shared) {
    core::StateSpace s = parts.front();
    s.C.resize(static_cast<Eigen::Index>(parts.size()), s.A.cols());
    s.D.resize(static_cast<Eigen::Index>(parts.size()), 1);
    std::vector<std::size_t> idx;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      s.C.row(static_cast<Eigen::Index>(k)) = parts[k].C;
      s.D(static_cast<Eigen::Index>(k), 0) = parts[k].D(0, 0);
      idx.push_back(k);
    }
    systems.emplace_back(std::move(s), std::move(idx));
  } else {
    for (std::size_t k = 0; k < parts.size(); ++k) systems.emplace_back(parts[k], std::vector<std::size_t>{k});
  }
  const std::array<double, 1> u{1.0};
  for (const auto& [sys, idx] : systems) {
    core::DiscreteSimulator sim(core::discretize_zoh(sys, dt));
    std::vector<double> y(idx.size());
    for (std::size_t k = 0; k < samples; ++k) {
      sim.step(u, y);
      const double t = static_cast<double>(k) * dt;
      for (std::size_t j = 0; j < idx.size(); ++j) acc[idx[j]].add(k, t, y[j], dt);
    }
  }
}

// A closed-loop pole within this relative distance of both a zero and a pole of the plant (or of
// the controller) belongs to a nearly cancelled pole-zero pair of that block.
constexpr double kCancellationDistance = 1e-3;
// Only lightly damped poles are tested for cancellation (a practically unobservable mode); the
// real poles that set most horizons are not, which keeps the scans' cost unchanged.
constexpr double kCancellationDampingBelow = 0.1;

bool near_any(const Complex& p, const std::vector<Complex>& roots) {
  return std::any_of(roots.begin(), roots.end(),
                     [&](const Complex& z) { return std::abs(p - z) <= kCancellationDistance * std::abs(p); });
}

double damping_of(const Complex& p) { return core::modal_info(p).zeta; }

void time_indices(const ClosedLoopTransfer& cl, const std::vector<Complex>& visible, const AnalysisOptions& o,
                  LoopIndices& out) {
  const bool tracking = cl.load_tracking.has_value();
  const bool load = cl.load_from_load_torque.has_value();
  double fastest = 0.0;
  double slowest = kInf;
  for (const Complex& p : out.closed_loop_poles) fastest = std::max(fastest, std::abs(p));
  for (const Complex& p : visible) slowest = std::min(slowest, -p.real());
  out.horizon = o.horizon_time_constants / slowest;
  out.sample_time = 0.02 / fastest;
  auto samples = static_cast<std::size_t>(std::ceil(out.horizon / out.sample_time)) + 1;
  if (samples > o.max_samples + 1) {
    samples = o.max_samples + 1;
    out.sample_time = out.horizon / static_cast<double>(o.max_samples);
  }
  std::vector<core::TransferFunction> tfs{cl.motor_tracking, cl.effort};
  if (tracking) tfs.push_back(*cl.load_tracking);
  if (load) tfs.push_back(*cl.load_from_load_torque);
  std::vector<StepAccumulator> acc;
  for (const core::TransferFunction& g : tfs) acc.emplace_back(g.dc_gain(), o.settling_band, o.position_outputs);
  simulate_steps(tfs, out.sample_time, samples, acc);
  out.overshoot_motor = acc[0].overshoot();
  out.settling_time_motor = acc[0].settling_time(out.sample_time);
  out.peak_torque_step = acc[1].max_abs();
  out.overshoot = tracking ? acc[2].overshoot() : out.overshoot_motor;
  out.settling_time = tracking ? acc[2].settling_time(out.sample_time) : out.settling_time_motor;
  out.itae_load_step = load ? acc[3].itae() : kNaN;
}

void mark_unstable(LoopIndices& out) {
  out.bandwidth_motor = out.bandwidth_load = kNaN;
  out.peak_s = out.peak_t = out.peak_tm = out.peak_tl = out.peak_load_disturbance = out.j2 = kInf;
  out.peak_s_omega = kNaN;
  out.gain_margin_db = out.phase_margin_deg = out.phase_crossover = out.gain_crossover = kNaN;
  out.modulus_margin = 0.0;
  out.overshoot = out.settling_time = out.overshoot_motor = out.settling_time_motor = kInf;
  out.itae_load_step = out.peak_torque_step = kInf;
  out.sample_time = out.horizon = kNaN;
}

}  // namespace

ClosedLoopTransfer integrated_outputs(ClosedLoopTransfer cl) {
  cl.motor_tracking = integrated(cl.motor_tracking);
  if (cl.load_tracking) cl.load_tracking = integrated(*cl.load_tracking);
  if (cl.motor_from_load_torque) cl.motor_from_load_torque = integrated(*cl.motor_from_load_torque);
  if (cl.load_from_load_torque) cl.load_from_load_torque = integrated(*cl.load_from_load_torque);
  return cl;
}

void validate(const AnalysisOptions& o) {
  detail::require_positive(o.omega_min, "omega_min", "the grid start");
  if (!std::isfinite(o.omega_max) || o.omega_max <= o.omega_min)
    throw core::InputError(core::at_field("omega_max"),
                           "expected a finite grid end > omega_min = " + detail::show(o.omega_min) + ", got " +
                               detail::show(o.omega_max));
  if (o.grid_points < 16)
    throw core::InputError(core::at_field("grid_points"),
                           "expected at least 16 grid points, got " + std::to_string(o.grid_points));
  if (!(o.rel_tol >= 1e-12 && o.rel_tol <= 0.1))
    throw core::InputError(core::at_field("rel_tol"), "expected a tolerance in [1e-12, 0.1], got " + detail::show(o.rel_tol));
  if (!(o.settling_band > 0.0 && o.settling_band < 1.0))
    throw core::InputError(core::at_field("settling_band"),
                           "expected a relative band in (0, 1), got " + detail::show(o.settling_band));
  for (const double w : o.extra_frequencies)
    if (!std::isfinite(w) || w <= 0.0)
      throw core::InputError(core::at_field("extra_frequencies"), "expected finite frequencies > 0, got " + detail::show(w));
  detail::require_finite(o.hf_gain_omega, "hf_gain_omega");
  detail::require_positive(o.horizon_time_constants, "horizon_time_constants", "a number of time constants");
  if (o.max_samples < 100)
    throw core::InputError(core::at_field("max_samples"), "expected at least 100 samples, got " + std::to_string(o.max_samples));
}

/// The zeros and poles of the plant and of the feedback controller, rooted on first use.
struct BlockRoots {
  std::vector<Complex> plant_zeros, plant_poles, controller_zeros, controller_poles;
  explicit BlockRoots(const VelocityLoop& loop)
      : plant_zeros(loop.measured_num().roots()),
        plant_poles(loop.plant_den().roots()),
        controller_zeros(loop.controller_tf().feedback.num().roots()),
        controller_poles(loop.controller_tf().feedback.den().roots()) {}
  /// p sits on a nearly cancelled pole-zero pair of the plant or of the controller.
  [[nodiscard]] bool cancelled(const Complex& p) const {
    return (near_any(p, plant_zeros) && near_any(p, plant_poles)) ||
           (near_any(p, controller_zeros) && near_any(p, controller_poles));
  }
};

std::vector<Complex> visible_poles(const VelocityLoop& loop, const std::vector<Complex>& poles) {
  std::vector<Complex> visible;
  visible.reserve(poles.size());
  std::optional<BlockRoots> roots;
  for (const Complex& p : poles) {
    if (damping_of(p) >= kCancellationDampingBelow) {
      visible.push_back(p);
      continue;
    }
    if (!roots) roots.emplace(loop);
    if (!roots->cancelled(p)) visible.push_back(p);
  }
  return visible.empty() ? poles : visible;  // every pole cancelled: keep them all
}

double least_visible_damping(const VelocityLoop& loop, const std::vector<Complex>& poles) {
  double least = kInf;
  for (const Complex& p : visible_poles(loop, poles)) least = std::min(least, damping_of(p));
  return least;
}

LoopIndices analyse(const VelocityLoop& loop, const AnalysisOptions& options) {
  validate(options);
  LoopIndices out;
  const ClosedLoopTransfer cl = options.position_outputs ? integrated_outputs(loop.closed_loop()) : loop.closed_loop();
  out.closed_loop_poles = cl.characteristic.roots();
  const std::vector<Complex> visible = visible_poles(loop, out.closed_loop_poles);
  out.min_damping = kInf;
  for (const Complex& p : visible) out.min_damping = std::min(out.min_damping, damping_of(p));
  out.closed_loop_stable = loop.stable();
  out.hf_controller_gain =
      options.hf_gain_omega > 0.0 ? std::abs(loop.controller(options.hf_gain_omega)) : loop.controller_hf_limit();
  if (!out.closed_loop_stable) {
    mark_unstable(out);
    return out;
  }
  const std::vector<double> grid = analysis_grid(options, out.closed_loop_poles);
  frequency_indices(loop, cl, grid, options, out);
  time_indices(cl, visible, options, out);
  return out;
}

LoopIndices analyse(const NormalizedPlant& plant, const PidGains& gains, const AnalysisOptions& options) {
  return analyse(plant, pid_controller(gains), options);
}

LoopIndices analyse(const NormalizedPlant& plant, const ControllerTf& controller, const AnalysisOptions& options) {
  return analyse(plant, VelocityLoop(plant, controller), options);
}

LoopIndices analyse(const NormalizedPlant& plant, const VelocityLoop& loop, const AnalysisOptions& options) {
  AnalysisOptions o = options;
  o.extra_frequencies.push_back(1.0);
  if (plant.r > 0.0) o.extra_frequencies.push_back(plant.r);
  for (const fit::Mode& m : plant.higher_modes) {
    o.extra_frequencies.push_back(m.antiresonance.omega_rad_s);
    o.extra_frequencies.push_back(m.resonance.omega_rad_s);
  }
  if (o.hf_gain_omega <= 0.0) o.hf_gain_omega = 10.0 * plant.r;
  return analyse(loop, o);
}


// ----------------------------------------------------------------------------- J1/J2 (C7.8)

namespace {

constexpr double kInvGolden = 0.6180339887498949;  // (√5 − 1)/2

/// Golden-section maximization of f on [lo, hi] in log ω (or linearly when `linear`), `steps`
/// steps; returns the best evaluated point (the ends are not evaluated).
template <class F>
std::pair<double, double> golden_max(F&& f, double lo, double hi, int steps, bool linear) {
  const auto to = [linear](double x) { return linear ? x : std::log(x); };
  const auto from = [linear](double x) { return linear ? x : std::exp(x); };
  double a = to(lo), b = to(hi);
  double x1 = b - kInvGolden * (b - a), x2 = a + kInvGolden * (b - a);
  double f1 = f(from(x1)), f2 = f(from(x2));
  std::pair<double, double> best = f1 >= f2 ? std::pair{from(x1), f1} : std::pair{from(x2), f2};
  for (int k = 0; k < steps; ++k) {
    if (f1 >= f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - kInvGolden * (b - a);
      f1 = f(from(x1));
      if (f1 > best.second) best = {from(x1), f1};
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + kInvGolden * (b - a);
      f2 = f(from(x2));
      if (f2 > best.second) best = {from(x2), f2};
    }
  }
  return best;
}

/// The J1/J2 evaluation of one ω*.
struct OmegaScore {
  double j1 = -1.0;  ///< load bandwidth at the best feasible wp; −1: no wp meets the peak limit
  double wp = 1.0;
  double j2 = kInf;
};

class IndexEvaluator {
 public:
  IndexEvaluator(const NormalizedPlant& plant, const IndexOptions& o) : plant_(plant), o_(o), model_(plant.motor(false)) {
    o_.analysis.extra_frequencies.push_back(1.0);
    o_.analysis.extra_frequencies.push_back(plant.r);
    // The open-loop reference ‖(ωl/Tl)_ol W‖∞ does not depend on the gains.
    const VelocityLoop loop(plant, PidGains{1.0, 1.0, 0.0, 0.0, 1.0, 0.0});
    const std::vector<double> grid = analysis_grid(o_.analysis, {});
    std::vector<double> mags(grid.size());
    const std::function<Complex(double)> f = [&loop](double w) { return loop.open_loop_load_from_load_torque(w) * weight(w); };
    for (std::size_t i = 0; i < grid.size(); ++i) mags[i] = magnitude(f(grid[i]));
    open_peak_ = refined_peak(f, grid, mags, o_.analysis.rel_tol).value;
  }

  OmegaScore operator()(double omega_star, bool want_j1, bool want_j2) const {
    OmegaScore score;
    PidGains g{0.0, 0.0, o_.kd, o_.tau, 1.0, 0.0};
    try {
      const PolePlacement placed = pi_pole_placement(model_, omega_star, o_.zeta_star, o_.kd, o_.tau);
      g.kp = placed.gains.kp;
      g.ki = placed.gains.ki;
    } catch (const core::InputError&) {
      return score;  // the pair cannot be placed here: worst scores
    }
    const VelocityLoop loop(plant_, g);
    if (!loop.stable()) {
      score.j1 = 0.0;
      return score;
    }
    const std::vector<Complex> poles = loop.characteristic_polynomial().roots();
    const std::vector<double> grid = analysis_grid(o_.analysis, poles);
    if (want_j2) score.j2 = j2(loop, grid);
    if (want_j1) best_wp(loop, g, grid, score);
    return score;
  }

 private:
  double j2(const VelocityLoop& loop, const std::vector<double>& grid) const {
    std::vector<double> mags(grid.size());
    const std::function<Complex(double)> f = [&loop](double w) { return loop.load_from_load_torque(w) * weight(w); };
    for (std::size_t i = 0; i < grid.size(); ++i) mags[i] = magnitude(f(grid[i]));
    return refined_peak(f, grid, mags, o_.analysis.rel_tol).value / open_peak_;
  }

  /// J1 over wp. With w_d = 0, R_wp(jω) = wp kp + ki/(jω), so ωl/ω*(wp) = (ωl/ω*)_{wp=1}·R_wp/R_1:
  /// one evaluation of the loop per grid point serves every wp.
  void best_wp(const VelocityLoop& loop, const PidGains& g, const std::vector<double>& grid, OmegaScore& score) const {
    const std::size_t n = grid.size();
    std::vector<Complex> x(n), y(n);  // ωl/ω*(wp) = wp x + y
    for (std::size_t i = 0; i < n; ++i) {
      const Complex integral = g.ki / Complex(0.0, grid[i]);
      const Complex base = loop.load_tracking(grid[i]) / (g.kp + integral);
      x[i] = g.kp * base;
      y[i] = integral * base;
    }
    std::vector<double> mags(n);
    const auto j1_of = [&](double wp) {
      for (std::size_t i = 0; i < n; ++i) mags[i] = magnitude(wp * x[i] + y[i]);
      const std::function<Complex(double)> f = [&loop, &g, wp](double w) {
        const Complex integral = g.ki / Complex(0.0, w);
        return loop.load_tracking(w) * (wp * g.kp + integral) / (g.kp + integral);
      };
      if (refined_peak(f, grid, mags, o_.analysis.rel_tol).value > o_.peak_limit) return -1.0;
      return bandwidth_from_samples(f, 1.0, grid, mags);  // integral action: DC gain 1
    };
    constexpr int kWpPoints = 11;
    std::array<double, kWpPoints> values{};
    std::size_t best = 0;
    for (std::size_t k = 0; k < kWpPoints; ++k) {
      values[k] = j1_of(static_cast<double>(k) / (kWpPoints - 1));
      if (values[k] > values[best]) best = k;
    }
    score.j1 = values[best];
    score.wp = static_cast<double>(best) / (kWpPoints - 1);
    if (score.j1 < 0.0) return;
    const double step = 1.0 / (kWpPoints - 1);
    for (const double side : {-1.0, 1.0}) {
      const double lo = std::clamp(score.wp + std::min(side, 0.0) * step, 0.0, 1.0);
      const double hi = std::clamp(score.wp + std::max(side, 0.0) * step, 0.0, 1.0);
      if (hi <= lo) continue;
      const auto [wp, j1] = golden_max(j1_of, lo, hi, 24, true);
      if (j1 > score.j1) {
        score.j1 = j1;
        score.wp = wp;
      }
    }
  }

  const NormalizedPlant& plant_;
  IndexOptions o_;
  core::TransferFunction model_;
  double open_peak_ = 0.0;
};

void validate(const IndexOptions& o) {
  detail::require_positive(o.peak_limit, "peak_limit", "a peak limit M_T");
  detail::require_positive(o.zeta_star, "zeta_star", "a damping");
  detail::require_finite(o.kd, "kd");
  detail::require_non_negative(o.tau, "tau", "a derivative filter time constant");
  if (o.kd != 0.0 && o.tau <= 0.0)
    throw core::InputError(core::at_field("tau"),
                           "expected a derivative filter tau > 0 with kd = " + detail::show(o.kd) +
                               " (an ideal derivative cannot be evaluated)");
  if (o.omega_star_points < 3)
    throw core::InputError(core::at_field("omega_star_points"),
                           "expected at least 3 scan points, got " + std::to_string(o.omega_star_points));
  validate(o.analysis);
}

}  // namespace

OmegaChoice choose_omega_star(const NormalizedPlant& plant, const IndexOptions& options) {
  validate(options);
  if (!two_mass_transfer(plant))
    throw core::InputError(core::at_field("plant"),
                           "J1/J2 need the load velocity, but the plant has higher modes or no two-mass realization "
                           "with viscous friction; use analyse() for the motor-side indices");
  const AdmissibleRange range = admissible_range(plant, options.zeta_star, options.kd);
  if (range.empty())
    throw core::InputError(core::at_field("zeta_star"), "no admissible omega* for zeta* = " +
                                                            detail::show(options.zeta_star) + " (" +
                                                            to_string(range.upper) + ")");
  // The ends are boundaries (a gain vanishes, the loop is marginal, the pair stops dominating).
  const double hi = range.omega_max * (1.0 - 1e-6);
  const double lo = range.omega_min > 0.0 ? range.omega_min * (1.0 + 1e-6) : 0.02 * range.omega_max;
  const IndexEvaluator evaluate(plant, options);
  const std::vector<double> scan = core::log_space(lo, hi, options.omega_star_points);
  std::vector<OmegaScore> scores;
  scores.reserve(scan.size());
  for (const double w : scan) scores.push_back(evaluate(w, true, true));
  std::size_t b1 = 0, b2 = 0;
  for (std::size_t k = 1; k < scan.size(); ++k) {
    if (scores[k].j1 > scores[b1].j1) b1 = k;
    if (scores[k].j2 < scores[b2].j2) b2 = k;
  }
  const auto bracket = [&](std::size_t k) {
    return std::pair{scan[k == 0 ? 0 : k - 1], scan[std::min(k + 1, scan.size() - 1)]};
  };
  OmegaChoice out;
  out.range_min = lo;
  out.range_max = hi;
  out.omega_j2 = scan[b2];
  out.j2 = scores[b2].j2;
  {
    const auto [a, b] = bracket(b2);
    const auto [w, neg_j2] = golden_max([&](double x) { return -evaluate(x, false, true).j2; }, a, b, 40, false);
    if (-neg_j2 < out.j2) {
      out.omega_j2 = w;
      out.j2 = -neg_j2;
    }
  }
  if (scores[b1].j1 <= 0.0) {
    out.omega_j1 = kNaN;
    out.j1 = 0.0;
    out.interval_empty = true;
    return out;
  }
  out.omega_j1 = scan[b1];
  out.j1 = scores[b1].j1;
  out.wp = scores[b1].wp;
  const auto [a, b] = bracket(b1);
  OmegaScore refined;
  const auto [w, j1] = golden_max(
      [&](double x) {
        const OmegaScore s = evaluate(x, true, false);
        if (s.j1 > refined.j1) refined = s;
        return s.j1;
      },
      a, b, 40, false);
  if (j1 > out.j1) {
    out.omega_j1 = w;
    out.j1 = j1;
    out.wp = refined.wp;
  }
  out.interval_empty = !(out.omega_j2 <= out.omega_j1);
  return out;
}

}  // namespace servotwin::tuning
