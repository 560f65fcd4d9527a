#pragma once
/// \file
/// The real-time frequency-response identification block (dissertation C5.13, "RFID"): a swept
/// sine with adaptive amplitude drives the actuator, the harmonic observer estimates the response,
/// and a sweep/measure state machine latches steady-state response points at listed frequencies
/// and at resonances and antiresonances it detects on the way.
///
/// Per sample the block takes (start, pv, cv) and returns mv and the estimates; step() is
/// allocation-free and exception-free. All parameter checking happens in the constructor.
///
/// Timing convention: pv(k) is the output measured at sample k (the response to mv(0..k-1));
/// mv(k) = A(k) sin(theta_k) + u0 + cv(k) is applied from sample k on. The response point is
/// therefore the response of the sampled loop, P(e^{j omega Ts}) of the zero-order-hold
/// discretized plant (for a continuous plant it includes the hold's half-sample delay).
///
/// Safety: |mv - u0 - cv| never exceeds max_amplitude (the excitation term is clamped), |mv|
/// never exceeds actuator_limit, and when pv leaves [output_min, output_max], an input is not
/// finite, or start falls during a run, the block aborts: the excitation stops at once and mv
/// becomes cv (semi-closed/closed loop keeps the plant stabilized) or 0 (AbortAction::kZero).

#include <array>
#include <complex>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/frf/amplitude_adaptation.hpp"
#include "servotwin/frf/excitation.hpp"
#include "servotwin/frf/harmonic_observer.hpp"
#include "servotwin/frf/observer_gains.hpp"
#include "servotwin/frf/settle_windows.hpp"

namespace servotwin::frf {

/// What the block does with mv after an abort.
enum class AbortAction {
  kControllerOnly,  ///< mv = cv (clamped to the actuator limit): the stabilizing loop stays closed
  kZero,            ///< mv = 0
};

/// User parameters of the block. Frequencies in rad/s, times in s.
struct RfidParameters {
  double ts = 0.0;                   ///< sample period [s]
  double omega_begin = 0.0;          ///< sweep start [rad/s], > 0
  double omega_end = 0.0;            ///< sweep end [rad/s], < pi/(5 ts) so the 5th harmonic is below Nyquist
  double initial_amplitude = 0.0;    ///< A(0), > 0
  double dc_offset = 0.0;            ///< u0 added to the excitation (open-loop working point)
  /// Raised-cosine fade-in of the excitation over this many periods of the first frequency
  /// (0 = start at A(0) at once, as the document does). A sine switched on at full amplitude
  /// gives an integrating plant (a free inertia's velocity) a DC offset A/(J omega) that friction
  /// and the observer's DC channel take seconds to absorb at low frequencies; fading in avoids it.
  double fade_in_periods = 0.0;
  SweepType sweep_type = SweepType::kLogarithmic;
  double sweep_rate = 0.0;           ///< linear: rad/s per sample; logarithmic: sc [1/s]
  double settling_time_s = 0.0;      ///< minimum wait in measurement mode after omega or A last changed
  double max_settling_time_s = 0.0;  ///< give up waiting and latch (flagged not settled); 0 = 5 x settling_time_s
  /// Give up after this many periods of the point's frequency too, but not before 2 s, when that
  /// is shorter (0: no such limit): at the lowest frequencies a point that has not settled in a
  /// few periods is friction- or noise-bound, and the time limit alone costs seconds per such point
  /// (issue 25 §1); above a few hertz lightly damped modes need more periods than that.
  double max_settling_periods = 0.0;
  double settle_tolerance = 0.005;   ///< settled when |P(now) - P(half a period ago)| <= tol/2 |P(now)| + noise_level/(4 A)
  std::vector<double> measurement_frequencies;  ///< strictly increasing, inside [omega_begin, omega_end]
  ObserverDesign observer;           ///< estimator bandwidth (Kalman V or Butterworth alpha0)
  double thd_threshold = 0.1;        ///< THD* of the amplitude relay
  double thd_hysteresis = 0.02;      ///< h, 0 <= h < THD*
  double amplitude_rate = 0.2;       ///< rc: relative amplitude increment per period
  bool proportional_growth = false;  ///< AmplitudeLaw::proportional: rc A(t) instead of rc A(t0) per period
  double amplitude_growth_per_second = 0.0;  ///< AmplitudeLaw::growth_per_second (with proportional growth)
  double output_min = -std::numeric_limits<double>::infinity();  ///< allowed pv range (abort outside)
  double output_max = std::numeric_limits<double>::infinity();
  double range_margin = 0.8;         ///< reduce A when the predicted output peak uses this fraction of the range
  double max_amplitude = 0.0;        ///< ceiling of A (actuator/current limit of the excitation), >= A(0)
  double actuator_limit = std::numeric_limits<double>::infinity();  ///< |mv| ceiling
  double noise_level = 0.0;          ///< sensor noise amplitude A_n for SNR = A1/A_n; 0 = unknown (SNR = 1/THD)
  bool detect_extrema = true;        ///< add points at resonances and antiresonances found while sweeping
  double extremum_prominence = 0.25; ///< relative rise/fall of |P| that confirms an extremum
  std::size_t max_extra_points = 8;  ///< capacity for detected points
  AbortAction abort_action = AbortAction::kControllerOnly;
};

enum class RfidState { kIdle, kSweep, kSettle, kRampOut, kDone, kAborted };
enum class AbortReason { kNone, kOutputOutOfRange, kNonFiniteInput, kStoppedByUser };
/// Why a point was measured.
enum class PointKind { kListed, kResonance, kAntiresonance };

/// One latched response point.
struct MeasuredPoint {
  double omega = 0.0;                  ///< rad/s
  std::complex<double> response;       ///< P(j omega) = (A1/A) e^{j phi1}
  double thd = 0.0;
  double snr = 0.0;
  double amplitude = 0.0;              ///< excitation amplitude A at the latch
  double dc = 0.0;                     ///< A0 (DC estimate) at the latch
  double time_s = 0.0;                 ///< time since the start edge
  PointKind kind = PointKind::kListed;
  bool settled = true;                 ///< false: latched at max_settling_time_s without converging
  bool amplitude_limited = false;      ///< THD above THD* + h but the amplitude could not rise
};

/// Outputs of one step (the document's mv, xres/xims, xrem/ximm, DAV, A0..A5 plus diagnostics).
struct RfidOutput {
  double mv = 0.0;                     ///< actuator command
  std::complex<double> running;        ///< running estimate (valid for experiment control only)
  std::complex<double> latched;        ///< last latched point
  bool data_valid = false;             ///< DAV: true on the sample a new point is latched
  std::array<double, 6> harmonics{};   ///< A0 (signed DC estimate, the semi-closed-loop feedback), A1..A5
  double omega = 0.0;                  ///< excitation frequency of this sample [rad/s]
  double amplitude = 0.0;              ///< excitation amplitude of this sample
  double thd = 0.0;
  RfidState state = RfidState::kIdle;
};

/// The RFID block.
class RfidBlock {
 public:
  /// Validates every parameter (throws core::InputError naming the field) and designs the
  /// observer gains; all memory the run needs is allocated here.
  explicit RfidBlock(RfidParameters parameters);

  /// One sample. start: a rising edge starts a run (also after done/aborted; a falling edge
  /// during a run aborts it); pv: measured output; cv: stabilizing controller output, added to mv.
  RfidOutput step(bool start, double pv, double cv) noexcept;

  [[nodiscard]] RfidState state() const noexcept { return state_; }
  [[nodiscard]] AbortReason abort_reason() const noexcept { return abort_reason_; }
  /// Points latched in this run, in the order they were measured.
  [[nodiscard]] std::span<const MeasuredPoint> points() const noexcept { return points_; }
  /// The latched points as a response (sorted by frequency; a repeated frequency keeps the later
  /// point), quality = THD, with the run's duration. Allocates; not for the per-sample path.
  /// A point is invalid (FrequencyPoint::valid, issue 25 §1) when the amplitude adaptation could
  /// not bring it within its limits: THD above THD* + h at the latch (friction, backlash or noise
  /// still dominating the response), or SNR below kMinimumSnr; the note says which and whether
  /// the amplitude was held by its ceiling or the range protection.
  [[nodiscard]] core::FrequencyResponse frequency_response() const;
  /// Fewest A1/noise a valid point has: at 3 the noise moves the phase by up to 19°.
  static constexpr double kMinimumSnr = 3.0;
  /// The least settling limit that max_settling_periods can set [s].
  static constexpr double kMinimumPeriodLimit_s = 2.0;
  /// Seconds since the start edge (frozen when the run ends).
  [[nodiscard]] double elapsed_s() const noexcept { return static_cast<double>(run_samples_) * p_.ts; }
  [[nodiscard]] const RfidParameters& parameters() const noexcept { return p_; }
  [[nodiscard]] const HarmonicObserver& observer() const noexcept { return observer_; }

 private:
  struct ExtremumDetector {
    enum class Mode { kUnknown, kSeekMax, kSeekMin } mode = Mode::kUnknown;
    double max = 0.0, max_omega = 0.0, min = 0.0, min_omega = 0.0;
    long holdoff = 0;
  };

  void start_run() noexcept;
  void abort_run(AbortReason reason) noexcept;
  void enter_settle() noexcept;
  void advance_sweep(double magnitude) noexcept;
  void advance_settle(std::complex<double> running, double thd) noexcept;
  void latch(std::complex<double> running, double thd, bool settled) noexcept;
  double limit_usage(double pv, double cv) const noexcept;
  double idle_command(double cv) const noexcept;
  [[nodiscard]] long period_samples(double omega) const noexcept;
  /// The settling limit at the current frequency: max_settling_time_s, or max_settling_periods
  /// periods when that is shorter (computed on entering a point: settle_limit_).
  [[nodiscard]] long max_settle_limit() const noexcept;
  double fade_in_factor() noexcept;

  RfidParameters p_;
  HarmonicObserver observer_;
  SineGenerator generator_;
  SweepSchedule sweep_;
  AmplitudeAdapter adapter_;

  RfidState state_ = RfidState::kIdle;
  AbortReason abort_reason_ = AbortReason::kNone;
  bool previous_start_ = false;
  double omega_;
  double amplitude_ = 0.0;
  std::size_t next_listed_ = 0;
  long run_samples_ = 0;
  long fade_length_ = 0, fade_done_ = 0;
  long settle_samples_ = 0, max_settle_samples_ = 0;
  // measurement mode
  long settle_elapsed_ = 0, settle_total_ = 0, period_count_ = 0, period_length_ = 1;
  std::complex<double> period_mark_;
  bool period_converged_ = false;
  SettleWindows windows_;              ///< half-period means since the last change (settle_windows.hpp)
  std::size_t max_window_ = 0;         ///< the longest window in half periods at this frequency
  long settle_limit_ = 0;              ///< max_settle_limit() at this frequency
  bool window_converged_ = false;
  std::complex<double> window_mean_;
  PointKind settle_kind_ = PointKind::kListed;
  double resume_omega_ = 0.0;
  std::size_t extra_points_ = 0;
  ExtremumDetector detector_;
  // ramp-out
  long ramp_left_ = 0, ramp_length_ = 1;
  double ramp_from_ = 0.0;
  std::complex<double> latched_;
  bool data_valid_ = false;
  std::vector<MeasuredPoint> points_;
};

}  // namespace servotwin::frf
