#include "servotwin/tuning/tune.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <iterator>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/tuning/position_loop.hpp"
#include "servotwin/tuning/uncertainty.hpp"
#include "auto_notch.hpp"

namespace servotwin::tuning {

namespace {

using core::InputError;
using core::at_field;

constexpr double kRatioForPassiveMethods = 1.3;  // C7.4: below it no PI/PID reaches a useful bandwidth
// Below this least closed-loop damping a design on a modal model (no load side) gets a note.
constexpr double kLowDampingNote = 0.1;
constexpr double kDefaultTargetR = 2.0;       // C7.5/C7.15: the PID's virtual resonance ratio
constexpr std::size_t kTargetRCandidates = 6;  // automatic r̄: 2 … 0.9 r, geometric
constexpr double kTargetRFractionOfR = 0.9;    // the largest automatic r̄ (r̄ = r is no derivative at all)

void require(bool ok, const char* flag, const std::string& message) {
  if (!ok) throw InputError(at_field(flag), message);
}

/// A filter request: the period it is designed for, a structure that takes it, each spec.
void validate_drive_filters(const TuneOptions& o) {
  require(!is_lqg(o.structure), "--drive-filter",
          "the LQG structures take no drive filter (their Kalman filter shapes the controller's dynamics); use pi, pid, "
          "pi+p or an H-infinity structure");
  require(o.ts.has_value() || is_hinf(o.structure), "--ts",
          "a drive filter runs at the drive's sample period and is written as discrete biquads: give --ts");
  if (is_hinf(o.structure)) {
    const bool one_rolloff = !o.auto_notch && o.drive_filters.size() == 1 &&
                             o.drive_filters.front().type == DriveFilterType::kLowpass && !o.drive_filters.front().damping;
    require(one_rolloff, "--drive-filter",
            "an H-infinity controller takes one first-order lowpass (its roll-off, designed with); it places its own "
            "notches on higher modes with --hinf-modes passive (catalog C7.16)");
    require(!o.rolloff_rad_s, "--drive-filter", "give the roll-off once: --drive-filter lowpass:F_HZ or --rolloff-hz");
  }
  for (const DriveFilterSpec& f : o.drive_filters) validate(f, o.ts, "--drive-filter");
}

void validate(const TuneOptions& o) {
  require(std::isfinite(o.zeta_star) && o.zeta_star > 0.0 && o.zeta_star <= 3.0, "--zeta-star",
          fmt::format("expected a damping in (0, 3], got {}", o.zeta_star));
  if (o.omega_star) {
    require(std::isfinite(*o.omega_star) && *o.omega_star > 0.0, "--omega-star",
            fmt::format("expected omega*/omega_z > 0, got {}", *o.omega_star));
  }
  if (o.target_r)
    require(std::isfinite(*o.target_r) && *o.target_r > 1.0, "--target-r",
            fmt::format("expected a resonance ratio > 1, got {}", *o.target_r));
  if (o.tau) require(std::isfinite(*o.tau) && *o.tau > 0.0, "--tau", fmt::format("expected a time > 0 s, got {}", *o.tau));
  require(std::isfinite(o.ms) && o.ms > 1.0, "--ms", fmt::format("expected a sensitivity peak limit > 1, got {}", o.ms));
  require(std::isfinite(o.mt) && o.mt >= 1.0, "--mt", fmt::format("expected a tracking peak limit >= 1, got {}", o.mt));
  if (o.min_damping)
    require(std::isfinite(*o.min_damping) && *o.min_damping > 0.0 && *o.min_damping < 1.0, "--min-damping",
            fmt::format("expected a damping ratio in (0, 1), got {}", *o.min_damping));
  if (o.ts) require(std::isfinite(*o.ts) && *o.ts > 0.0, "--ts", fmt::format("expected a sample period > 0 s, got {}", *o.ts));
  require(o.setpoint_weight >= 0.0 && o.setpoint_weight <= 1.0, "--setpoint-weight",
          fmt::format("expected a weight in [0, 1], got {}", o.setpoint_weight));
  require(o.scan_points >= 4 && o.scan_points <= 1000, "scan_points", "expected 4 to 1000 candidates");
  if (o.kbw) require(std::isfinite(*o.kbw) && *o.kbw > 0.0, "--kbw", fmt::format("expected a knob > 0, got {}", *o.kbw));
  if (o.feedforward)
    require(std::isfinite(*o.feedforward) && *o.feedforward >= 0.0, "--kff",
            fmt::format("expected a normalized feedforward gain >= 0, got {}", *o.feedforward));
  if (o.omega_0s)
    require(std::isfinite(*o.omega_0s) && *o.omega_0s > 0.0, "--omega-0s",
            fmt::format("expected w0S/omega_z > 0, got {}", *o.omega_0s));
  if (o.omega_0t)
    require(std::isfinite(*o.omega_0t) && *o.omega_0t > 0.0, "--omega-0t",
            fmt::format("expected w0T/omega_z > 0, got {}", *o.omega_0t));
  require(std::isfinite(o.xi_v) && o.xi_v >= kXiVMin && o.xi_v <= kXiVMax, "--xi-v",
          fmt::format("expected a damping in [0.707, 1] (catalog C7.14), got {}", o.xi_v));
  if (o.rolloff_rad_s) {
    require(std::isfinite(*o.rolloff_rad_s) && *o.rolloff_rad_s > 0.0, "--rolloff-hz",
            fmt::format("expected a corner frequency > 0, got {} rad/s", *o.rolloff_rad_s));
    require(is_hinf(o.structure), "--rolloff-hz",
            "rolloff_rad_s is the H-infinity roll-off; a PI/PID takes it as a drive filter (--drive-filter lowpass:F_HZ)");
  }
  if (!o.drive_filters.empty() || o.auto_notch) validate_drive_filters(o);
  if (o.controller_order)
    require(*o.controller_order >= 1, "--controller-order",
            fmt::format("expected a number of controller states >= 1, got {}", *o.controller_order));
  if (o.w2) {
    require(o.w2->is_proper(), "--w2", "the uncertainty weight must be proper (numerator degree <= denominator degree)");
    require(core::is_hurwitz(o.w2->den()), "--w2", "the uncertainty weight must be stable (poles in the left half-plane)");
  }
}

/// What the automatic searches maximize: the load tracking bandwidth where the plant has a load
/// side (NormalizedPlant::load_estimate(), as VelocityLoop::has_load_tracking()), else the motor's.
std::string largest_bandwidth(const NormalizedPlant& plant) {
  if (!plant.load_estimate()) return "largest motor bandwidth (no load side)";
  return plant.higher_modes.empty() ? "largest load bandwidth" : "largest load bandwidth (load through the chain)";
}

/// A note when the first mode's two-mass realization is not passive: its load side (the load
/// bandwidth and peaks, the LQG's design model, the position loop) is then an estimate.
std::optional<std::string> estimated_load_note(const NormalizedPlant& plant) {
  const std::optional<FrictionTwoMass> m = two_mass_realization(plant.first_mode());
  if (!m || m->passive()) return std::nullopt;
  return fmt::format("the load side is an estimate: the fit has no passive two-mass realization (antiresonance "
                     "damping {:.3g} against resonance damping {:.3g}); its exact realization needs shaft damping "
                     "b = {:.3g}, load friction bl = {:.3g} and motor friction bm = {:.3g} (normalized), and a motor "
                     "measurement cannot tell where the damping sits: load bandwidth, load peaks and full-order "
                     "designs rest on that reading",
                     plant.zeta_z, plant.zeta_p, m->damping, m->load_viscous, m->motor_viscous);
}

/// The frequency grid of the scan: wide enough for every loop function of a normalized plant.
std::vector<double> scan_grid(const NormalizedPlant& plant) {
  std::vector<double> g = core::log_space(1e-3, 100.0 * std::max(plant.r, 1.0), 500);
  // The lightly damped mode: put its exact frequencies on the grid so its peak is not stepped over.
  g.push_back(1.0);
  g.push_back(plant.r);
  for (const fit::Mode& m : plant.higher_modes) {
    g.push_back(m.antiresonance.omega_rad_s);
    g.push_back(m.resonance.omega_rad_s);
  }
  std::sort(g.begin(), g.end());
  g.erase(std::unique(g.begin(), g.end()), g.end());
  return g;
}

/// The design at one ω*: the PI of C7.3 or the virtual-inertia PID of C7.5, with the setpoint weight.
struct GainDesigner {
  const NormalizedPlant& plant;
  const TuneOptions& options;
  /// The drive filters at the controller's output, normalized time (nullptr: none): the PI's
  /// pair is placed on the plant followed by them.
  const core::TransferFunction* filter = nullptr;

  [[nodiscard]] double tau_normalized(double omega_star) const {
    return options.tau ? *options.tau * plant.omega_z : default_derivative_time_constant(plant.r, omega_star);
  }

  [[nodiscard]] PidGains operator()(double omega_star, std::vector<std::string>* warnings = nullptr) const {
    PidGains g;
    if (options.structure == Structure::kPid) {
      const PidDesign d = pid_design(plant, options.target_r.value_or(kDefaultTargetR), omega_star, options.zeta_star,
                                     tau_normalized(omega_star), options.allow_negative_kd);
      g = d.gains;
      if (warnings) warnings->insert(warnings->end(), d.warnings.begin(), d.warnings.end());
    } else {
      const core::TransferFunction p = filter ? core::series(plant.motor(false), *filter) : plant.motor(false);
      const PiGains pi = pi_pole_placement(p, omega_star, options.zeta_star).gains;
      g.kp = pi.kp;
      g.ki = pi.ki;
    }
    g.wp = options.setpoint_weight;
    return g;
  }
};

/// A coarser robustness grid for the ω* scan (the chosen design is re-evaluated on the full one).
RobustnessOptions scan_robustness_options() {
  RobustnessOptions o;
  o.grid_points = 250;
  o.rel_tol = 1e-4;
  return o;
}

using Complex = std::complex<double>;

/// A position controller's reference prefilter keeps the judged position free of overshoot (C7.13).
constexpr double kNoOvershoot = 1.0;
/// The scans rank candidates with the prefilter found to this relative tolerance.
constexpr double kScanPrefilterTolerance = 1e-4;

/// The spec evaluated on the loop WITH the HF dynamics: stability, ‖S‖∞, the tracking peak, the
/// bandwidth, and robust performance (uncertainty.hpp) when W2 is given. A position controller
/// (lqg-pos, hinf-pos; its loop in velocity_form) is judged on positions: the tracking peak of
/// φ/φ* without its prefilter (the feedback's resonance) against Mt, the bandwidth with the
/// prefilter that keeps φ/φ* free of overshoot.
struct SpecCheck {
  const NormalizedPlant& plant;
  const TuneOptions& options;
  std::optional<core::TransferFunction> w2;  // normalized time
  std::vector<double> grid;
  std::vector<double> bandwidth_grid;  // the grid with ω = 0 first (the DC reference of the bandwidth)

  [[nodiscard]] TuneResult::Candidate operator()(double omega_star, const PidGains& gains) const {
    return (*this)(omega_star, VelocityLoop(plant, gains));
  }

  /// The spec of the loop; `parameter` is recorded as the candidate's ω* (lqg: kbw).
  [[nodiscard]] TuneResult::Candidate operator()(double parameter, const VelocityLoop& loop) const {
    TuneResult::Candidate c;
    c.omega_star = parameter;
    c.stable = loop.stable();
    if (!c.stable) return c;
    c.peak_s = core::peak_on_grid([&](double w) { return loop.sensitivity(w); }, grid, 1e-4).value;
    const std::function<Complex(double)> tracking = judged_tracking(loop);
    c.peak_tracking = core::peak_on_grid(tracking, grid, 1e-4).value;
    c.feasible = c.peak_s <= options.ms && c.peak_tracking <= options.mt;
    c.bandwidth = core::bandwidth(tracking, bandwidth_grid).value_or(0.0);
    if (position() && c.feasible) {
      const std::optional<double> tau = prefilter(tracking, kScanPrefilterTolerance);
      c.feasible = tau.has_value();
      if (tau) c.bandwidth = core::bandwidth(filtered(tracking, *tau), bandwidth_grid).value_or(0.0);
    }
    if (options.min_damping) {
      c.min_damping = least_visible_damping(loop, loop.characteristic_polynomial().roots());
      c.feasible = c.feasible && c.min_damping >= *options.min_damping;
    }
    if (c.feasible && w2) c.feasible = robust(loop);
    return c;
  }


  [[nodiscard]] bool position() const noexcept { return is_position_controller(options.structure); }

  /// The tracking function the spec judges: the load's where the loop has one (estimated through
  /// the chain on a modal plant), else the motor's; for a position controller as a position (the
  /// velocity form's output over jω; 1 at DC, where its integral action holds the reference).
  [[nodiscard]] std::function<Complex(double)> judged_tracking(const VelocityLoop& loop) const {
    const bool load = loop.has_load_tracking();
    const bool as_position = position();
    return [&loop, load, as_position](double w) {
      const Complex v = load ? loop.load_tracking(w) : loop.motor_tracking(w);
      if (!as_position) return v;
      return w == 0.0 ? Complex(1.0, 0.0) : v / Complex(0.0, w);
    };
  }

  /// The prefilter time constant keeping `tracking` free of overshoot; std::nullopt when none does.
  [[nodiscard]] std::optional<double> prefilter(const std::function<Complex(double)>& tracking, double rel_tol) const {
    try {
      return prefilter_time_constant(tracking, grid, kNoOvershoot, rel_tol);
    } catch (const std::invalid_argument&) {
      return std::nullopt;
    }
  }

  [[nodiscard]] static std::function<Complex(double)> filtered(const std::function<Complex(double)>& tracking,
                                                               double tau) {
    return [tracking, tau](double w) { return tracking(w) / (tau * Complex(0.0, w) + 1.0); };
  }

 private:
  /// PI/PID: RP of the disturbance type (uncertainty.hpp); lqg: RS and C7.13's robust tracking,
  /// with a margin for the scan grid's resolution: the bisections of kbw and kff end on the
  /// boundary, and the final test on the fine grid must still pass there.
  [[nodiscard]] bool robust(const VelocityLoop& loop) const {
    // A 1-DoF loop (PI/PID, hinf): RP of the disturbance type; the 2-DoF LQG: robust tracking. A
    // position controller: RP of the disturbance type too (C7.13's tracking test is the velocity's).
    if (!is_full_order(options.structure) || is_hinf(options.structure) || position())
      return robustness(loop, *w2, options.ms, scan_robustness_options()).rp_ok;
    constexpr double kScanGridMargin = 1e-3;
    return robust_tracking(loop, *w2, options.mt, scan_robustness_options()).value < 1.0 - kScanGridMargin;
  }
};

[[nodiscard]] std::vector<double> candidates(const AdmissibleRange& range, std::size_t n) {
  const double hi = range.omega_max;
  const double lo = std::max(range.omega_min, 0.02 * hi);
  std::vector<double> c = core::log_space(lo * (1.0 + 1e-9), hi * (1.0 - 1e-9), n);
  return c;
}

/// The largest-bandwidth feasible candidate, its boundary with the next infeasible one refined
/// by bisection (feasibility usually ends at a peak limit reached as the loop gets faster).
/// `evaluate(parameter)` gives the candidate of one parameter (ω*, or kbw for lqg).
/// Bisection (`steps` geometric steps) between a feasible parameter `lo` and an infeasible `hi`;
/// every feasible candidate with a larger bandwidth than `chosen` replaces it.
template <class Evaluate>
void refine_boundary(double lo, double hi, Evaluate&& evaluate, TuneResult::Candidate& chosen, int steps = 12) {
  for (int it = 0; it < steps; ++it) {
    const double mid = std::sqrt(lo * hi);
    const TuneResult::Candidate c = evaluate(mid);
    if (c.feasible) {
      lo = mid;
      if (c.bandwidth > chosen.bandwidth) chosen = c;
    } else {
      hi = mid;
    }
  }
}

template <class Evaluate>
TuneResult::Candidate choose(const std::vector<TuneResult::Candidate>& scan, Evaluate&& evaluate,
                             int boundary_steps = 12) {
  std::size_t best = scan.size();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan[i].feasible && (best == scan.size() || scan[i].bandwidth > scan[best].bandwidth)) best = i;
  }
  if (best == scan.size()) return {};
  TuneResult::Candidate chosen = scan[best];
  if (best + 1 < scan.size() && !scan[best + 1].feasible)
    refine_boundary(scan[best].omega_star, scan[best + 1].omega_star, evaluate, chosen, boundary_steps);
  return chosen;
}

[[noreturn]] void no_feasible_omega(const std::vector<TuneResult::Candidate>& scan, const TuneOptions& o) {
  double best_s = std::numeric_limits<double>::infinity(), best_t = best_s, at = 0.0;
  for (const TuneResult::Candidate& c : scan) {
    if (c.stable && std::max(c.peak_s / o.ms, c.peak_tracking / o.mt) < std::max(best_s / o.ms, best_t / o.mt)) {
      best_s = c.peak_s;
      best_t = c.peak_tracking;
      at = c.omega_star;
    }
  }
  const bool hinf = is_hinf(o.structure);
  const bool lqg = is_full_order(o.structure) && !hinf;
  const char* parameter = lqg ? "kbw" : hinf ? "w0S" : "omega*";
  if (!std::isfinite(best_s)) {
    throw InputError(at_field("--structure"),
                     fmt::format("no {} in the {} gives a stable loop with the known HF dynamics: reduce the "
                                 "delay/lags or use a slower structure",
                                 parameter, lqg ? "range [1e-4, 1e3]" : hinf ? "range [0.05, 2r]" : "admissible range"));
  }
  if (o.min_damping) {
    double best_damping = 0.0, at_damping = 0.0;
    for (const TuneResult::Candidate& c : scan)
      if (c.stable && c.peak_s <= o.ms && c.peak_tracking <= o.mt && c.min_damping > best_damping) {
        best_damping = c.min_damping;
        at_damping = c.omega_star;
      }
    if (best_damping > 0.0)
      throw InputError(at_field("--min-damping"),
                       fmt::format("no {} within ||S|| <= {} and the tracking peak <= {} gives every visible "
                                   "closed-loop pole a damping >= {}: the best is {:.3g} at {} = {:.3g}; lower "
                                   "--min-damping",
                                   parameter, o.ms, o.mt, *o.min_damping, best_damping,
                                   lqg ? "kbw" : hinf ? "w0S/omega_z" : "omega*/omega_z", at_damping));
  }
  // The nearest limits that work: the best candidate's own peaks, rounded up to three digits so
  // that the limits printed accept it.
  const auto round_up = [](double v) {
    const double scale = std::pow(10.0, 2.0 - std::floor(std::log10(v)));
    return std::ceil(v * scale * (1.0 - 1e-12)) / scale;
  };
  // With W2 the robustness condition decides too: only the direction is known.
  const std::string advice =
      o.w2 ? std::string("relax --ms/--mt")
           : fmt::format("the nearest limits that accept it: --ms {:g} --mt {:g}", std::max(o.ms, round_up(best_s)),
                         std::max(o.mt, round_up(best_t)));
  throw InputError(at_field(o.w2 ? "--w2" : "--ms"),
                   fmt::format("no {} meets ||S|| <= {} and the tracking peak <= {}{}: the best achievable are "
                               "||S|| = {:.3g} and {:.3g} at {} = {:.3g}; {}",
                               parameter, o.ms, o.mt,
                               !o.w2 ? ""
                               : lqg && !is_position_controller(o.structure)
                                   ? " with robust stability and robust tracking (C7.13)"
                                   : " with robust performance",
                               best_s, best_t,
                               lqg ? "kbw" : hinf ? "w0S/omega_z" : "omega*/omega_z", at, advice));
}

PlantScales scales(const NormalizedPlant& p) { return {p.omega_z, p.motor_inertia, p.r, p.zeta_z, p.zeta_p, p.a}; }

/// The bandwidth of the measured velocity's loop (physical): the motor's, or the load's for a
/// load-measuring controller.
double measured_bandwidth(const Controller& c) {
  return (measures_load(c.structure) ? c.predicted.bandwidth_load : c.predicted.bandwidth_motor) * c.plant.omega_z;
}

/// Prewarp the Tustin map at the closed-loop bandwidth when it lies safely below Nyquist.
std::optional<double> prewarp_frequency(const Controller& c, double ts) {
  const double w = measured_bandwidth(c);
  if (std::isfinite(w) && w > 0.0 && w < 0.5 * std::numbers::pi / ts) return w;
  return std::nullopt;
}

void add_discrete(Controller& c, double ts) {
  c.prewarp_rad_s = prewarp_frequency(c, ts);
  c.discrete = discretize_controller(c, ts, c.prewarp_rad_s);
  if (c.physical.kd != 0.0 && ts / c.physical.tau > 0.5) {
    c.notes.push_back(fmt::format("the derivative filter tau = {:.3g} s is short against ts = {:.3g} s: "
                                  "its discrete pole is poorly resolved; increase --tau",
                                  c.physical.tau, ts));
  }
  const double w_bw = measured_bandwidth(c);
  if (w_bw * ts > 0.1) {
    c.notes.push_back(fmt::format("the loop bandwidth is {:.0f} % of the sampling rate: the discrete loop "
                                  "loses phase; verify with the sample delay in the HF dynamics (--delay)",
                                  100.0 * w_bw * ts / (2.0 * std::numbers::pi)));
  }
}

/// The P position loop over the tuned velocity loop (C7.10): the largest gain without overshoot
/// of the load position, lowered to the robust limits when W2 is given.
void add_position_loop(Controller& c, const VelocityLoop& loop, const std::optional<core::TransferFunction>& w2,
                       const NormalizedPlant& plant) {
  // With higher modes the load side is that of the first mode's two-mass realization.
  std::optional<VelocityLoop> first_mode;
  if (!loop.has_load()) first_mode.emplace(plant, normalized_controller(c), true, false);
  const VelocityLoop& base = first_mode ? *first_mode : loop;
  if (!base.has_load()) {
    throw InputError(at_field("--structure"),
                     to_string(c.structure) + " needs the load side of a two-mass realization, and this plant has "
                     "none (its friction terms would be negative); tune the velocity loop alone");
  }
  if (!plant.higher_modes.empty()) {
    c.notes.push_back("the position loop is designed on the first mode's two-mass realization (higher modes left out)");
  }
  const PositionLoop position(functions_of(base), w2);
  const PositionLoopDesign d = position.design();
  if (!(d.kpp_nominal > 0.0)) {
    throw InputError(at_field("--structure"), "no position gain keeps the load position free of overshoot");
  }
  PositionSummary p;
  p.kpp_nominal = d.kpp_nominal;
  double kpp = d.kpp_nominal;
  if (w2) {
    p.kpp_rs = d.kpp_rs;
    p.kpp_rp_exact = d.kpp_rp_exact;
    kpp = std::min({kpp, d.kpp_rs, d.kpp_rp_exact});
    if (!(kpp > 0.0)) {
      throw InputError(at_field("--w2"), "no position gain is robustly stable/robustly performing for this W2");
    }
    if (kpp < d.kpp_nominal) c.notes.push_back("position gain lowered below the no-overshoot value by the uncertainty W2");
  }
  p.bandwidth_load = position.load_bandwidth(kpp).value_or(0.0);
  p.j2 = position.load_disturbance_peak(kpp);
  p.peak_load_tracking = position.load_tracking_peak(kpp);
  c.kpp_normalized = kpp;
  c.kpp_physical = kpp * plant.omega_z;
  c.position = p;
}


/// RS, NP, RP and C7.13's robust tracking of the final design on the fine grid.
void add_robustness(Controller& c, const VelocityLoop& loop, const core::TransferFunction& w2, const TuneOptions& o) {
  const RobustnessResult rob = robustness(loop, w2, o.ms);
  c.robustness.rs = rob.rs;
  c.robustness.np = rob.np;
  c.robustness.rp = rob.rp;
  c.robustness.rp_tracking = robust_tracking(loop, w2, o.mt).value;
  if (!rob.rs_ok) c.notes.push_back("robust stability FAILS for the given W2 (||W2 T|| >= 1)");
}

// ------------------------------------------------------------------------------------- lqg

/// kbw candidates of the automatic search, from slow to fast (C7.13: a larger kbw is slower).
constexpr double kKbwSlowest = 1e3, kKbwFastest = 1e-4;
constexpr std::size_t kKbwPoints = 36;
/// The automatic feedforward stops doubling here (normalized torque per velocity).
constexpr double kFeedforwardCap = 1e3;
constexpr int kFeedforwardBisections = 40;

/// The LQG's design model: the first mode's two-mass realization and the higher modes it is
/// extended with (C7.16; none with --modes first).
struct LqgModel {
  FrictionTwoMass two_mass;
  std::vector<fit::Mode> modes;
};

/// The C7.13 velocity LQG (or C7.17's load-side LQG for lqg-load) of the user's weights at one
/// (kbw, kff), and its loop.
struct LqgDesigner {
  const NormalizedPlant& plant;
  const LqgModel& model;
  VelocityLqgOptions weights;
  Structure structure = Structure::kLqg;

  [[nodiscard]] LqgDesign design(double kbw, double kff) const {
    VelocityLqgOptions w = weights;
    w.kbw = kbw;
    w.feedforward = kff;
    if (measures_load(structure)) return load_side_lqg(model.two_mass, plant.r, w);
    return velocity_lqg(model.two_mass, model.modes, plant.r, w);
  }
  [[nodiscard]] VelocityLoop loop(const LqgDesign& d) const { return compensator_loop(plant, structure, d.compensator); }
};

/// The LQG's design model: the first mode's two-mass realization with friction, extended by the
/// higher modes unless the user asked for the first mode alone.
LqgModel lqg_design_model(const NormalizedPlant& plant, const TuneOptions& options) {
  const std::optional<FrictionTwoMass> m = two_mass_realization(plant.first_mode());
  if (!m) {
    throw InputError(at_field("--structure"),
                     to_string(options.structure) + " needs a two-mass realization, and this plant has none (its "
                     "shaft damping would be negative); use --structure pi or pid");
  }
  LqgModel model{*m, {}};
  if (options.hinf_modes != ModeHandling::kFirstMode) model.modes = plant.higher_modes;
  return model;
}

std::vector<double> kbw_candidates() {
  std::vector<double> k = core::log_space(kKbwFastest, kKbwSlowest, kKbwPoints);
  std::reverse(k.begin(), k.end());
  return k;
}

/// The automatic feedforward at one kbw, what limited it, and the spec of the design with it.
struct Feedforward {
  double kff = 0.0;
  std::string source;
  TuneResult::Candidate candidate;  ///< check() at (kbw, kff)
};

/// The largest kff in [0, kFeedforwardCap] keeping the spec (C7.13: the tracking peak <= Mt):
/// doubling to the first failure, then `bisections` halvings. 0 when the loop misses the spec
/// without it.
Feedforward automatic_feedforward(const LqgDesigner& lqg, const SpecCheck& check, double kbw, int bisections) {
  const auto evaluate = [&](double kff) { return check(kbw, lqg.loop(lqg.design(kbw, kff))); };
  Feedforward best{0.0, "none: the loop misses the spec already without feedforward", evaluate(0.0)};
  if (!best.candidate.feasible) return best;
  // Keeps the largest feasible kff with its candidate; returns whether `kff` was feasible.
  const auto try_kff = [&](double kff) {
    TuneResult::Candidate c = evaluate(kff);
    const bool feasible = c.feasible;
    if (feasible) best = {kff, "", std::move(c)};
    return feasible;
  };
  double hi = 0.125;
  while (hi < kFeedforwardCap && try_kff(hi)) hi *= 2.0;
  if (hi >= kFeedforwardCap && try_kff(hi)) {
    best.source = fmt::format("capped at {:g}: the spec never binds", kFeedforwardCap);
    return best;
  }
  double lo = best.kff;
  for (int it = 0; it < bisections; ++it) {
    const double mid = 0.5 * (lo + hi);
    (try_kff(mid) ? lo : hi) = mid;
  }
  best.source = check.w2 ? "largest keeping the tracking peak <= Mt and robust tracking"
                         : "largest keeping the tracking peak <= Mt";
  return best;
}

/// The kbw giving the largest load bandwidth within the spec: each candidate is evaluated with its
/// feedforward (the given one, or the automatic one to 2^-12 of its bracket: enough to rank), since
/// the feedforward, not only the feedback, sets the tracking bandwidth; feasibility in kbw need not
/// be monotone (‖S‖∞ hovers near Ms over decades of kbw on high-r plants), so the whole scan is
/// ranked, then the boundary next to the best refined by bisection.
/// std::nullopt when no kbw meets the spec (the scan is in `scan` either way).
std::optional<double> automatic_kbw(const LqgDesigner& lqg, const SpecCheck& check,
                                    const std::optional<double>& given_kff, std::vector<TuneResult::Candidate>& scan) {
  constexpr int kRankingBisections = 12;
  const auto evaluate = [&](double kbw) {
    if (given_kff) return check(kbw, lqg.loop(lqg.design(kbw, *given_kff)));
    return automatic_feedforward(lqg, check, kbw, kRankingBisections).candidate;
  };
  scan.clear();
  for (double kbw : kbw_candidates()) scan.push_back(evaluate(kbw));
  const TuneResult::Candidate chosen = choose(scan, evaluate);
  if (!chosen.feasible) return std::nullopt;
  return chosen.omega_star;
}

/// Runs the kbw search `found()` (true when some kbw met the spec); when none does, raises the
/// Kalman filter's measurement noise `v` by decades (at most kMaxNoiseDecades, when allowed) and
/// searches again: C7.13's estimator has a fixed bandwidth (its weights do not scale with kbw), too
/// high for a loop with delay, and a larger V slows it. A note says so.
template <class Search>
void search_raising_noise(double& v, const TuneOptions& options, TuneResult& result, Search&& found) {
  constexpr int kMaxNoiseDecades = 4;
  const double printed = v;
  for (int decade = 0; !found(); ++decade) {
    if (!options.raise_measurement_noise || decade == kMaxNoiseDecades) no_feasible_omega(result.scan, options);
    v *= 10.0;
  }
  if (v != printed) {
    result.controller.notes.push_back(fmt::format(
        "no kbw met the spec with the Kalman filter's measurement noise V = {:g}: V raised to {:g} (a slower "
        "estimator; the estimator of C7.13's weights is too fast for this loop's delay or lags)",
        printed, v));
  }
}

/// Automatic kbw, the measurement noise raised where needed (search_raising_noise).
void choose_kbw(const NormalizedPlant& plant, const LqgModel& model, const TuneOptions& options,
                const SpecCheck& check, FullOrderSummary& f, TuneResult& result) {
  search_raising_noise(f.weights.measurement_noise, options, result, [&] {
    const LqgDesigner lqg{plant, model, f.weights, options.structure};
    const std::optional<double> kbw = automatic_kbw(lqg, check, options.feedforward, result.scan);
    if (kbw) f.weights.kbw = *kbw;
    return kbw.has_value();
  });
  f.kbw_source = largest_bandwidth(plant) + (options.w2 ? " with ||S|| <= Ms, tracking peak <= Mt and robust tracking"
                                                         : " with ||S|| <= Ms and tracking peak <= Mt");
}

std::string pole_list(const std::vector<std::complex<double>>& poles) {
  std::string out;
  for (const std::complex<double>& p : poles) {
    if (p.imag() < 0.0) continue;  // one of each conjugate pair
    out += (out.empty() ? "" : ", ") + (p.imag() > 0.0 ? fmt::format("{:.3g} ± {:.3g}j", p.real(), p.imag())
                                                        : fmt::format("{:.3g}", p.real()));
  }
  return out;
}

/// The common end of the full-order paths (lqg, hinf): the summary stored, the loop analysed with
/// the HF dynamics, notes when it is unstable (`knob`: what to change) or the controller itself
/// is (`kind` names it), robustness with W2. Returns the loop for what follows.
VelocityLoop finish_full_order(TuneResult& result, const TuneOptions& options, const SpecCheck& check,
                               FullOrderSummary f, const std::string& knob, const std::string& kind) {
  Controller& c = result.controller;
  AnalysisOptions analysis;
  analysis.position_outputs = is_position_controller(options.structure);
  const VelocityLoop loop = compensator_loop(result.plant, options.structure, f.compensator);
  c.predicted = analyse(result.plant, loop, analysis);
  if (!c.predicted.closed_loop_stable) c.notes.push_back("the loop with the known HF dynamics is UNSTABLE at this " + knob);
  if (!f.controller_stable) {
    c.notes.push_back(fmt::format("the {} is itself UNSTABLE (poles {}, normalized): the loop is stable only while "
                                  "closed; switch it on in closed loop and keep the torque limit out of reach "
                                  "(saturation opens the loop)",
                                  kind, pole_list(f.controller_poles)));
  }
  c.full_order = std::move(f);
  if (check.w2) add_robustness(c, loop, *check.w2, options);
  return loop;
}

/// A load-measuring design (C7.17) needs the load of a two-mass plant.
void require_two_mass_load(const NormalizedPlant& plant, Structure structure) {
  if (plant.higher_modes.empty() && two_mass_realization(plant)) return;
  const std::string motor_side = is_hinf(structure) ? "hinf" : "lqg";
  throw InputError(at_field("--structure"),
                   plant.higher_modes.empty()
                       ? fmt::format("{} measures the load of the two-mass realization, and this plant has none (its "
                                     "shaft damping would be negative); use --structure {}",
                                     to_string(structure), motor_side)
                       : fmt::format("{} (C7.17) needs a two-mass plant; this one has {} higher mode(s): use "
                                     "--structure {} (motor feedback, C7.16)",
                                     to_string(structure), plant.higher_modes.size(), motor_side));
}

/// The LQG path of tune(): kbw and kff, the compensator, its analysis and robustness.
void tune_lqg(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  const NormalizedPlant& plant = result.plant;
  if (measures_load(options.structure)) require_two_mass_load(plant, options.structure);
  const LqgModel model = lqg_design_model(plant, options);
  Controller& c = result.controller;
  FullOrderSummary f;
  f.weights = options.lqg;
  if (options.kbw) {
    f.weights.kbw = *options.kbw;
    f.kbw_source = "given";
  } else {
    choose_kbw(plant, model, options, check, f, result);
  }
  const LqgDesigner lqg{plant, model, f.weights, options.structure};
  if (options.feedforward) {
    f.weights.feedforward = *options.feedforward;
    f.feedforward_source = "given";
  } else {
    const Feedforward ff = automatic_feedforward(lqg, check, f.weights.kbw, kFeedforwardBisections);
    f.weights.feedforward = ff.kff;
    f.feedforward_source = ff.source;
  }
  const LqgDesign d = lqg.design(f.weights.kbw, f.weights.feedforward);
  f.compensator = d.compensator;
  f.controller_poles = d.controller_poles;
  f.controller_stable = d.controller_stable;
  const VelocityLoop loop = finish_full_order(result, options, check, std::move(f), "kbw: choose a larger one",
                                              "LQG compensator");
  if (options.structure == Structure::kLqgP) add_position_loop(c, loop, check.w2, plant);
}

// ------------------------------------------------------------------- position controllers

/// C7.13's reference prefilter of a position controller: the smallest τ keeping the judged
/// position (the load's, else the motor's) free of overshoot on the loop with the HF dynamics,
/// put in front of the compensator's reference input (its pole joins the controller's).
void add_prefilter(const NormalizedPlant& plant, const SpecCheck& check, FullOrderSummary& f) {
  const VelocityLoop loop = compensator_loop(plant, check.options.structure, f.compensator);
  if (!loop.stable()) return;  // finish_full_order says so; no prefilter can help
  constexpr double kFinalPrefilterTolerance = 1e-9;
  const std::optional<double> tau = check.prefilter(check.judged_tracking(loop), kFinalPrefilterTolerance);
  if (!tau) {
    throw InputError(at_field("--structure"),
                     "no reference prefilter keeps the position free of overshoot (the loop's static gain exceeds 1)");
  }
  f.prefilter_tau = *tau;
  if (*tau == 0.0) return;
  f.compensator = with_prefilter(f.compensator, *tau);
  f.controller_poles.push_back(Complex(-1.0 / *tau, 0.0));
}

/// The C7.13 position LQG of the user's weights at one kbw, and its loop (velocity form).
struct PositionLqgDesigner {
  const NormalizedPlant& plant;
  const FrictionTwoMass& model;
  PositionLqgOptions weights;

  [[nodiscard]] LqgDesign design(double kbw) const {
    PositionLqgOptions w = weights;
    w.kbw = kbw;
    return position_lqg(model, plant.r, w);
  }
  [[nodiscard]] VelocityLoop loop(const LqgDesign& d) const {
    return compensator_loop(plant, Structure::kLqgPos, d.compensator);
  }
};

/// The automatic kbw of the position LQG (the velocity's search without feedforward: the
/// reference enters through the integral state), V raised by decades when nothing meets the spec.
void choose_position_kbw(const NormalizedPlant& plant, const FrictionTwoMass& model, const TuneOptions& options,
                         const SpecCheck& check, PositionLqgOptions& weights, FullOrderSummary& f, TuneResult& result) {
  search_raising_noise(weights.measurement_noise, options, result, [&] {
    const PositionLqgDesigner lqg{plant, model, weights};
    const auto evaluate = [&](double kbw) { return check(kbw, lqg.loop(lqg.design(kbw))); };
    result.scan.clear();
    for (double kbw : kbw_candidates()) result.scan.push_back(evaluate(kbw));
    const TuneResult::Candidate chosen = choose(result.scan, evaluate);
    if (chosen.feasible) weights.kbw = chosen.omega_star;
    return chosen.feasible;
  });
  f.kbw_source = largest_bandwidth(plant) + " of the position with its prefilter, " +
                 (options.w2 ? "||S|| <= Ms, unfiltered tracking peak <= Mt and robust performance"
                             : "||S|| <= Ms and unfiltered tracking peak <= Mt");
}

/// The lqg-pos path of tune(): kbw, the compensator of C7.13 on the first mode's two-mass
/// realization (position_lqg has no extended model), its prefilter, analysis and robustness.
void tune_lqg_position(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  const NormalizedPlant& plant = result.plant;
  TuneOptions first_mode = options;
  first_mode.hinf_modes = ModeHandling::kFirstMode;
  const LqgModel model = lqg_design_model(plant, first_mode);
  FullOrderSummary f;
  PositionLqgOptions weights = options.lqg_position;
  if (options.kbw) {
    weights.kbw = *options.kbw;
    f.kbw_source = "given";
  } else {
    choose_position_kbw(plant, model.two_mass, options, check, weights, f, result);
  }
  f.feedforward_source = "none: the position reference enters through the integral state and the prefilter";
  const LqgDesign d = PositionLqgDesigner{plant, model.two_mass, weights}.design(weights.kbw);
  f.position_weights = weights;
  f.compensator = d.compensator;
  f.controller_poles = d.controller_poles;
  f.controller_stable = d.controller_stable;
  add_prefilter(plant, check, f);
  (void)finish_full_order(result, options, check, std::move(f), "kbw: choose a larger one", "LQG compensator");
}

// ------------------------------------------------------------------------------------ hinf

/// w0S candidates of the automatic search (normalized), and the w0T ladder of C7.14.
constexpr double kOmega0sSlowest = 0.05, kOmega0sFastestPerR = 2.0;
constexpr std::size_t kOmega0sPoints = 20;
constexpr int kOmega0tSteps = 4;  // r, 2r, 4r, 8r

/// The C7.14 design at (w0S, w0T) on the first mode, and its loop with the HF dynamics.
struct HinfDesigner {
  const NormalizedPlant& plant;
  NormalizedPlant design_plant;  // the plant, or its first mode for ModeHandling::kFirstMode
  const TuneOptions& options;

  /// `final`: the design returned (its minimal realization); the search's candidates skip it.
  [[nodiscard]] HinfDesign design(double omega_0s, double omega_0t, bool final = false) const {
    VelocityHinfWeights w;
    w.minimal_realization = final;
    w.omega_0s = omega_0s;
    w.omega_0t = omega_0t;
    w.xi_v = options.xi_v;
    w.ms = options.ms;
    w.mt = options.mt;
    w.modes = options.hinf_modes;
    w.controller_order = options.controller_order;
    if (options.rolloff_rad_s) w.rolloff = *options.rolloff_rad_s / plant.omega_z;
    if (measures_load(options.structure)) return load_side_hinf(design_plant, w);
    return is_position_controller(options.structure) ? position_hinf(design_plant, w) : velocity_hinf(design_plant, w);
  }
  [[nodiscard]] VelocityLoop loop(const HinfDesign& d) const {
    return compensator_loop(plant, options.structure, d.compensator);
  }
};

/// One w0S: the first w0T of the ladder (or the given one) whose design meets the spec; when none
/// does, the tried one closest to it (closer_to_spec).
struct HinfCandidate {
  TuneResult::Candidate candidate;
  double omega_0t = 0.0;
};

/// Of two infeasible candidates, the one closer to the spec: meeting the peak limits first, then
/// the larger least damping (what --min-damping's error message reports).
bool closer_to_spec(const TuneResult::Candidate& a, const TuneResult::Candidate& b, const TuneOptions& o) {
  const auto peaks_ok = [&](const TuneResult::Candidate& c) { return c.stable && c.peak_s <= o.ms && c.peak_tracking <= o.mt; };
  if (peaks_ok(a) != peaks_ok(b)) return peaks_ok(a);
  return a.min_damping > b.min_damping;
}

/// One w0S with the w0T ladder r, 2r, 4r, 8r from `start_omega_0t` up (C7.14's loop raises w0T on
/// failure and keeps it when w0S is raised: a faster pair never gets a lower cap than a slower one
/// needed). The given --omega-0t alone when set.
HinfCandidate evaluate_hinf(const HinfDesigner& h, const SpecCheck& check, double omega_0s, double start_omega_0t) {
  const double r = h.design_plant.r;
  HinfCandidate out;
  std::optional<HinfCandidate> closest;
  for (int step = 0; step < (h.options.omega_0t ? 1 : kOmega0tSteps); ++step) {
    out.omega_0t = h.options.omega_0t.value_or(r * std::ldexp(1.0, step));
    if (!h.options.omega_0t && step + 1 < kOmega0tSteps && out.omega_0t < start_omega_0t * (1.0 - 1e-9)) continue;
    try {
      out.candidate = check(omega_0s, h.loop(h.design(omega_0s, out.omega_0t)));
    } catch (const std::domain_error&) {
      out.candidate = {};  // no controller for these weights: an unstable candidate
      out.candidate.omega_star = omega_0s;
    } catch (const InputError& e) {
      if (e.where().field != "controller_order") throw;
      out.candidate = {};  // more unstable controller poles than the order asked for
      out.candidate.omega_star = omega_0s;
    }
    if (out.candidate.feasible) return out;
    if (!closest || closer_to_spec(out.candidate, closest->candidate, h.options)) closest = out;
  }
  return closest.value_or(out);
}

/// Where the w0T ladder starts for `omega_0s` (C7.14's loop keeps w0T when w0S is raised): one
/// rung below the w0T of the nearest slower design that met the spec, since a faster pair can pass
/// a lower cap again (C7.16's active design does); at that w0T itself between it and a faster w0S
/// that no rung rescued, where the lower rungs failed on both sides (the boundary bisections). r
/// when no slower design met the spec. `evaluated`: every w0S designed so far.
double ladder_start(const std::map<double, HinfCandidate>& evaluated, double omega_0s) {
  const auto faster = evaluated.upper_bound(omega_0s);
  for (auto slower = std::make_reverse_iterator(faster); slower != evaluated.rend(); ++slower) {
    if (!slower->second.candidate.feasible) continue;
    const double carried = slower->second.omega_0t;
    const bool bracketed = faster != evaluated.end() && !faster->second.candidate.feasible;
    return bracketed ? carried : 0.5 * carried;
  }
  return 0.0;
}

/// What the design did with the higher modes (C7.16).
std::string higher_modes_note(const TuneOptions& o, const std::vector<fit::Mode>& modes) {
  const std::size_t count = modes.size();
  const bool hinf = is_hinf(o.structure);
  std::string unobservable;
  for (std::size_t i = 0; i < count; ++i)
    if (practically_unobservable(modes[i]))
      unobservable += fmt::format("{}mode {} ({:.4g}/{:.4g} omega_z)", unobservable.empty() ? "" : ", ", i + 2,
                                  modes[i].resonance.omega_rad_s, modes[i].antiresonance.omega_rad_s);
  const std::string except =
      unobservable.empty()
          ? std::string()
          : "; except " + unobservable +
                ": resonance within 1 % of its antiresonance, practically unobservable from the motor, left out of "
                "the design (damping it needs another sensor, e.g. a frame accelerometer)";
  if (hinf && o.hinf_modes == ModeHandling::kActive)
    return fmt::format("designed on the full model: the {} higher mode(s) are damped actively (C7.16, V extended "
                       "as eq. 7.164), at a larger controller gain at their frequencies{}",
                       count, except);
  if (hinf && o.hinf_modes == ModeHandling::kPassive)
    return fmt::format("designed on the full model: the controller cancels the {} higher mode(s) (a notch; "
                       "C7.16 passive): disturbances at the motor still excite them{}",
                       count, except);
  if (is_full_order(o.structure) && o.structure != Structure::kLqgPos && o.hinf_modes != ModeHandling::kFirstMode)
    return fmt::format("designed on the full model: the {} higher mode(s) extend the LQG's design model (C7.16), "
                       "unweighted, so the regulator and the Kalman filter know them", count);
  return fmt::format("designed on the first mode; {} higher mode(s) are included in every index", count);
}

/// The hinf path of tune(): w0S and w0T, the compensator, its analysis and robustness.
void tune_hinf(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  const NormalizedPlant& plant = result.plant;
  if (measures_load(options.structure)) require_two_mass_load(plant, options.structure);
  // With the known HF dynamics; C7.16 decides on the modes.
  const HinfDesigner h{plant, options.hinf_modes == ModeHandling::kFirstMode ? plant.first_mode() : plant, options};
  HinfSummary s;
  s.xi_v = options.xi_v;
  s.modes = plant.higher_modes.empty() ? ModeHandling::kFirstMode : options.hinf_modes;
  if (options.rolloff_rad_s) s.rolloff = *options.rolloff_rad_s / plant.omega_z;
  std::map<double, HinfCandidate> evaluated;  // w0S -> its design's spec and w0T
  if (options.omega_0s) {
    s.omega_0s = *options.omega_0s;
    s.omega_0s_source = "given";
  } else {
    const auto evaluate = [&](double w) {
      // The boundary bisections revisit w0S: each is designed once.
      if (const auto seen = evaluated.find(w); seen != evaluated.end()) return seen->second.candidate;
      return evaluated.emplace(w, evaluate_hinf(h, check, w, ladder_start(evaluated, w))).first->second.candidate;
    };
    // C7.14's loop: raise w0S while some w0T meets the spec (w0T kept from the last success, raised
    // on failure); stop after two w0S in a row that no w0T of the ladder rescues (a faster pair
    // only raises the peaks further). Keeping w0T saves the ladder's lower rungs, which a faster
    // pair rarely passes again: 4-6x fewer syntheses than restarting each w0S at r.
    bool met = false;
    int misses = 0;
    const double fastest = kOmega0sFastestPerR * plant.r;
    for (double w : core::log_space(kOmega0sSlowest, fastest, kOmega0sPoints)) {
      result.scan.push_back(evaluate(w));
      met = met || result.scan.back().feasible;
      misses = result.scan.back().feasible ? 0 : misses + 1;
      // Load feedback (C7.17) has no such monotony: a band of low w0S can fail between feasible ones.
      if (met && misses == 2 && !measures_load(options.structure)) break;
    }
    constexpr int kBoundarySteps = 8;  // scan points 1.3 apart: 0.1 % in w0S
    TuneResult::Candidate chosen = choose(result.scan, evaluate, kBoundarySteps);
    if (!chosen.feasible) no_feasible_omega(result.scan, options);
    // The w0T ladder makes the bandwidth jump along w0S: the upper end of the feasible range may
    // beat the best scanned point even when its neighbour is feasible (when it is the best, this
    // bisection repeats the one above: `evaluated` answers it).
    std::size_t last = 0;
    for (std::size_t i = 0; i < result.scan.size(); ++i)
      if (result.scan[i].feasible) last = i;
    if (last + 1 < result.scan.size())
      refine_boundary(result.scan[last].omega_star, result.scan[last + 1].omega_star, evaluate, chosen, kBoundarySteps);
    s.omega_0s = chosen.omega_star;
    s.omega_0s_source = largest_bandwidth(plant) + (options.w2 ? " with ||S|| <= Ms, peak <= Mt and robust performance"
                                                               : " with ||S|| <= Ms and peak <= Mt");
    if (chosen.omega_star >= fastest * (1.0 - 1e-9)) {
      s.omega_0s_source = fmt::format("the search's end 2r = {:.4g} (the spec did not bind)", fastest);
      result.controller.notes.push_back(fmt::format(
          "w0S stopped at the end of its search, 2r = {:.4g} omega_z, with the spec still met{}: a faster loop costs "
          "controller gain (noise); give --omega-0s to go further",
          fastest, measures_load(options.structure) ? " (load feedback has no antiresonance limit, C7.17)" : ""));
    }
  }
  if (options.omega_0t) {
    s.omega_0t = *options.omega_0t;
  } else {
    const auto found = evaluated.find(s.omega_0s);
    s.omega_0t = found != evaluated.end() ? found->second.omega_0t : evaluate_hinf(h, check, s.omega_0s, 0.0).omega_0t;
  }
  HinfDesign d;
  try {
    d = h.design(s.omega_0s, s.omega_0t, true);
  } catch (const std::domain_error& e) {
    throw InputError(at_field(options.omega_0s ? "--omega-0s" : "--structure"),
                     fmt::format("no H-infinity controller for w0S = {:.4g}, w0T = {:.4g} ({}); try other weights or "
                                 "--omega-0s auto",
                                 s.omega_0s, s.omega_0t, e.what()));
  } catch (const InputError& e) {
    if (e.where().field != "controller_order") throw;
    throw InputError(at_field("--controller-order"), e.reason());
  }
  s.gamma_optimal = d.gamma_optimal;
  s.gamma = d.gamma;
  s.full_order = d.full_order;
  s.hankel = d.hankel;
  s.reduction_error_bound = d.reduction_error_bound;
  FullOrderSummary f;
  f.hinf = s;
  f.compensator = d.compensator;
  f.controller_poles = d.controller_poles;
  f.controller_stable = d.controller_stable;
  if (is_position_controller(options.structure)) add_prefilter(plant, check, f);
  (void)finish_full_order(result, options, check, std::move(f), "w0S: choose a smaller one", "H-infinity controller");
  if (!result.advice.verdict.empty()) result.controller.notes.push_back(result.advice.verdict);
}

/// The bandwidth the automatic searches compare: the load's where there is one, else the motor's.
double compared_bandwidth(const LoopIndices& i) {
  return std::isfinite(i.bandwidth_load) ? i.bandwidth_load : i.bandwidth_motor;
}

void tune_cascade(TuneResult& result, const TuneOptions& options, const SpecCheck& check);

/// PID with an automatic r̄: tuned at r̄ = 2 and at r̄ toward 0.9 r (a smaller derivative gain),
/// the largest bandwidth kept; the error of r̄ = 2 when none meets the spec.
void tune_pid_automatic_ratio(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  const double r = result.plant.r;
  std::vector<double> ratios{kDefaultTargetR};
  const double top = kTargetRFractionOfR * r;
  for (std::size_t k = 1; top > kDefaultTargetR && k < kTargetRCandidates; ++k)
    ratios.push_back(kDefaultTargetR * std::pow(top / kDefaultTargetR, static_cast<double>(k) /
                                                                        static_cast<double>(kTargetRCandidates - 1)));
  std::optional<TuneResult> best;
  double at_default = std::numeric_limits<double>::quiet_NaN();
  for (const double ratio : ratios) {
    TuneOptions o = options;
    o.target_r = ratio;
    TuneResult trial = result;
    try {
      tune_cascade(trial, o, check);
    } catch (const InputError&) {
      continue;  // no ω* meets the spec at this r̄
    }
    const double bandwidth = compared_bandwidth(trial.controller.predicted);
    if (ratio == kDefaultTargetR) at_default = bandwidth;
    if (!best || bandwidth > compared_bandwidth(best->controller.predicted)) best = std::move(trial);
  }
  if (!best) {
    TuneOptions o = options;
    o.target_r = kDefaultTargetR;
    tune_cascade(result, o, check);  // throws the spec's error at r̄ = 2
    return;
  }
  result = std::move(*best);
  const double chosen = *result.controller.design.r_target;
  result.controller.notes.push_back(fmt::format(
      "r-bar chosen automatically: {:.3g} of {} tried between 2 and {:.3g} (largest bandwidth: {:.3g} Hz; r-bar = 2: {})",
      chosen, ratios.size(), ratios.back(), result.plant.physical_frequency(compared_bandwidth(result.controller.predicted)) /
                                                 (2.0 * std::numbers::pi),
      std::isfinite(at_default) ? fmt::format("{:.3g} Hz", result.plant.physical_frequency(at_default) / (2.0 * std::numbers::pi))
                                : std::string("no omega* meets the spec")));
}

/// The cascade path of tune() (pi, pid, pi+p): ω*, the gains, their analysis and robustness.
void tune_cascade(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  const NormalizedPlant& plant = result.plant;
  Controller& c = result.controller;
  c.drive_filters.clear();
  for (const DriveFilterSpec& spec : options.drive_filters)
    c.drive_filters.push_back(make_drive_filter(spec, options.ts, "--drive-filter"));
  const std::optional<core::TransferFunction> filter =
      c.drive_filters.empty() ? std::nullopt
                              : std::optional(to_normalized_time(filter_chain(c.drive_filters), plant.omega_z));
  const GainDesigner design{plant, options, filter ? &*filter : nullptr};
  const auto evaluate = [&](double w) {
    PidGains g;
    try {
      g = design(w);
    } catch (const InputError&) {
      // The pair cannot be placed at this ω* (it sits on a zero of plant × filters): infeasible.
      TuneResult::Candidate none;
      none.omega_star = w;
      return none;
    }
    const ControllerTf k = pid_controller(g);
    return check(w, VelocityLoop(plant, filter ? with_output_filter(k, *filter) : k));
  };
  const double kd =
      options.structure == Structure::kPid ? virtual_inertia_kd(plant.r, options.target_r.value_or(kDefaultTargetR)) : 0.0;
  result.range = admissible_range(plant, options.zeta_star, kd);
  if (result.range.empty()) {
    throw InputError(at_field("--zeta-star"),
                     fmt::format("no admissible omega* for zeta* = {} on r = {:.3f} (the second pole pair is "
                                 "slower than the assigned one everywhere); lower --zeta-star",
                                 options.zeta_star, plant.r));
  }
  c.design.zeta_star = options.zeta_star;
  if (options.structure == Structure::kPid) c.design.r_target = options.target_r.value_or(kDefaultTargetR);

  if (options.omega_star) {
    const double w = *options.omega_star;
    if (w < result.range.omega_min || w > result.range.omega_max) {
      throw InputError(at_field("--omega-star"),
                       fmt::format("omega*/omega_z = {} lies outside the admissible range [{:.4g}, {:.4g}] "
                                   "(upper end: {}); choose inside it or use --omega-star auto",
                                   w, result.range.omega_min, result.range.omega_max, to_string(result.range.upper)));
    }
    c.design.omega_star = w;
    c.design.omega_star_source = "given";
  } else {
    result.scan.clear();
    for (double w : candidates(result.range, options.scan_points)) result.scan.push_back(evaluate(w));
    const TuneResult::Candidate chosen = choose(result.scan, evaluate);
    if (!chosen.feasible) no_feasible_omega(result.scan, options);
    c.design.omega_star = chosen.omega_star;
    c.design.omega_star_source =
        largest_bandwidth(plant) + (options.w2 ? " with ||S|| <= Ms, peak <= Mt and robust performance"
                                               : " with ||S|| <= Ms and peak <= Mt");
  }
  c.normalized = design(c.design.omega_star, &c.notes);
  c.physical = to_physical(c.normalized, plant);
  if (filter)
    c.notes.push_back("the admissible omega* range is the design plant's without the drive filters (C7.3); the "
                      "search and the analysis include them");
  const VelocityLoop loop = controller_loop(plant, c);
  c.predicted = analyse(plant, loop, {});
  if (!c.predicted.closed_loop_stable) {
    c.notes.push_back("the loop with the known HF dynamics is UNSTABLE at this omega*: choose a smaller one");
  }
  if (check.w2) add_robustness(c, loop, *check.w2, options);
  if (options.structure == Structure::kPiP) add_position_loop(c, loop, check.w2, plant);
  if (!result.advice.verdict.empty()) c.notes.push_back(result.advice.verdict);
}

/// pi, pid (automatic r̄ or not), pi+p.
void tune_cascade_structure(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  if (options.structure == Structure::kPid && !options.target_r) {
    tune_pid_automatic_ratio(result, options, check);
  } else {
    tune_cascade(result, options, check);
  }
}

std::string hz(const NormalizedPlant& plant, double omega) {
  return fmt::format("{:.4g} Hz", plant.physical_frequency(omega) / (2.0 * std::numbers::pi));
}

/// notch:auto (auto_notch.hpp): the cascade tuned with each candidate notch on the target mode,
/// the largest bandwidth kept; without a target, or when no candidate meets the spec, a note says
/// why and the design goes on without the notch. The design without it is tuned too, to report
/// what the notch gained.
void tune_cascade_with_auto_notch(TuneResult& result, const TuneOptions& options, const SpecCheck& check) {
  const NormalizedPlant& plant = result.plant;
  const std::optional<detail::NotchTarget> target = detail::notch_target(plant);
  const std::vector<DriveFilterSpec> notches =
      target ? detail::notch_candidates(*target, plant.omega_z, *options.ts) : std::vector<DriveFilterSpec>{};
  std::optional<TuneResult> without;
  try {
    without = result;
    tune_cascade_structure(*without, options, check);
  } catch (const InputError&) {
    without.reset();
  }
  std::optional<TuneResult> best;
  for (const DriveFilterSpec& notch : notches) {
    TuneOptions o = options;
    o.drive_filters.push_back(notch);
    TuneResult trial = result;
    try {
      tune_cascade_structure(trial, o, check);
    } catch (const InputError&) {
      continue;
    }
    if (!best || compared_bandwidth(trial.controller.predicted) > compared_bandwidth(best->controller.predicted))
      best = std::move(trial);
  }
  const auto bandwidth = [&](const TuneResult& r) { return hz(plant, compared_bandwidth(r.controller.predicted)); };
  if (!best) {
    if (!without) {
      tune_cascade_structure(result, options, check);  // throws the spec's error
      throw InputError(at_field("--drive-filter"), "notch:auto: no design meets the spec with or without a notch");
    }
    result = std::move(*without);
    result.controller.notes.push_back(
        !target ? "notch:auto: no notch placed: the PI damps the first mode itself (r within sqrt(3)..sqrt(5), "
                  "catalog C7.4) and there is no higher mode"
        : notches.empty()
            ? fmt::format("notch:auto: no notch placed: the target, {} at {}, lies at or above the Nyquist frequency "
                          "of --ts",
                          target->reason, hz(plant, target->omega))
            : fmt::format("notch:auto: no notch placed: no candidate on {} at {} meets the spec", target->reason,
                          hz(plant, target->omega)));
    return;
  }
  if (without && compared_bandwidth(without->controller.predicted) >= compared_bandwidth(best->controller.predicted)) {
    // A notch that gains nothing only costs phase and robustness to the mode's shift: none placed.
    const std::string gained = bandwidth(*best);
    result = std::move(*without);
    result.controller.notes.push_back(fmt::format(
        "notch:auto: no notch placed: on {} at {} the best of {} widths reaches {} bandwidth {}, not more than the {} "
        "without (the PI is not limited by this mode)",
        target->reason, hz(plant, target->omega), notches.size(), plant.load_estimate() ? "load" : "motor", gained,
        bandwidth(result)));
    return;
  }
  result = std::move(*best);
  DriveFilter& notch = result.controller.drive_filters.back();
  notch.reason = target->reason;
  result.controller.notes.push_back(fmt::format(
      "notch:auto: a notch at {:.4g} Hz, width {:.3g} Hz, depth {:.3g} dB on {} (best of {} widths); {} bandwidth "
      "{} with it, {} without",
      notch.spec.frequency_hz, notch.spec.width_hz, notch.spec.depth_db, target->reason, notches.size(),
      plant.load_estimate() ? "load" : "motor", bandwidth(result),
      without ? bandwidth(*without) : std::string("no omega* meeting the spec")));
}

}  // namespace

TuneResult tune(const fit::PlantModel& model, const TuneOptions& given) {
  validate(given);
  TuneOptions options = given;
  if (is_hinf(options.structure) && !options.drive_filters.empty()) {
    // The H-infinity roll-off is its one drive filter (validate_drive_filters), designed with.
    options.rolloff_rad_s = 2.0 * std::numbers::pi * options.drive_filters.front().frequency_hz;
    options.drive_filters.clear();
  }
  TuneResult result;
  result.plant = normalize(model, options.hf);
  result.plant.chain_load = options.chain_load;
  const NormalizedPlant& plant = result.plant;
  result.advice = advise(plant.r, options.zeta_star);
  if (plant.r < kRatioForPassiveMethods) {
    throw InputError(at_field("plant"),
                     fmt::format("resonance ratio r = {:.3f} < {}: a PI/PID cannot damp this mode (catalog C7.4) and "
                                 "a full-order design gains little; recommend passive methods: a notch filter or an "
                                 "input shaper (servotwin shaper)",
                                 plant.r, kRatioForPassiveMethods));
  }
  std::optional<core::TransferFunction> w2_normalized;
  if (options.w2) w2_normalized = to_normalized_time(*options.w2, plant.omega_z);
  const std::vector<double> grid = scan_grid(plant);
  std::vector<double> bandwidth_grid{0.0};
  bandwidth_grid.insert(bandwidth_grid.end(), grid.begin(), grid.end());
  const SpecCheck check{plant, options, w2_normalized, grid, bandwidth_grid};
  Controller& c = result.controller;
  c.structure = options.structure;
  c.plant = scales(plant);
  c.design.ms = options.ms;
  c.design.mt = options.mt;
  c.design.min_damping = options.min_damping;
  if (is_hinf(options.structure)) {
    tune_hinf(result, options, check);
  } else if (options.structure == Structure::kLqgPos) {
    tune_lqg_position(result, options, check);
  } else if (is_full_order(options.structure)) {
    tune_lqg(result, options, check);
  } else if (options.auto_notch) {
    tune_cascade_with_auto_notch(result, options, check);
  } else {
    tune_cascade_structure(result, options, check);
  }
  if (!plant.higher_modes.empty()) c.notes.push_back(higher_modes_note(options, plant.higher_modes));
  // The note matters where a load side is used: the loop's load numbers, the LQG's design model or
  // the position loop (both on the first mode's realization).
  const bool lqg = is_lqg(options.structure);
  const bool uses_load =
      plant.load_estimate() || lqg || controls_position(options.structure) || measures_load(options.structure);
  if (const std::optional<std::string> note = estimated_load_note(plant); note && uses_load) c.notes.push_back(*note);
  if (options.min_damping && c.predicted.min_damping < *options.min_damping)
    c.notes.push_back(fmt::format("least closed-loop damping {:.3g} is below --min-damping {:.3g}: the given design "
                                  "parameter was kept (the automatic search enforces the floor)",
                                  c.predicted.min_damping, *options.min_damping));
  if (!plant.higher_modes.empty() && !plant.load_estimate() && !options.min_damping &&
      c.predicted.min_damping < kLowDampingNote)
    c.notes.push_back(fmt::format(
        "least closed-loop damping {:.3g}: without a load side the search maximizes the motor bandwidth and may "
        "leave a closed-loop mode (near an antiresonance or a higher resonance) ringing in the load or the frame "
        "while the motor is quiet; --min-damping 0.15 trades bandwidth for damping",
        c.predicted.min_damping));
  if (options.ts) add_discrete(c, *options.ts);
  return result;
}

}  // namespace servotwin::tuning
