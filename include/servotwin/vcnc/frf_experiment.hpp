#pragma once
/// \file
/// The virtual frequency-response experiment: the real-time identification block (frf::RfidBlock)
/// drives a simulated flexible plant (machine::FlexiblePlant) sample by sample, exactly as a
/// drive's cyclic task would step it against the real mechanics. Used by `servotwin frf measure`,
/// the tests of the block's end-to-end behaviour and the frequency-identification study.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/frf/rfid_block.hpp"
#include "servotwin/machine/flexible_plant.hpp"

namespace servotwin::vcnc {

/// What a user states about an experiment; everything else is derived (experiment_parameters).
struct FrfExperimentSettings {
  double f_begin_hz = 1.0;      ///< first frequency [Hz]
  double f_end_hz = 500.0;      ///< last frequency [Hz]; below fs/10 so the 5th harmonic stays below Nyquist
  std::size_t points = 30;      ///< listed measurement frequencies, logarithmically spaced, ends included (>= 2)
  /// Excitation amplitude at the start (input units, e.g. N m). Empty: chosen from the plant so
  /// that the response at f_begin stands 300 times above the measurement noise.
  std::optional<double> amplitude;
  /// Ceiling of the excitation amplitude. Empty: 100 x the initial amplitude.
  std::optional<double> max_amplitude;
  /// Allowed output range +-output_limit (abort outside). Empty: 20 x the largest output
  /// amplitude the initial amplitude gives over the range (the plant's linear model), so the
  /// amplitude adaptation meets the range protection before the limit.
  std::optional<double> output_limit;
  /// Time the logarithmic sweep alone takes from f_begin to f_end [s]; 0: max(8 s, 8 periods of
  /// f_begin), so the sweep never outruns the observer at the lowest frequencies.
  double sweep_time_s = 0.0;
  double thd_threshold = 0.05;  ///< THD* of the amplitude adaptation
  /// The simulation stops (and says so) after this much experiment time [s]; 0: max(120 s,
  /// 200 periods of f_begin + 4 sweep times) — a point needs a few periods of its frequency.
  double max_time_s = 0.0;
  frf::ObserverDesign observer; ///< estimator bandwidth
  /// Semi-closed loop (C5.12) for velocity outputs: a proportional loop on the observer's DC
  /// estimate A0 (not on the measured output, so the harmonics it measures are untouched) holds
  /// the mean velocity at zero. Without it, switching the sine on leaves a free inertia with a
  /// mean velocity that friction takes seconds to remove at the lowest frequencies. Its gain
  /// gives a loop bandwidth of f_begin/4 on the plant's rigid inertia, well below the DC
  /// channel's bandwidth (about 2.8 x f_begin), so loop and measurement do not interact.
  bool hold_dc = true;
};

/// One sample of the experiment, for `--trace`.
struct FrfTraceSample {
  double t = 0.0;          ///< time since the start [s]
  double mv = 0.0;         ///< actuator command
  double pv = 0.0;         ///< measured output
  double f_hz = 0.0;       ///< excitation frequency
  double amplitude = 0.0;  ///< excitation amplitude
  double thd = 0.0;
  frf::RfidState state = frf::RfidState::kIdle;
};

/// The outcome of a run.
struct FrfExperiment {
  core::FrequencyResponse response;          ///< latched points, duration_s = experiment time
  std::vector<frf::MeasuredPoint> points;    ///< in measurement order, with their kind
  frf::RfidState final_state = frf::RfidState::kIdle;
  frf::AbortReason abort_reason = frf::AbortReason::kNone;
  bool timed_out = false;                    ///< max_time_s reached before the block finished
  frf::RfidParameters parameters;            ///< what the block ran with
  std::vector<FrfTraceSample> trace;         ///< every sample when asked for, else empty
  double dc_gain = 0.0;                      ///< gain of the semi-closed loop (0 = open loop)
};

/// The block parameters for `plant` and `settings`: listed frequencies, sweep coefficient, the
/// settling time from the plant's slowest lightly damped mode in the range, amplitudes and output
/// range from the plant's linear model and noise level. core::InputError naming the setting
/// ("--range-hz", "--points", "--amplitude", ...) when the request cannot be measured at the
/// plant's sample period.
frf::RfidParameters experiment_parameters(const machine::FlexiblePlant& plant, const FrfExperimentSettings& settings);

/// Progress callback: (experiment time [s], points latched so far, current frequency [Hz]).
using FrfProgress = std::function<void(double, std::size_t, double)>;

/// experiment_parameters for the block inside a velocity loop: its signal is the reference, which
/// the loop follows with |T| close to 1 in its band, so the start amplitude is 300 × the noise
/// floor (or settings.amplitude), the ceiling 100 × that, and the output range 3 × the ceiling
/// (or settings.output_limit).
frf::RfidParameters closed_loop_parameters(const machine::FlexiblePlant& plant, const FrfExperimentSettings& settings);

/// The sweep time and the time limit with their automatic values resolved (see the settings).
double sweep_time(const FrfExperimentSettings& settings);
double time_limit(const FrfExperimentSettings& settings);

/// Gain of the semi-closed loop for `plant` and `settings` (0 when hold_dc is off, when the output
/// is a position, which would need a stabilizing position loop the plant description lacks, or when
/// the plant does not integrate below f_begin: |P(j w/10)| < 5 |P(j w)|).
double dc_hold_gain(const machine::FlexiblePlant& plant, const FrfExperimentSettings& settings);

/// Runs the block against the plant from rest until it is done, aborts or max_time_s passes,
/// with cv = -dc_gain A0 (0: open loop). The plant is reset first. `progress` (optional) is
/// called about once per simulated second.
FrfExperiment run_frf_experiment(machine::FlexiblePlant& plant, const frf::RfidParameters& parameters,
                                 double max_time_s, bool keep_trace, double dc_gain = 0.0,
                                 const FrfProgress& progress = {});

/// The block inside a velocity loop (issue 25 §3): its excitation is the velocity reference ω*,
/// `controller` (discrete at the plant's period, inputs [ω*, y], output the torque command) drives
/// the plant, and the block measures the closed loop T = y/ω*. Each point becomes the plant's
/// response P = T/(C_r + T·C_y), with C_r and C_y the controller's responses at e^{jωts} (the
/// indirect method with a known controller, Ljung 1999 §13.5: u = C_r ω* + C_y y and y = P u);
/// its THD and SNR are those of the measured T. No semi-closed loop: the loop holds the mean.
/// core::InputError naming "controller" when it does not have two inputs and one output, its
/// period differs from the plant's, the plant does not measure a velocity, or the discrete loop
/// of the plant's linear part, its input delay and the controller is unstable (the largest |z|
/// named; loops of more than 200 states, i.e. long delays, are left to the run's range abort).
/// The SNR of each plant point is the measured T's over |1 − P·C_y| (δP/P = (δT/T)(1 − P·C_y)),
/// and a point whose plant SNR falls below RfidBlock::kMinimumSnr is marked invalid.
FrfExperiment run_frf_experiment_closed_loop(machine::FlexiblePlant& plant, const frf::RfidParameters& parameters,
                                             double max_time_s, const core::DiscreteStateSpace& controller,
                                             bool keep_trace, const FrfProgress& progress = {});

/// "listed", "resonance", "antiresonance".
std::string point_kind_name(frf::PointKind kind);
/// "done", "aborted: output out of range", ...
std::string outcome_text(const FrfExperiment& experiment);

}  // namespace servotwin::vcnc
