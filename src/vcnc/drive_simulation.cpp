#include "servotwin/vcnc/drive_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <fmt/format.h>

#include "servotwin/core/error.hpp"

namespace servotwin::vcnc {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kMinSamples = 200;
constexpr double kMaxSamples = 1e7;
/// Share of the run at its end over which the final error and the residual oscillation are taken.
constexpr double kTailShare = 0.1;
/// A position loop settles in a few 1/Kpp; the velocity loop's horizon may be shorter.
constexpr double kPositionTimeConstants = 15.0;

[[noreturn]] void fail(const std::string& field, const std::string& expected) {
  throw core::InputError(core::at_field(field), "expected " + expected);
}

void check_settings(const DriveSimulationSettings& s) {
  if (!(std::isfinite(s.amplitude) && s.amplitude > 0.0)) fail("amplitude", "a finite step height > 0");
  if (!(std::isfinite(s.duration_s) && s.duration_s >= 0.0)) fail("duration_s", "a finite time >= 0 (0: automatic)");
  if (s.torque_limit && !(std::isfinite(*s.torque_limit) && *s.torque_limit > 0.0))
    fail("torque_limit", "a finite torque > 0");
  if (!(std::isfinite(s.settling_band) && s.settling_band > 0.0 && s.settling_band < 1.0))
    fail("settling_band", "a fraction in (0, 1)");
}

bool is_position_loop(const tuning::Controller& c) { return tuning::has_position_loop(c.structure); }

/// A position controller settles within its analysis horizon, which judges positions; its
/// prefilter (C7.13) adds a few of its time constants.
double position_controller_duration(const tuning::Controller& c) {
  const double tau = c.full_order ? c.full_order->prefilter_tau / c.plant.omega_z : 0.0;
  return kPositionTimeConstants * tau;
}

bool is_position_output(machine::PlantOutput o) {
  return o == machine::PlantOutput::MotorPosition || o == machine::PlantOutput::LoadPosition;
}
bool is_load_output(machine::PlantOutput o) {
  return o == machine::PlantOutput::LoadVelocity || o == machine::PlantOutput::LoadPosition;
}

/// The plant as the controller measures it: a load-measuring controller (C7.17) reads the load, so a
/// plant that measures the motor is run with its encoder moved to the load (a note says so).
machine::PlantConfig as_measured(const machine::PlantConfig& plant, const tuning::Controller& controller,
                                 std::vector<std::string>& notes) {
  if (!tuning::measures_load(controller.structure)) return plant;
  const auto* chain = std::get_if<machine::MassChain>(&plant.model);
  if (!chain || chain->masses() < 2)
    fail("model", "a mass chain with a load for the " + tuning::to_string(controller.structure) +
                      " controller, which measures the load");
  if (tuning::measures_both(controller.structure)) {
    notes.push_back(fmt::format("the controller measures both velocities: the plant's sensor reads the {}, a second "
                                "encoder of the same resolution (no noise) the {} side",
                                machine::to_string(plant.settings.output),
                                is_load_output(plant.settings.output) ? "motor" : "load"));
    return plant;
  }
  if (is_load_output(plant.settings.output)) return plant;
  machine::PlantConfig moved = plant;
  moved.settings.output = is_position_output(plant.settings.output) ? machine::PlantOutput::LoadPosition
                                                                    : machine::PlantOutput::LoadVelocity;
  notes.push_back(fmt::format("the controller measures the load: the plant's measured output moved from {} to {} (its "
                              "noise and quantization apply there)",
                              machine::to_string(plant.settings.output), machine::to_string(moved.settings.output)));
  return moved;
}

/// The measured output must be on the side the controller feeds back: the motor for the cascade
/// and the motor-feedback full-order controllers.
void check_plant(const machine::PlantConfig& plant, const tuning::Controller& controller, DriveTest test) {
  const auto output = plant.settings.output;
  if (is_load_output(output) && !tuning::measures_load(controller.structure))
    fail("settings.output", fmt::format("a motor-side output (motor_velocity or motor_position) for the cascade "
                                        "controller, which feeds back the motor; the plant measures {}",
                                        machine::to_string(output)));
  if (test == DriveTest::kLoadStep && !has_load_torque_input(plant))
    fail("model", "a mass chain for the load-step test: a transfer-function plant has no load-torque input");
  if (is_position_loop(controller) && !controller.kpp_physical)
    fail("controller.kpp_physical", "the position gain of a " + tuning::to_string(controller.structure) + " controller");
}

/// Turns the plant's measurement into the motor velocity and position the controller reads.
class FeedbackReader {
 public:
  FeedbackReader(machine::PlantOutput output, double ts, double y0)
      : position_output_(is_position_output(output)), ts_(ts), previous_(y0),
        position_(position_output_ ? y0 : 0.0) {}

  void read(double y) noexcept {
    if (position_output_) {
      velocity_ = (y - previous_) / ts_;  // a drive differences its encoder
      position_ = y;
    } else {
      position_ += 0.5 * ts_ * (y + previous_);  // trapezoidal integral of the velocity
      velocity_ = y;
    }
    previous_ = y;
  }
  [[nodiscard]] double velocity() const noexcept { return velocity_; }
  [[nodiscard]] double position() const noexcept { return position_; }

 private:
  bool position_output_;
  double ts_;
  double previous_;
  double velocity_ = 0.0;
  double position_;
};

/// The plant's sensor on the other side of the shaft, for a controller measuring both velocities:
/// the true motor or load signal of the same kind (velocity or position), quantized like the sensor.
class SecondEncoder {
 public:
  explicit SecondEncoder(const machine::PlantSettings& s)
      : load_(!is_load_output(s.output)), position_(is_position_output(s.output)), q_(s.quantization) {}

  [[nodiscard]] double read(const machine::PlantMeasurement& m) const noexcept {
    const double exact = load_ ? (position_ ? m.load_position : m.load_velocity)
                               : (position_ ? m.motor_position : m.motor_velocity);
    return q_ > 0.0 ? q_ * std::round(exact / q_) : exact;
  }
  /// True when it reads the load (the plant's sensor the motor).
  [[nodiscard]] bool reads_load() const noexcept { return load_; }
  /// What it reads, as a plant output.
  [[nodiscard]] machine::PlantOutput output() const noexcept {
    using machine::PlantOutput;
    if (load_) return position_ ? PlantOutput::LoadPosition : PlantOutput::LoadVelocity;
    return position_ ? PlantOutput::MotorPosition : PlantOutput::MotorVelocity;
  }

 private:
  bool load_, position_;
  double q_;
};

/// The discrete controller with inputs [ω*, y] or [ω*, ωm, ωl], its torque limit and conditional
/// integration.
class LimitedController {
 public:
  /// `running_states`: the trailing states that keep running while the limit is active (the drive
  /// filters at the controller's output, which a drive runs whatever its command; the gains'
  /// states before them stop: conditional integration).
  LimitedController(const core::DiscreteStateSpace& c, std::optional<double> limit, Eigen::Index running_states = 0)
      : c_(c), limit_(limit), x_(Eigen::VectorXd::Zero(c.states())), next_(x_), both_(c.B.cols() == 3),
        frozen_(c.states() - std::clamp<Eigen::Index>(running_states, 0, c.states())) {}

  /// The torque command for this sample; advances the states, those of the gains only while the
  /// limit is inactive. `load` is read only by a controller with three inputs ([ω*, ωm, ωl];
  /// `measured` is then ωm).
  double update(double reference, double measured, double load = 0.0) noexcept {
    double raw = c_.C.row(0).dot(x_) + c_.D(0, 0) * reference + c_.D(0, 1) * measured;
    if (both_) raw += c_.D(0, 2) * load;
    double u = raw;
    limited_ = false;
    if (limit_ && std::abs(raw) > *limit_) {
      u = std::copysign(*limit_, raw);
      limited_ = true;
    }
    if (!limited_ || frozen_ < c_.states()) {
      next_.noalias() = c_.A * x_;
      next_ += c_.B.col(0) * reference + c_.B.col(1) * measured;
      if (both_) next_ += c_.B.col(2) * load;
      if (limited_) next_.head(frozen_) = x_.head(frozen_);
      x_.swap(next_);
    }
    return u;
  }
  [[nodiscard]] bool limited() const noexcept { return limited_; }

 private:
  const core::DiscreteStateSpace& c_;
  std::optional<double> limit_;
  Eigen::VectorXd x_, next_;
  bool both_;
  Eigen::Index frozen_;
  bool limited_ = false;
};

struct LoopRun {
  std::vector<DriveSample> samples;
  std::size_t limited = 0;
};

double reference_of(DriveTest test, double amplitude) { return test == DriveTest::kSetpointStep ? amplitude : 0.0; }

/// What the discrete controller reads: [ω*, ωm] (velocity loop, with ω* = kpp (φ* − φm) under a P
/// position loop), [φ*, φm] (a full-order position controller) or [ω*, ωm, ωl] (both measured).
struct ControllerInputs {
  std::optional<double> kpp;
  bool position = false;
  bool both = false;
  Eigen::Index filter_states = 0;  ///< the drive filters' states, last in the controller (LimitedController)
};

LoopRun run_loop(const machine::PlantConfig& config, const core::DiscreteStateSpace& controller,
                 ControllerInputs inputs, DriveTest test, double amplitude, std::size_t steps,
                 std::optional<double> limit) {
  machine::FlexiblePlant plant(config);
  const double ts = plant.ts();
  machine::PlantMeasurement m = plant.measure();
  FeedbackReader feedback(config.settings.output, ts, m.y);
  // A transfer-function plant reports only its output: the other motor signal is its exact
  // difference or integral.
  const bool tf_plant = !std::holds_alternative<machine::MassChain>(config.model);
  FeedbackReader exact(config.settings.output, ts, m.y_exact);
  LimitedController velocity_controller(controller, limit, inputs.filter_states);
  const SecondEncoder second_encoder(config.settings);
  FeedbackReader second(second_encoder.output(), ts, second_encoder.read(m));
  const double reference = reference_of(test, amplitude);
  const double load_torque = test == DriveTest::kLoadStep ? amplitude : 0.0;
  LoopRun run;
  run.samples.reserve(steps);
  for (std::size_t k = 0; k < steps; ++k) {
    feedback.read(m.y);
    double u = 0.0;
    if (inputs.both) {
      second.read(second_encoder.read(m));
      const bool motor_first = second_encoder.reads_load();
      u = velocity_controller.update(reference, motor_first ? feedback.velocity() : second.velocity(),
                                     motor_first ? second.velocity() : feedback.velocity());
    } else {
      u = inputs.position ? velocity_controller.update(reference, feedback.position())
                          : velocity_controller.update(
                                inputs.kpp ? *inputs.kpp * (reference - feedback.position()) : reference,
                                feedback.velocity());
    }
    run.limited += velocity_controller.limited() ? 1 : 0;
    DriveSample s;
    s.t = static_cast<double>(k) * ts;
    s.reference = reference;
    s.load_torque = load_torque;
    s.torque_command = u;
    s.motor_velocity = m.motor_velocity;
    s.load_velocity = m.load_velocity;
    s.motor_position = m.motor_position;
    s.load_position = m.load_position;
    s.measured = m.y;
    if (tf_plant) {
      exact.read(m.y_exact);
      s.motor_velocity = exact.velocity();
      s.motor_position = exact.position();
    }
    run.samples.push_back(s);
    m = plant.step(u, load_torque);
  }
  return run;
}

using Selector = ControlledVariable;

/// Time at which the series first reaches `level` (linear interpolation), +inf if never.
double first_crossing(const std::vector<DriveSample>& samples, Selector select, double level) {
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const double a = select(samples[k - 1]), b = select(samples[k]);
    if (b >= level && a < level) {
      const double f = (level - a) / (b - a);
      return samples[k - 1].t + f * (samples[k].t - samples[k - 1].t);
    }
  }
  return select(samples.front()) >= level ? samples.front().t : kInf;
}

/// Time after which |value − target| stays within `band` (the sample after the last exit), +inf
/// when the last sample is outside, 0 when always inside.
double last_exit(const std::vector<DriveSample>& samples, Selector select, double target, double band) {
  for (std::size_t k = samples.size(); k-- > 0;) {
    if (std::abs(select(samples[k]) - target) > band) return k + 1 < samples.size() ? samples[k + 1].t : kInf;
  }
  return 0.0;
}

double integral_time_abs_error(const std::vector<DriveSample>& samples, Selector select, double target) {
  double itae = 0.0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const double f0 = samples[k - 1].t * std::abs(target - select(samples[k - 1]));
    const double f1 = samples[k].t * std::abs(target - select(samples[k]));
    itae += 0.5 * (f0 + f1) * (samples[k].t - samples[k - 1].t);
  }
  return itae;
}

void tail_metrics(const std::vector<DriveSample>& samples, Selector select, double target, DriveMetrics& m) {
  const auto n = samples.size();
  const auto tail = std::max<std::size_t>(1, static_cast<std::size_t>(kTailShare * static_cast<double>(n)));
  double sum = 0.0, lo = kInf, hi = -kInf;
  for (std::size_t k = n - tail; k < n; ++k) {
    const double v = select(samples[k]);
    sum += target - v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  m.final_error = sum / static_cast<double>(tail);
  m.residual_oscillation = hi - lo;
}

DriveMetrics metrics_of(const LoopRun& run, DriveTest test, double amplitude, Selector select, double band) {
  const auto& s = run.samples;
  DriveMetrics m;
  Selector motor = select;
  motor.load = false;
  const double target = reference_of(test, amplitude);
  double peak = 0.0, peak_motor = 0.0, max_value = -kInf, max_motor = -kInf;
  for (const auto& sample : s) {
    m.peak_torque = std::max(m.peak_torque, std::abs(sample.torque_command));
    peak = std::max(peak, std::abs(select(sample)));
    peak_motor = std::max(peak_motor, std::abs(motor(sample)));
    max_value = std::max(max_value, select(sample));
    max_motor = std::max(max_motor, motor(sample));
  }
  m.saturated_fraction = static_cast<double>(run.limited) / static_cast<double>(s.size());
  m.itae = integral_time_abs_error(s, select, target);
  tail_metrics(s, select, target, m);
  if (test == DriveTest::kSetpointStep) {
    const double t10 = first_crossing(s, select, 0.1 * amplitude);
    const double t90 = first_crossing(s, select, 0.9 * amplitude);
    m.rise_time = std::isfinite(t90) ? t90 - t10 : kInf;
    m.overshoot = std::max(0.0, max_value / amplitude - 1.0);
    m.overshoot_motor = std::max(0.0, max_motor / amplitude - 1.0);
    m.settling_time = last_exit(s, select, amplitude, band * amplitude);
  } else {
    m.peak_deviation = peak;
    m.peak_deviation_motor = peak_motor;
    // Settled where the run ends (the final error): with motor feedback a constant load torque
    // leaves the load deflected by the shaft's twist Tl/k, which no motor-side loop removes.
    m.recovery_time = peak > 0.0 ? last_exit(s, select, -m.final_error, band * peak) : 0.0;
  }
  return m;
}

/// Automatic runs are lengthened (doubled) at most this often until the linear loop settles.
constexpr int kMaxExtensions = 4;

bool settled(const DriveMetrics& m, DriveTest test) {
  return std::isfinite(test == DriveTest::kSetpointStep ? m.settling_time : m.recovery_time);
}

double automatic_duration(const tuning::Controller& c, double ts) {
  double duration = c.predicted.horizon / c.plant.omega_z;
  if (is_position_loop(c)) duration = std::max(duration, kPositionTimeConstants / *c.kpp_physical);
  if (tuning::is_position_controller(c.structure)) duration = std::max(duration, position_controller_duration(c));
  if (!std::isfinite(duration) || duration <= 0.0) duration = 0.0;
  return std::max(duration, static_cast<double>(kMinSamples) * ts);
}

std::size_t sample_count(double duration, double ts, const std::string& field) {
  const double steps = std::ceil(duration / ts - 1e-9) + 1.0;
  if (steps > kMaxSamples)
    fail(field, fmt::format("at most {:g} samples at ts = {:g} s; {:g} s needs {:.0f}", kMaxSamples, ts, duration, steps));
  return static_cast<std::size_t>(steps);
}

/// The controller's Tustin prewarp frequency when it lies below the plant's Nyquist frequency.
std::optional<double> usable_prewarp(const tuning::Controller& c, double ts, std::vector<std::string>& notes) {
  if (!c.prewarp_rad_s) return std::nullopt;
  if (*c.prewarp_rad_s < 0.9 * std::numbers::pi / ts) return c.prewarp_rad_s;
  notes.push_back(fmt::format("the controller's prewarp frequency {:.4g} rad/s is not below the plant's Nyquist "
                              "frequency {:.4g} rad/s: discretized without prewarp",
                              *c.prewarp_rad_s, std::numbers::pi / ts));
  return std::nullopt;
}

/// The plant's scales against the design model's: a large mismatch usually means other units.
void compare_scales(const machine::PlantConfig& plant, const tuning::Controller& c, std::vector<std::string>& notes) {
  const auto* chain = std::get_if<machine::MassChain>(&plant.model);
  if (!chain || chain->masses() != 2) return;
  const auto p = machine::two_mass_parameters(*chain);
  const double inertia_ratio = chain->inertia[0] / c.plant.motor_inertia;
  const double omega_ratio = p.omega_z / c.plant.omega_z;
  if (inertia_ratio < 0.5 || inertia_ratio > 2.0 || omega_ratio < 0.5 || omega_ratio > 2.0)
    notes.push_back(fmt::format("the plant differs much from the design model: motor inertia x{:.3g}, antiresonance "
                                "x{:.3g} (other units, or a different machine?)",
                                inertia_ratio, omega_ratio));
}

}  // namespace

std::string_view to_string(DriveTest test) noexcept {
  return test == DriveTest::kSetpointStep ? "step" : "load-step";
}

std::optional<DriveTest> drive_test_from_string(std::string_view text) noexcept {
  if (text == "step") return DriveTest::kSetpointStep;
  if (text == "load-step") return DriveTest::kLoadStep;
  return std::nullopt;
}

bool has_load_torque_input(const machine::PlantConfig& plant) noexcept {
  return std::holds_alternative<machine::MassChain>(plant.model);
}

ControlledVariable controlled_variable(const DriveSimulation& simulation) noexcept {
  return {tuning::controls_position(simulation.structure), simulation.load_side};
}

machine::PlantConfig linear_part(const machine::PlantConfig& plant) {
  machine::PlantConfig linear = plant;
  if (auto* chain = std::get_if<machine::MassChain>(&linear.model)) {
    chain->friction.clear();
    chain->backlash.clear();
  }
  linear.settings.noise_std = 0.0;
  linear.settings.quantization = 0.0;
  linear.settings.substeps = 0;
  return linear;
}

/// Issue 27 §3: a loop that diverges (a controller sampled far too slowly, ts = 1 s for a loop of
/// hundreds of rad/s) filled the CSV with inf and nan and its notes blamed friction. Diverged: the
/// controlled variable or the torque not finite, or the controlled variable beyond 1e12 step heights
/// (no working loop comes near: a load step of 1e-3 N m on 1e-6 kg m^2 moves a 100 rad/s loop ~10 rad/s).
constexpr double kDivergedSteps = 1e12;

void require_bounded(const LoopRun& run, const Selector& select, double amplitude, const char* which, double ts,
                     std::optional<double> prewarp_rad_s) {
  const std::string design = prewarp_rad_s ? fmt::format(" (designed near {:.4g} rad/s)", *prewarp_rad_s) : "";
  for (const DriveSample& s : run.samples) {
    const double v = select(s);
    if (std::isfinite(v) && std::isfinite(s.torque_command) && std::abs(v) <= kDivergedSteps * amplitude) continue;
    throw core::InputError(
        core::at_field("ts"),
        fmt::format("the {} closed loop diverges (the controlled variable is {:.3g} at t = {:.6g} s): the controller{} "
                    "is unstable on this plant sampled at ts = {} s (Nyquist {:.4g} rad/s); tune for this plant, or "
                    "sample faster",
                    which, v, s.t, design, ts, std::numbers::pi / ts));
  }
}

DriveSimulation simulate_drive(const machine::PlantConfig& given_plant, const tuning::Controller& controller,
                               const DriveSimulationSettings& settings) {
  check_settings(settings);
  machine::validate(given_plant);
  DriveSimulation out;
  const machine::PlantConfig plant = as_measured(given_plant, controller, out.notes);
  check_plant(plant, controller, settings.test);
  out.test = settings.test;
  out.structure = controller.structure;
  out.ts = plant.settings.ts;
  out.amplitude = settings.amplitude;
  out.torque_limit = settings.torque_limit;
  out.settling_band = settings.settling_band;
  out.gains = controller.physical;
  out.full_order = controller.full_order;
  const auto* chain = std::get_if<machine::MassChain>(&plant.model);
  out.load_side = chain != nullptr && chain->masses() >= 2;
  compare_scales(plant, controller, out.notes);
  out.controller = tuning::discretize_controller(controller, out.ts, usable_prewarp(controller, out.ts, out.notes));

  const ControllerInputs inputs{is_position_loop(controller) ? controller.kpp_physical : std::nullopt,
                                tuning::is_position_controller(controller.structure),
                                tuning::measures_both(controller.structure),
                                tuning::filter_chain(controller.drive_filters).den().degree()};
  out.kpp = inputs.kpp;
  const Selector select = controlled_variable(out);
  const machine::PlantConfig linear_plant = linear_part(plant);
  const auto run_linear = [&](std::size_t steps) {
    return run_loop(linear_plant, out.controller, inputs, settings.test, settings.amplitude, steps, std::nullopt);
  };
  const auto metrics = [&](const LoopRun& run) {
    return metrics_of(run, settings.test, settings.amplitude, select, settings.settling_band);
  };

  std::size_t steps = 0;
  LoopRun linear;
  if (settings.duration_s > 0.0) {
    steps = sample_count(settings.duration_s, out.ts, "duration_s");
    linear = run_linear(steps);
    out.linear_metrics = metrics(linear);
  } else {
    // The design's horizon is a guess for cascades and load steps (slow integrator modes): lengthen
    // the run until the linear loop has settled, so the run shows the whole response.
    double duration = automatic_duration(controller, out.ts);
    for (int extension = 0;; ++extension) {
      steps = sample_count(duration, out.ts, "duration_s");
      linear = run_linear(steps);
      out.linear_metrics = metrics(linear);
      if (settled(out.linear_metrics, settings.test) || extension == kMaxExtensions ||
          2.0 * duration / out.ts > kMaxSamples)
        break;
      duration *= 2.0;
    }
  }
  const std::optional<double> design_rad_s = controller.prewarp_rad_s;
  require_bounded(linear, select, settings.amplitude, "linear", out.ts, design_rad_s);
  LoopRun nonlinear =
      run_loop(plant, out.controller, inputs, settings.test, settings.amplitude, steps, settings.torque_limit);
  require_bounded(nonlinear, select, settings.amplitude, "simulated", out.ts, design_rad_s);
  out.metrics = metrics(nonlinear);
  out.samples = std::move(nonlinear.samples);
  out.linear_samples = std::move(linear.samples);
  if (out.metrics.saturated_fraction > 0.0)
    out.notes.push_back(fmt::format("the torque limit was active in {:.1f} % of the samples",
                                    100.0 * out.metrics.saturated_fraction));
  if (!std::isfinite(out.metrics.settling_time) && settings.test == DriveTest::kSetpointStep)
    out.notes.push_back("the controlled variable had not settled at the end of the run: friction holding the load off "
                        "the target (see the final error), hunting or a limit cycle (see the residual oscillation)");
  return out;
}

}  // namespace servotwin::vcnc
