#include "servotwin/frf/rfid_block.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <string>
#include <utility>

#include "servotwin/core/error.hpp"

namespace servotwin::frf {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// A short message with numbers (the module has fmt; this keeps the call sites compact).
template <typename... Args>
std::string fmt_reason(fmt::format_string<Args...> format, Args&&... args) {
  return fmt::format(format, std::forward<Args>(args)...);
}
constexpr long kHoldoffPeriods = 2;     // observer re-convergence after a start or a frequency jump (~1.25 periods)
constexpr double kMinimumAmplitudeFraction = 0.05;  // range reduction floor, relative to A(0)
/// The longest window of the settling test on half-period means (settle_windows.hpp): long enough
/// to average the beat of a mode ringing a few hertz away, short against the 2 s a point may take.
constexpr double kMaxWindow_s = 0.25;
constexpr double kSettleNoiseFraction = 0.25;  // share of the sensor noise (in output units) a settled estimate may still move per half period

[[noreturn]] void reject(const std::string& field, const std::string& expected, double got) {
  throw core::InputError(core::at_field(field), "expected " + expected + ", got " + std::to_string(got));
}

void require_finite_positive(double value, const std::string& field) {
  if (!std::isfinite(value) || value <= 0.0) reject(field, "a finite value > 0", value);
}

RfidParameters validated(RfidParameters p) {
  require_finite_positive(p.ts, "ts");
  require_finite_positive(p.omega_begin, "omega_begin");
  const double nyquist_fifth = std::numbers::pi / (5.0 * p.ts);
  if (!std::isfinite(p.omega_end) || p.omega_end <= p.omega_begin || p.omega_end >= nyquist_fifth)
    reject("omega_end", "omega_begin < omega_end < pi/(5 ts) = " + std::to_string(nyquist_fifth) +
                            " rad/s (the 5th harmonic must stay below Nyquist)", p.omega_end);
  require_finite_positive(p.initial_amplitude, "initial_amplitude");
  if (!std::isfinite(p.max_amplitude) || p.max_amplitude < p.initial_amplitude)
    reject("max_amplitude", "a finite value >= initial_amplitude (" + std::to_string(p.initial_amplitude) + ")",
           p.max_amplitude);
  if (!std::isfinite(p.dc_offset)) reject("dc_offset", "a finite value", p.dc_offset);
  require_finite_positive(p.sweep_rate, "sweep_rate");
  if (!std::isfinite(p.settling_time_s) || p.settling_time_s < 0.0)
    reject("settling_time_s", "a finite value >= 0", p.settling_time_s);
  if (!std::isfinite(p.max_settling_time_s) || p.max_settling_time_s < 0.0 ||
      (p.max_settling_time_s > 0.0 && p.max_settling_time_s < p.settling_time_s))
    reject("max_settling_time_s", "0 (= 5 x settling_time_s) or a finite value >= settling_time_s",
           p.max_settling_time_s);
  require_finite_positive(p.settle_tolerance, "settle_tolerance");
  for (std::size_t i = 0; i < p.measurement_frequencies.size(); ++i) {
    const double w = p.measurement_frequencies[i];
    const std::string field = "measurement_frequencies[" + std::to_string(i) + "]";
    if (!std::isfinite(w) || w < p.omega_begin || w > p.omega_end)
      reject(field, "a frequency inside [omega_begin, omega_end] = [" + std::to_string(p.omega_begin) + ", " +
                        std::to_string(p.omega_end) + "] rad/s", w);
    if (i > 0 && w <= p.measurement_frequencies[i - 1])
      reject(field, "strictly increasing frequencies (previous " + std::to_string(p.measurement_frequencies[i - 1]) + ")",
             w);
  }
  require_finite_positive(p.thd_threshold, "thd_threshold");
  if (!std::isfinite(p.thd_hysteresis) || p.thd_hysteresis < 0.0 || p.thd_hysteresis >= p.thd_threshold)
    reject("thd_hysteresis", "0 <= h < thd_threshold", p.thd_hysteresis);
  require_finite_positive(p.amplitude_rate, "amplitude_rate");
  if (!std::isfinite(p.max_settling_periods) || p.max_settling_periods < 0.0)
    reject("max_settling_periods", "0 (no limit by periods) or a finite value > 0", p.max_settling_periods);
  if (!std::isfinite(p.amplitude_growth_per_second) || p.amplitude_growth_per_second < 0.0 ||
      (p.amplitude_growth_per_second > 0.0 && !p.proportional_growth))
    reject("amplitude_growth_per_second", "a finite value >= 0, and 0 unless proportional_growth",
           p.amplitude_growth_per_second);
  if (!std::isfinite(p.fade_in_periods) || p.fade_in_periods < 0.0 || p.fade_in_periods > 100.0)
    reject("fade_in_periods", "a value in [0, 100]", p.fade_in_periods);
  const bool min_inf = std::isinf(p.output_min) && p.output_min < 0.0;
  const bool max_inf = std::isinf(p.output_max) && p.output_max > 0.0;
  if (std::isnan(p.output_min) || (std::isinf(p.output_min) && !min_inf))
    reject("output_min", "a finite lower bound (or -infinity with output_max = +infinity)", p.output_min);
  if (std::isnan(p.output_max) || (std::isinf(p.output_max) && !max_inf))
    reject("output_max", "a finite upper bound (or +infinity with output_min = -infinity)", p.output_max);
  if (min_inf != max_inf)
    reject(min_inf ? "output_min" : "output_max", "both output bounds finite or both infinite",
           min_inf ? p.output_min : p.output_max);
  if (!min_inf && p.output_max <= p.output_min)
    reject("output_max", "a value > output_min (" + std::to_string(p.output_min) + ")", p.output_max);
  if (!std::isfinite(p.range_margin) || p.range_margin <= 0.0 || p.range_margin > 1.0)
    reject("range_margin", "a fraction in (0, 1]", p.range_margin);
  if (std::isnan(p.actuator_limit) || p.actuator_limit <= 0.0)
    reject("actuator_limit", "a value > 0 (+infinity = none)", p.actuator_limit);
  if (!std::isfinite(p.noise_level) || p.noise_level < 0.0)
    reject("noise_level", "a finite value >= 0 (0 = unknown)", p.noise_level);
  if (!std::isfinite(p.extremum_prominence) || p.extremum_prominence <= 0.0 || p.extremum_prominence >= 1.0)
    reject("extremum_prominence", "a fraction in (0, 1)", p.extremum_prominence);
  if (p.max_extra_points > 1000)
    reject("max_extra_points", "at most 1000", static_cast<double>(p.max_extra_points));
  return p;
}

ObserverVector observer_gains_of(const RfidParameters& p) {
  try {
    return design_gains(p.observer);
  } catch (const core::InputError& e) {
    throw core::InputError(core::at_field("observer." + e.where().field), e.reason());
  }
}

AmplitudeLaw amplitude_law_of(const RfidParameters& p) {
  AmplitudeLaw law;
  law.initial = p.initial_amplitude;
  law.maximum = p.max_amplitude;
  law.minimum = kMinimumAmplitudeFraction * p.initial_amplitude;
  law.rate = p.amplitude_rate;
  law.proportional = p.proportional_growth;
  law.growth_per_second = p.amplitude_growth_per_second;
  law.ts = p.ts;
  law.thd_threshold = p.thd_threshold;
  law.thd_hysteresis = p.thd_hysteresis;
  // With a known noise level the SNR drives the relay too (issue 25 §1).
  law.snr_minimum = p.noise_level > 0.0 ? RfidBlock::kMinimumSnr : 0.0;
  law.reduce_ratio = p.range_margin;
  return law;
}

bool is_running(RfidState s) {
  return s == RfidState::kSweep || s == RfidState::kSettle || s == RfidState::kRampOut;
}

}  // namespace

RfidBlock::RfidBlock(RfidParameters parameters)
    : p_(validated(std::move(parameters))),
      observer_(observer_gains_of(p_), p_.ts),
      generator_(p_.ts),
      sweep_(p_.sweep_type, p_.sweep_rate, p_.ts, p_.omega_end),
      adapter_(amplitude_law_of(p_)),
      omega_(p_.omega_begin) {
  settle_samples_ = std::lround(p_.settling_time_s / p_.ts);
  const double max_settle = p_.max_settling_time_s > 0.0 ? p_.max_settling_time_s : 5.0 * p_.settling_time_s;
  max_settle_samples_ = std::max(std::lround(max_settle / p_.ts), settle_samples_ + 1);
  points_.reserve(p_.measurement_frequencies.size() + p_.max_extra_points);
}

long RfidBlock::period_samples(double omega) const noexcept {
  return std::max(1L, std::lround(kTwoPi / (omega * p_.ts)));
}

long RfidBlock::max_settle_limit() const noexcept {
  if (!(p_.max_settling_periods > 0.0)) return max_settle_samples_;
  // In double until it is known to lie below the time limit: a huge period count must mean "no
  // limit by periods", not overflow.
  const double by_periods = std::max(p_.max_settling_periods * kTwoPi / (omega_ * p_.ts), kMinimumPeriodLimit_s / p_.ts);
  if (!(by_periods < static_cast<double>(max_settle_samples_))) return max_settle_samples_;
  return std::max(std::lround(by_periods), settle_samples_ + 1);
}

void RfidBlock::start_run() noexcept {
  state_ = RfidState::kSweep;
  abort_reason_ = AbortReason::kNone;
  omega_ = p_.omega_begin;
  generator_.reset();
  adapter_.reset();
  amplitude_ = adapter_.amplitude();
  points_.clear();  // keeps the capacity reserved by the constructor
  next_listed_ = 0;
  extra_points_ = 0;
  run_samples_ = 0;
  latched_ = {};
  detector_ = {};
  detector_.holdoff = kHoldoffPeriods * period_samples(omega_);
  fade_length_ = std::lround(p_.fade_in_periods * static_cast<double>(period_samples(omega_)));
  fade_done_ = 0;
  if (!p_.measurement_frequencies.empty() && p_.measurement_frequencies.front() <= omega_) {
    settle_kind_ = PointKind::kListed;
    enter_settle();
  }
}

void RfidBlock::abort_run(AbortReason reason) noexcept {
  state_ = RfidState::kAborted;
  abort_reason_ = reason;
  amplitude_ = 0.0;
}

void RfidBlock::enter_settle() noexcept {
  state_ = RfidState::kSettle;
  settle_elapsed_ = 0;
  settle_total_ = 0;
  period_count_ = 0;
  // The running estimate is compared every half period: in steady state it is constant (the
  // observer separates the harmonics), so half a period shows a transient as well as a full one
  // and halves the wait at low frequencies, where the periods dominate the experiment time.
  period_length_ = std::max(1L, period_samples(omega_) / 2);
  period_converged_ = false;
  period_mark_ = {};
  windows_.clear();
  window_converged_ = false;
  max_window_ = static_cast<std::size_t>(std::clamp(std::floor(kMaxWindow_s / (static_cast<double>(period_length_) * p_.ts)), 0.0,
                                                    static_cast<double>(SettleWindows::kCapacity / 2)));
  settle_limit_ = max_settle_limit();
}

double RfidBlock::idle_command(double cv) const noexcept {
  if (state_ == RfidState::kAborted && p_.abort_action == AbortAction::kZero) return 0.0;
  if (!std::isfinite(cv)) return 0.0;
  return std::clamp(cv, -p_.actuator_limit, p_.actuator_limit);
}

double RfidBlock::limit_usage(double pv, double cv) const noexcept {
  double usage = 0.0;
  if (std::isfinite(p_.output_min)) {
    const double center = 0.5 * (p_.output_min + p_.output_max);
    const double half = 0.5 * (p_.output_max - p_.output_min);
    double peak = std::abs(observer_.dc() - center);
    for (int i = 1; i <= kHarmonicCount; ++i) peak += observer_.harmonic_amplitude(i);
    usage = std::max(peak, std::abs(pv - center)) / half;
  }
  if (std::isfinite(p_.actuator_limit)) {
    const double headroom = p_.actuator_limit - std::abs(p_.dc_offset + cv);
    usage = std::max(usage, headroom > 0.0 ? amplitude_ / headroom : std::numeric_limits<double>::infinity());
  }
  return usage;
}

void RfidBlock::advance_sweep(double magnitude) noexcept {
  const double omega_k = omega_;
  bool found = false;
  PointKind kind = PointKind::kResonance;
  double found_omega = 0.0;
  ExtremumDetector& d = detector_;
  if (d.holdoff > 0) {
    --d.holdoff;
    d.max = d.min = magnitude;
    d.max_omega = d.min_omega = omega_k;
  } else if (p_.detect_extrema && extra_points_ < p_.max_extra_points) {
    const double rise = 1.0 + p_.extremum_prominence, fall = 1.0 - p_.extremum_prominence;
    switch (d.mode) {
      case ExtremumDetector::Mode::kUnknown:
        if (magnitude > d.max) { d.max = magnitude; d.max_omega = omega_k; }
        if (magnitude < d.min) { d.min = magnitude; d.min_omega = omega_k; }
        // Boundary values are not extrema: only decide the direction once |P| moved enough.
        if (magnitude > d.min * rise) { d.mode = ExtremumDetector::Mode::kSeekMax; d.max = magnitude; d.max_omega = omega_k; }
        else if (magnitude < d.max * fall) { d.mode = ExtremumDetector::Mode::kSeekMin; d.min = magnitude; d.min_omega = omega_k; }
        break;
      case ExtremumDetector::Mode::kSeekMax:
        if (magnitude > d.max) { d.max = magnitude; d.max_omega = omega_k; }
        else if (magnitude < d.max * fall) {
          found = true; kind = PointKind::kResonance; found_omega = d.max_omega;
          d.mode = ExtremumDetector::Mode::kSeekMin; d.min = magnitude; d.min_omega = omega_k;
        }
        break;
      case ExtremumDetector::Mode::kSeekMin:
        if (magnitude < d.min) { d.min = magnitude; d.min_omega = omega_k; }
        else if (magnitude > d.min * rise) {
          found = true; kind = PointKind::kAntiresonance; found_omega = d.min_omega;
          d.mode = ExtremumDetector::Mode::kSeekMax; d.max = magnitude; d.max_omega = omega_k;
        }
        break;
    }
  }
  const double next = sweep_.next(omega_k);
  if (found) {
    ++extra_points_;
    settle_kind_ = kind;
    // Resume the sweep from the extremum itself, where the plant is in steady state after the
    // measurement: jumping ahead instead would ring the just-excited mode and fake extrema.
    resume_omega_ = found_omega;
    omega_ = found_omega;
    enter_settle();
    return;
  }
  if (next_listed_ < p_.measurement_frequencies.size() && next >= p_.measurement_frequencies[next_listed_]) {
    settle_kind_ = PointKind::kListed;
    omega_ = p_.measurement_frequencies[next_listed_];
    enter_settle();
    return;
  }
  if (omega_k >= p_.omega_end) {
    state_ = RfidState::kRampOut;
    ramp_length_ = period_samples(omega_k);
    ramp_left_ = ramp_length_;
    ramp_from_ = amplitude_;
    return;
  }
  omega_ = next;
}

void RfidBlock::advance_settle(std::complex<double> running, double thd) noexcept {
  ++settle_total_;
  ++settle_elapsed_;
  if (adapter_.last_action() != AmplitudeAction::kHold) {
    // A changed: the plant and the observer need a new transient before P is steady again.
    settle_elapsed_ = 0;
    period_count_ = 0;
    period_converged_ = false;
    period_mark_ = running;
    windows_.clear();
    window_converged_ = false;
  }
  windows_.add(running);
  if (++period_count_ >= period_length_) {
    // With a known sensor noise, changes the noise alone explains count as settled: near an
    // antiresonance the response is small and a purely relative test would wait for nothing.
    const double noise_allowance = amplitude_ > 0.0 ? kSettleNoiseFraction * p_.noise_level / amplitude_ : 0.0;
    // Half the tolerance over half the period: the same rate of change as tol per period.
    period_converged_ =
        std::abs(running - period_mark_) <= 0.5 * p_.settle_tolerance * std::abs(running) + noise_allowance;
    period_mark_ = running;
    period_count_ = 0;
    windows_.close_half_period();
    const SettleWindows::Verdict w = windows_.test(0.5 * p_.settle_tolerance, noise_allowance, max_window_);
    window_converged_ = w.settled;
    window_mean_ = w.mean;
  }
  const bool thd_accepted = !adapter_.relay() || adapter_.blocked();
  const bool faded_in = fade_done_ >= fade_length_;
  const bool ready = settle_elapsed_ >= settle_samples_ && thd_accepted && faded_in;
  // Where windows of half-period means can be formed (above 4 Hz, after four half periods), a pass
  // of the single test counts only with a window that passes too: beside a light mode the single
  // test passes at a turning point of the ringing's beat (three-mass chain: two points 0.01 %
  // apart at 72.66 Hz differed by 0.56 dB and 8°, and the modes' dampings came out 13-48 % off;
  // with the windows' consent 0-17 %).
  const bool windows_agree = max_window_ < 2 || windows_.count() < 4 || window_converged_;
  if (ready && period_converged_ && windows_agree) latch(running, thd, true);
  else if (ready && window_converged_) latch(window_mean_, thd, true);
  else if (settle_total_ >= settle_limit_) latch(windows_.longest_mean(max_window_, running), thd, false);
}

void RfidBlock::latch(std::complex<double> running, double thd, bool settled) noexcept {
  MeasuredPoint point;
  point.omega = omega_;
  point.response = running;
  point.thd = thd;
  const double a1 = observer_.harmonic_amplitude(1);
  point.snr = p_.noise_level > 0.0 ? a1 / p_.noise_level : 1.0 / std::max(thd, 1e-12);
  point.amplitude = amplitude_;
  point.dc = observer_.dc();
  point.time_s = elapsed_s();
  point.kind = settle_kind_;
  point.settled = settled;
  point.amplitude_limited = adapter_.blocked();
  if (points_.size() < points_.capacity()) points_.push_back(point);  // never reallocates
  latched_ = running;
  data_valid_ = true;

  state_ = RfidState::kSweep;
  if (settle_kind_ == PointKind::kListed) {
    ++next_listed_;
  } else {
    omega_ = resume_omega_;
    // Unknown direction again: the extremum just measured is a boundary value of the new search.
    detector_.mode = ExtremumDetector::Mode::kUnknown;
    detector_.holdoff = 1;
  }
}

double RfidBlock::fade_in_factor() noexcept {
  if (fade_done_ >= fade_length_) return 1.0;
  const double x = static_cast<double>(fade_done_++) / static_cast<double>(fade_length_);
  return 0.5 * (1.0 - std::cos(std::numbers::pi * x));
}

RfidOutput RfidBlock::step(bool start, double pv, double cv) noexcept {
  const bool rising = start && !previous_start_;
  const bool falling = !start && previous_start_;
  previous_start_ = start;
  const bool finite = std::isfinite(pv) && std::isfinite(cv);
  data_valid_ = false;

  if (rising && finite) start_run();
  else if (falling && is_running(state_)) abort_run(AbortReason::kStoppedByUser);
  if (is_running(state_) && !finite) abort_run(AbortReason::kNonFiniteInput);
  if (is_running(state_) && (pv < p_.output_min || pv > p_.output_max)) abort_run(AbortReason::kOutputOutOfRange);

  // The observer always runs, so A0 (the semi-closed-loop feedback) is valid before and after a run.
  if (std::isfinite(pv)) observer_.update(pv, omega_);
  const double thd = observer_.thd();

  RfidOutput out;
  out.harmonics[0] = observer_.dc();
  for (int i = 1; i <= kHarmonicCount; ++i) out.harmonics[static_cast<std::size_t>(i)] = observer_.harmonic_amplitude(i);
  out.thd = thd;
  out.omega = omega_;
  out.latched = latched_;

  if (!is_running(state_)) {
    out.mv = idle_command(cv);
    out.state = state_;
    return out;
  }

  ++run_samples_;
  const double omega_k = omega_;
  const double amplitude_k = amplitude_ * fade_in_factor();
  const std::complex<double> running =
      amplitude_k > 0.0 ? observer_.first_harmonic(generator_.sin_phase(), generator_.cos_phase()) / amplitude_k
                        : std::complex<double>{};
  const double excitation = std::clamp(generator_.output(amplitude_k, 0.0), -p_.max_amplitude, p_.max_amplitude);
  out.mv = std::clamp(excitation + p_.dc_offset + cv, -p_.actuator_limit, p_.actuator_limit);
  out.running = running;
  out.amplitude = amplitude_k;

  generator_.set_frequency(omega_k);
  generator_.advance();

  switch (state_) {
    case RfidState::kSweep:
    case RfidState::kSettle: {
      const bool trusted = state_ == RfidState::kSettle || detector_.holdoff == 0;
      // The SNR a point latched now would carry (latch()): the first harmonic over the noise level.
      // Not before the fade-in ends: the first harmonic of a fading-in excitation reads as no signal.
      const bool faded_in = fade_done_ >= fade_length_;
      const double snr = trusted && faded_in && p_.noise_level > 0.0
                             ? observer_.harmonic_amplitude(1) / p_.noise_level
                             : std::numeric_limits<double>::quiet_NaN();
      amplitude_ = adapter_.update(trusted ? thd : 0.0, limit_usage(pv, cv), omega_k * p_.ts, snr);
      if (state_ == RfidState::kSweep) advance_sweep(std::abs(running));
      else advance_settle(running, thd);
      break;
    }
    case RfidState::kRampOut:
      --ramp_left_;
      amplitude_ = ramp_from_ * static_cast<double>(std::max(ramp_left_, 0L)) / static_cast<double>(ramp_length_);
      if (ramp_left_ <= 0) {
        state_ = RfidState::kDone;
        amplitude_ = 0.0;
      }
      break;
    default:
      break;
  }
  out.data_valid = data_valid_;
  out.latched = latched_;
  out.state = state_;
  return out;
}

core::FrequencyResponse RfidBlock::frequency_response() const {
  std::vector<MeasuredPoint> sorted(points_.begin(), points_.end());
  std::stable_sort(sorted.begin(), sorted.end(), [](const MeasuredPoint& a, const MeasuredPoint& b) { return a.omega < b.omega; });
  core::FrequencyResponse response;
  response.quality_kind = core::QualityKind::kThd;
  response.duration_s = elapsed_s();
  for (const MeasuredPoint& m : sorted) {
    core::FrequencyPoint point;
    point.freq_hz = m.omega / kTwoPi;
    point.value = m.response;
    point.quality = m.thd;
    point.snr = m.snr;
    point.amplitude = m.amplitude;
    const double thd_limit = p_.thd_threshold + p_.thd_hysteresis;
    std::string why;
    if (m.thd > thd_limit) why = fmt_reason("THD {:.3g} above {:.3g}", m.thd, thd_limit);
    if (m.snr < kMinimumSnr) why += (why.empty() ? "" : ", ") + fmt_reason("SNR {:.3g} below {:.3g}", m.snr, kMinimumSnr);
    if (!why.empty()) {
      point.valid = false;
      point.note = why + fmt_reason(" at amplitude {:.4g}", m.amplitude) +
                   (m.amplitude_limited ? " (the amplitude could not rise: ceiling or range limit)" : "") +
                   (m.settled ? "" : "; latched at the settling-time limit");
    }
    if (!response.points.empty() && response.points.back().freq_hz >= point.freq_hz) response.points.back() = point;
    else response.points.push_back(point);
  }
  return response;
}

}  // namespace servotwin::frf
