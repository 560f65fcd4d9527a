#pragma once
/// \file
/// Excitation signals for a drive's own signal generator (issue 25 §4): a sampled sequence the
/// drive plays at its sample period while it records its response, designed so that the offline
/// estimators (offline.hpp) get a leakage-free response from the recording.
///
/// * Multisine: equal amplitudes on chosen DFT lines of one period of N samples, repeated P
///   times. Phases start from Schroeder's rule (M. R. Schroeder, "Synthesis of low-peak-factor
///   signals and binary sequences with low autocorrelation", IEEE Trans. Inf. Theory 16(1), 1970,
///   eq. 11) and are then improved by the time-frequency swapping ("clipping") iteration of
///   E. Van der Ouderaa, J. Schoukens, J. Renneboog, "Peak factor minimization using a
///   time-frequency domain swapping algorithm", IEEE Trans. Instrum. Meas. 37(1), 1988, which
///   keeps the amplitude spectrum exactly and lowers the crest factor (Pintelon & Schoukens 2012,
///   section 5.4.3).
/// * Log chirp: f(t) = f_b (f_e/f_b)^{t/T} over one period, phase ending on a multiple of 2π so
///   the signal starts and ends at 0 (and a repeated chirp is continuous).
/// * Sine steps: one sine per frequency, log spaced, each with a settling part and a measuring
///   part of whole cycles (the frequency is moved onto that window's DFT line, so a single-line
///   DFT is leakage-free); the phase runs on across steps, so the signal never jumps.
///
/// `amplitude` is the peak value: max |u| equals it exactly. Algorithms only; file I/O lives in
/// io/excitation_csv.hpp.

#include <cstddef>
#include <string_view>
#include <vector>

namespace servotwin::frf {

/// Kind of excitation.
enum class ExcitationType { kMultisine, kChirp, kSineSteps };

/// How a multisine's lines are spaced.
enum class LineSpacing {
  kLinear,       ///< every DFT line of the period in the range
  kLogarithmic,  ///< a quasi-logarithmic subset, `lines_per_decade` distinct lines per decade
};

/// What to design. Frequencies in Hz, times in s.
struct ExcitationRequest {
  ExcitationType type = ExcitationType::kMultisine;
  double f_begin_hz = 0.0;  ///< lowest excited frequency, > 0
  double f_end_hz = 0.0;    ///< highest excited frequency, below the Nyquist frequency 1/(2 ts)
  double ts = 0.0;          ///< the drive's sample period
  double duration_s = 0.0;  ///< total length of the sequence
  double amplitude = 0.0;   ///< peak value, > 0
  /// Multisine and chirp: periods in the sequence. 0 = multisine: as many as fit with a line
  /// spacing of at most f_begin_hz; chirp: 1 (a single sweep).
  std::size_t periods = 0;
  LineSpacing spacing = LineSpacing::kLinear;
  std::size_t lines_per_decade = 30;  ///< for LineSpacing::kLogarithmic
  /// Sine steps: number of frequencies; 0 = 10 per decade (at least 2).
  std::size_t steps = 0;
  /// Sine steps: fraction of each step spent settling before the measuring window, in [0, 1).
  double settle_fraction = 0.25;
  /// Multisine: swapping iterations after Schroeder's phases (0 = Schroeder's phases alone).
  std::size_t crest_iterations = 200;
};

/// One frequency of a sine-steps excitation. Sample indices count from the sequence's start.
struct SineStep {
  double freq_hz = 0.0;           ///< the played frequency: cycles / (measure_samples · ts)
  std::size_t begin = 0;          ///< first sample of the step
  std::size_t settle_samples = 0; ///< samples before the measuring window
  std::size_t measure_samples = 0;///< length of the measuring window
  std::size_t cycles = 0;         ///< whole cycles in the measuring window (its DFT line)
};

/// A designed excitation.
struct Excitation {
  ExcitationType type = ExcitationType::kMultisine;
  double ts = 0.0;
  double amplitude = 0.0;            ///< peak value, max |samples|
  std::vector<double> samples;       ///< the sequence to play, sample k at time k·ts
  /// Multisine and chirp: samples per period and the number of periods (samples.size() = their
  /// product); 0 for sine steps.
  std::size_t period_samples = 0;
  std::size_t periods = 0;
  /// Multisine: the excited DFT lines of one period (line k is k/(period_samples·ts) Hz).
  std::vector<std::size_t> lines;
  std::vector<SineStep> steps;       ///< sine steps only
  double f_begin_hz = 0.0, f_end_hz = 0.0;  ///< the requested range
  double crest_factor = 0.0;         ///< max |u| / rms(u) of the sequence
  /// Multisine: the crest factor of Schroeder's phases alone (what the swapping improved on).
  double schroeder_crest_factor = 0.0;
};

/// Designs the excitation. Throws core::InputError naming the field ("f_begin_hz", "f_end_hz",
/// "ts", "duration_s", "amplitude", "periods", "steps", "lines_per_decade", "settle_fraction")
/// when the request cannot be met: a range not inside (0, Nyquist), a duration too short for two
/// periods at the range's resolution (multisine), for one period of the lowest frequency
/// (chirp) or for three cycles per step (sine steps) — the message gives the smallest duration
/// that works — or a sequence longer than 100 M samples.
Excitation design_excitation(const ExcitationRequest& request);

/// Crest factor max|u| / rms(u) (0 for an empty or all-zero sequence).
double crest_factor(const std::vector<double>& u) noexcept;

/// "multisine", "chirp", "sine-steps".
std::string_view excitation_type_name(ExcitationType type) noexcept;

namespace detail {
/// The parts of design_excitation, one per type (the request is already checked).
Excitation design_multisine(const ExcitationRequest& request);
Excitation design_chirp(const ExcitationRequest& request);
Excitation design_sine_steps(const ExcitationRequest& request);
/// Scales `e.samples` to peak `amplitude` and fills amplitude and crest_factor.
void scale_to_peak(Excitation& e, double amplitude);
}  // namespace detail

}  // namespace servotwin::frf
