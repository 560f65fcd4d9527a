#include "servotwin/vcnc/frf_experiment.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "frf_run.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::vcnc {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

core::InputError setting_error(const std::string& option, const std::string& message) {
  return core::InputError(core::at_field(option), message);
}

void check_settings(const FrfExperimentSettings& s, double ts) {
  const double f_max = 1.0 / (10.0 * ts);
  if (!(s.f_begin_hz > 0.0) || !std::isfinite(s.f_end_hz) || !(s.f_end_hz > s.f_begin_hz))
    throw setting_error("--range-hz", "expected 0 < begin < end, got " + std::to_string(s.f_begin_hz) + ":" +
                                          std::to_string(s.f_end_hz) + " Hz");
  if (!(s.f_end_hz < f_max))
    throw setting_error("--range-hz", "the end frequency must stay below fs/10 = " + std::to_string(f_max) +
                                          " Hz at the plant's sample period (the observer's 5th harmonic must "
                                          "stay below Nyquist); got " + std::to_string(s.f_end_hz) + " Hz");
  if (s.points < 2 || s.points > 10000) throw setting_error("--points", "expected 2..10000 points");
  if (s.amplitude && !(*s.amplitude > 0.0 && std::isfinite(*s.amplitude)))
    throw setting_error("--amplitude", "expected a positive finite amplitude");
  if (s.max_amplitude && !(*s.max_amplitude > 0.0 && std::isfinite(*s.max_amplitude)))
    throw setting_error("--max-amplitude", "expected a positive finite amplitude");
  if (s.output_limit && !(*s.output_limit > 0.0 && std::isfinite(*s.output_limit)))
    throw setting_error("--output-limit", "expected a positive finite limit");
  if (!(s.sweep_time_s >= 0.0 && std::isfinite(s.sweep_time_s)))
    throw setting_error("--sweep-time", "expected a positive sweep time in seconds (0 = automatic)");
  if (!(s.max_time_s >= 0.0 && std::isfinite(s.max_time_s)))
    throw setting_error("--max-time", "expected a positive time limit in seconds (0 = automatic)");
}

std::vector<double> log_spaced(double a, double b, std::size_t n) {
  std::vector<double> out;
  out.reserve(n);
  const double step = std::log(b / a) / static_cast<double>(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) out.push_back(a * std::exp(step * static_cast<double>(i)));
  out.push_back(b);
  return out;
}

/// What the sensor cannot resolve: noise plus the quantization's uniform error.
double noise_floor(const machine::PlantSettings& s) {
  const double q = s.quantization / std::sqrt(12.0);
  return std::max(std::hypot(s.noise_std, q), 1e-9);
}

/// Largest |P(j w)| of the plant's linear model over [w_begin, w_end] (log grid): the default output
/// range must leave room for the resonances, not just for the first frequency.
double peak_gain(const machine::FlexiblePlant& plant, double w_begin, double w_end) {
  const core::TransferFunction tf = plant.transfer_function();
  double peak = 0.0;
  constexpr int kGrid = 2000;
  for (int i = 0; i <= kGrid; ++i) {
    const double w = w_begin * std::pow(w_end / w_begin, static_cast<double>(i) / kGrid);
    const double g = std::abs(tf.frequency_response(w));
    if (std::isfinite(g)) peak = std::max(peak, g);
  }
  return peak;
}

}  // namespace

double sweep_time(const FrfExperimentSettings& s) {
  return s.sweep_time_s > 0.0 ? s.sweep_time_s : std::max(8.0, 8.0 / s.f_begin_hz);
}

double time_limit(const FrfExperimentSettings& s) {
  return s.max_time_s > 0.0 ? s.max_time_s : std::max(120.0, 200.0 / s.f_begin_hz + 4.0 * sweep_time(s));
}

/// The amplitude's least growth per second while the SNR says the motor hardly moves
/// (AmplitudeLaw::growth_per_second): tripling each second, so a motor held by Coulomb friction
/// three times the start amplitude moves within about a second at 1 Hz (doubling: 1.5 s more per
/// friction-bound point; the 3x bench took 30.0 s instead of 28.8).
constexpr double kGrowthPerSecond = 2.0;
/// A point that has not settled in this many of its periods latches (RfidParameters::
/// max_settling_periods): a frictionless point settles in about three.
constexpr double kMaxSettlingPeriods = 5.0;

frf::RfidParameters experiment_parameters(const machine::FlexiblePlant& plant, const FrfExperimentSettings& settings) {
  const double ts = plant.ts();
  check_settings(settings, ts);
  const double w_begin = kTwoPi * settings.f_begin_hz;
  const double w_end = kTwoPi * settings.f_end_hz;

  const double gain_begin = std::abs(plant.transfer_function().frequency_response(w_begin));
  if (!(gain_begin > 0.0) || !std::isfinite(gain_begin))
    throw setting_error("--range-hz", "the plant does not respond at the start frequency");
  const double floor = noise_floor(plant.config().settings);
  const double amplitude = settings.amplitude.value_or(300.0 * floor / gain_begin);
  const double max_amplitude = std::max(settings.max_amplitude.value_or(100.0 * amplitude), amplitude);
  if (settings.max_amplitude && *settings.max_amplitude < amplitude)
    throw setting_error("--max-amplitude", "must not be below the initial amplitude");

  frf::RfidParameters p;
  p.ts = ts;
  p.omega_begin = w_begin;
  p.omega_end = w_end;
  p.initial_amplitude = amplitude;
  p.max_amplitude = max_amplitude;
  p.sweep_type = frf::SweepType::kLogarithmic;
  p.sweep_rate = std::log(w_end / w_begin) / sweep_time(settings);
  p.measurement_frequencies = log_spaced(w_begin, w_end, settings.points);
  // Interior points must lie strictly inside the range for the block; the ends are measured as the
  // sweep's first and last frequencies.
  p.settling_time_s = 20.0 * ts;
  p.max_settling_time_s = std::max(2.0, 8.0 / settings.f_begin_hz);
  p.max_settling_periods = kMaxSettlingPeriods;
  p.observer = settings.observer;
  p.thd_threshold = settings.thd_threshold;
  p.proportional_growth = true;  // antiresonances need many times A(t0)
  p.amplitude_rate = 0.1;
  p.amplitude_growth_per_second = kGrowthPerSecond;
  p.fade_in_periods = 1.0;
  p.thd_hysteresis = 0.4 * settings.thd_threshold;
  p.noise_level = floor;
  const double limit = settings.output_limit.value_or(20.0 * amplitude * peak_gain(plant, w_begin, w_end));
  p.output_min = -limit;
  p.output_max = limit;
  return p;
}

frf::RfidParameters closed_loop_parameters(const machine::FlexiblePlant& plant, const FrfExperimentSettings& settings) {
  frf::RfidParameters p = experiment_parameters(plant, settings);
  p.initial_amplitude = settings.amplitude.value_or(300.0 * noise_floor(plant.config().settings));
  p.max_amplitude = std::max(settings.max_amplitude.value_or(100.0 * p.initial_amplitude), p.initial_amplitude);
  const double limit = settings.output_limit.value_or(3.0 * p.max_amplitude);
  p.output_min = -limit;
  p.output_max = limit;
  return p;
}

double dc_hold_gain(const machine::FlexiblePlant& plant, const FrfExperimentSettings& settings) {
  const machine::PlantOutput output = plant.config().settings.output;
  const bool velocity = output == machine::PlantOutput::MotorVelocity || output == machine::PlantOutput::LoadVelocity;
  if (!settings.hold_dc || !velocity) return 0.0;
  // Rigid inertia seen at f_begin: |P(j w)| = 1/(J w) below the first antiresonance.
  const double w = kTwoPi * settings.f_begin_hz;
  const core::TransferFunction tf = plant.transfer_function();
  const double gain = std::abs(tf.frequency_response(w));
  if (!(gain > 0.0) || !std::isfinite(gain)) return 0.0;
  // Only an integrating plant (a free inertia: |P| grows like 1/w below f_begin) keeps the mean
  // velocity a switched-on sine gives it; a plant with a finite gain there settles by itself, and a
  // loop designed for an inertia would only disturb it.
  if (std::abs(tf.frequency_response(w / 10.0)) < 5.0 * gain) return 0.0;
  const double inertia = 1.0 / (w * gain);
  return inertia * w / 4.0;
}

FrfExperiment run_frf_experiment(machine::FlexiblePlant& plant, const frf::RfidParameters& parameters,
                                 double max_time_s, bool keep_trace, double dc_gain, const FrfProgress& progress) {
  FrfExperiment out;
  out.parameters = parameters;
  out.dc_gain = dc_gain;
  frf::RfidBlock block(parameters);
  detail::run_block(
      block, plant, max_time_s, keep_trace, progress, out,
      [dc_gain](const frf::RfidOutput& o) { return -dc_gain * o.harmonics[0]; },
      [](const frf::RfidOutput& o, double) { return o.mv; });
  return out;
}

std::string point_kind_name(frf::PointKind kind) {
  switch (kind) {
    case frf::PointKind::kResonance: return "resonance";
    case frf::PointKind::kAntiresonance: return "antiresonance";
    case frf::PointKind::kListed: break;
  }
  return "listed";
}

std::string outcome_text(const FrfExperiment& e) {
  if (e.timed_out) return "stopped at the time limit before the sweep ended";
  switch (e.final_state) {
    case frf::RfidState::kDone: return "done";
    case frf::RfidState::kAborted:
      switch (e.abort_reason) {
        case frf::AbortReason::kOutputOutOfRange: return "aborted: the output left its allowed range";
        case frf::AbortReason::kNonFiniteInput: return "aborted: the measured output was not finite";
        case frf::AbortReason::kStoppedByUser: return "aborted: stopped";
        case frf::AbortReason::kNone: break;
      }
      return "aborted";
    default: return "unfinished";
  }
}

}  // namespace servotwin::vcnc
