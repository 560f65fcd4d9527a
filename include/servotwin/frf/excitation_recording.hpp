#pragma once
/// \file
/// Reading back a drive's recording of an excitation (issue 25 §4): where the played sequence
/// sits in the recording, the period of a periodic recording when the sequence is not at hand,
/// and the frequency response of each excitation type — per-period DFTs for a periodic multisine
/// or chirp (leakage-free, offline.hpp), H1 for a single chirp, a single-line DFT per step for
/// stepped sines.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/frf/excitation_design.hpp"

namespace servotwin::frf {

/// Where the excitation's first sample lies in a recording of the played input.
struct Alignment {
  /// Recording index of excitation sample 0 (negative when the recording started after it).
  std::ptrdiff_t offset = 0;
  /// Least-squares gain of the recording on the shifted excitation (the drive may scale or
  /// invert what it plays; a negative gain is an inverted input).
  double gain = 0.0;
  /// Correlation coefficient of the recording with the gain-scaled excitation over the overlap.
  double correlation = 0.0;
  std::size_t overlap = 0;  ///< samples where the two overlap
};

/// Finds the shift with the largest |cross-correlation| among those overlapping at least half of
/// the excitation or of the recording (FFT-based, O((n+m) log(n+m))). core::InputError naming
/// "input" when the best correlation coefficient is below 0.9: the recording's input column does
/// not hold the excitation.
Alignment align_excitation(std::span<const double> recorded_input, std::span<const double> excitation);

/// Period found in a recording of a periodic signal.
struct PeriodDetection {
  std::size_t period_samples = 0;  ///< 0 when no period was found
  double correlation = 0.0;        ///< normalized autocorrelation at that lag (1 = exactly periodic)
};

/// The shortest lag (at least `min_period` samples, at most half the record) whose normalized
/// autocorrelation is a local maximum within 0.02 of the largest value over all such lags, and
/// at least 0.8 (otherwise period_samples = 0): for a multisine played P times the
/// autocorrelation is close to 1 at every multiple of the period.
PeriodDetection detect_period(std::span<const double> x, std::size_t min_period = 8);

/// Options of estimate_recorded.
struct RecordedOptions {
  /// Periodic excitations: leading periods dropped as transient (the plant's response to the
  /// start of the sequence).
  std::size_t skip_periods = 1;
};

/// The response estimated from a recording and how it was read.
struct RecordedEstimate {
  core::FrequencyResponse response;
  Alignment alignment;
  std::size_t periods_used = 0;    ///< periodic excitations
  std::size_t steps_used = 0;      ///< sine steps whose windows lie in the recording
  std::string method;              ///< one line: which estimator, for the output's comments
};

/// Aligns `excitation` with the recorded input `x` and estimates y/x as the excitation type
/// allows; x and y have the excitation's sample period. core::InputError naming "input" (no
/// alignment), "output" or "skip_periods" (fewer than 2 whole periods after the skipped ones, or
/// fewer than 2 steps, left in the recording).
RecordedEstimate estimate_recorded(const Excitation& excitation, std::span<const double> x,
                                   std::span<const double> y, const RecordedOptions& options = {});

/// Stepped-sine estimate: per step, the single-line DFT of x and y over the measuring window
/// (starting at `offset` + begin + settle in the recording); G = Y/X. quality = THD of y (the
/// 2nd … 5th harmonics over the fundamental), std_dev from the residual after the DC, the
/// fundamental and those harmonics (white noise of variance σ² gives a line variance of N·σ²).
/// Steps whose window is not wholly inside the recording are left out. quality_kind = kThd.
core::FrequencyResponse estimate_sine_steps(std::span<const double> x, std::span<const double> y, double ts,
                                            const std::vector<SineStep>& steps, std::ptrdiff_t offset);

}  // namespace servotwin::frf
