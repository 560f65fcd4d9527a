#pragma once
/// \file
/// Offline frequency-response estimation from recorded input/output data (seed2 catalog C3.16
/// "nonparametric: G = Suy/Suu"): the averaged H1 estimator with Welch segments for broadband
/// excitation (noise, chirp, PRBS), and the per-period DFT estimator for periodic multisines
/// (Pintelon & Schoukens, "System Identification: A Frequency Domain Approach", 2nd ed. 2012,
/// sections 2.4 and 7.2). Both return core::FrequencyResponse with coherence-like quality, the
/// standard deviation of every point and its SNR.
///
/// Conventions shared by both estimators:
/// * `x` is the input (excitation), `y` the output; the response is y over x.
/// * `ts` is the sample period [s]; frequencies are printed in Hz (`freq_hz`).
/// * `FrequencyPoint::std_dev` is the square root of the complex variance E|Ĥ − H|² (the error is
///   circular, so Re and Im each have variance std_dev²/2); see magnitude_std and phase_std_rad.
/// * `FrequencyPoint::snr` = |Ĥ| / std_dev (linear amplitude ratio; 0 when std_dev is exactly 0,
///   i.e. when no noise was observed and the ratio is not measurable).
/// * `FrequencyResponse::duration_s` = the whole record given, samples × ts.
/// * Bad input (too short, constant input, inconsistent options) throws core::InputError naming
///   the option (`segment`, `periods`, ...) or the signal (`input`, `output`).

#include <complex>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "servotwin/core/frequency_response.hpp"

namespace servotwin::frf {

/// Data window applied to each Welch segment.
enum class Window {
  kHann,         ///< periodic Hann, 0.5 − 0.5 cos(2πn/L) (scipy.signal.get_window("hann", L))
  kRectangular,  ///< no window (exact for signals periodic in the segment)
};

/// What is removed from each segment (H1) or from the record (multisine) before the DFT.
enum class Detrend {
  kNone,
  kMean,    ///< the mean (scipy detrend="constant")
  kLinear,  ///< a least-squares straight line (scipy detrend="linear"); for multisines the drift
            ///< line through the period means, see MultisineOptions::detrend
};

/// Settings of the H1 (Welch) estimator.
struct WelchOptions {
  /// Samples per segment; 0 = the largest power of two that still gives at least 8 segments at
  /// the chosen overlap (at least 16 samples, at most the record).
  std::size_t segment_length = 0;
  /// Overlap of consecutive segments as a fraction of the segment, in [0, 1).
  double overlap = 0.5;
  Window window = Window::kHann;
  /// Removed per segment before windowing (scipy's default is the mean).
  Detrend detrend = Detrend::kMean;
  /// Range of the returned lines [Hz]; the DC line is never returned.
  double min_freq_hz = 0.0;
  double max_freq_hz = std::numeric_limits<double>::infinity();
};

/// Averaged one-sided spectral densities of a Welch estimate, scaled as scipy.signal.csd /
/// welch with scaling="density": units² per Hz, non-DC, non-Nyquist lines doubled,
/// `sxy` = E[conj(X)·Y]. Index k is the line k·df_hz, k = 0 … segment_length/2.
struct WelchSpectra {
  double df_hz = 0.0;
  std::size_t segment_length = 0;
  std::size_t segments = 0;          ///< number of averaged segments
  double effective_averages = 0.0;   ///< independent averages equivalent to the overlapped segments (Welch 1967)
  std::vector<double> sxx, syy;
  std::vector<std::complex<double>> sxy;
  /// Sum of the window and of its squares, to convert densities to other scalings.
  double window_sum = 0.0, window_square_sum = 0.0;
};

/// How a record of `samples` samples is cut into Welch segments (what welch_spectra averages), without
/// computing any spectrum: for messages and reports.
struct WelchLayout {
  double df_hz = 0.0;
  std::size_t segment_length = 0;
  std::size_t segments = 0;
  double effective_averages = 0.0;
};
/// The layout welch_spectra() uses for a record of `samples` samples at period ts. core::InputError
/// for options out of range (as welch_spectra).
WelchLayout welch_layout(std::size_t samples, double ts, const WelchOptions& options = {});

/// Welch-averaged auto and cross spectra of x and y (same length, at least 16 samples).
WelchSpectra welch_spectra(std::span<const double> x, std::span<const double> y, double ts,
                           const WelchOptions& options = {});

/// Magnitude-squared coherence |Sxy|² / (Sxx·Syy) of line k (0 when either auto spectrum is 0).
double coherence(const WelchSpectra& spectra, std::size_t k);

/// H1 = Sxy/Sxx with Welch averaging. Per point: quality = coherence γ²; std_dev from Bendat &
/// Piersol (Random Data, 4th ed., Table 9.6: ε[|Ĥ|] = σ[φ̂] = √(1−γ²)/(|γ|√(2n))), written as
/// E|Ĥ−H|² = 2ε²|Ĥ|² = (1−γ²)·Syy/(n·Sxx) so that it stays finite at γ = 0, with n the effective
/// number of averages; amplitude = the amplitude
/// of a sine on that line giving the same input power (sqrt(2·Sxx) in spectrum scaling), so a
/// pure sine of amplitude A centred on a line reports A. Lines where Sxx is exactly 0 are left
/// out. quality_kind = kCoherence.
core::FrequencyResponse estimate_h1(std::span<const double> x, std::span<const double> y, double ts,
                                    const WelchOptions& options = {});

/// The H1 response of spectra already computed by welch_spectra (what estimate_h1 returns);
/// `samples` is the record length, for duration_s.
core::FrequencyResponse h1_from_spectra(const WelchSpectra& spectra, double ts, std::size_t samples,
                                        const WelchOptions& options = {});

/// Standard deviation of |Ĥ| of a point (the circular error's radial part: std_dev/√2).
double magnitude_std(const core::FrequencyPoint& point);
/// Standard deviation of arg Ĥ [rad] (std_dev/(√2·|Ĥ|), the small-error approximation of
/// Bendat & Piersol Table 9.6; infinity for a zero point).
double phase_std_rad(const core::FrequencyPoint& point);

/// Settings of the periodic (multisine) estimator.
struct MultisineOptions {
  /// Samples per period; 0 = record length / `periods` (rounded down).
  std::size_t period_samples = 0;
  /// Whole periods in the record; 0 = as many as fit. At least one of the two must be given.
  std::size_t periods = 0;
  /// Leading periods dropped as transient.
  std::size_t skip_periods = 0;
  /// kLinear removes a drift line fitted through the means of the used periods: for a periodic
  /// signal plus a drift a + b·t the period means are exactly affine in the period index, so the
  /// drift is removed without biasing the excited lines (a least-squares line through the samples
  /// would correlate with the periodic part). kMean and kNone change only the DC line, which is
  /// never returned.
  Detrend detrend = Detrend::kLinear;
  /// Excited lines are those within this many dB of the strongest input line (a negative
  /// number, e.g. −20). Empty = automatic: among the lines whose mean input stands 20 dB above
  /// its period-to-period scatter (|X̄|² > 100·σ²_X/P), the largest gap in the sorted line powers
  /// above max − 60 dB separates excited from non-excited lines (at least 6 dB wide, else an
  /// error naming `input`).
  std::optional<double> excitation_threshold_db;
  /// Explicit DFT lines (1 … period/2) to use instead of detection.
  std::vector<std::size_t> excited_lines;
};

/// The per-period estimate with its noise analysis.
struct MultisineEstimate {
  /// Points on the excited lines. quality = coherence equivalent 1/(1 + P·σ²_G/|G|²) (equal to
  /// the magnitude-squared coherence when the noise is on the output only); std_dev = σ_G;
  /// snr = |G|/σ_G; amplitude = 2|Û|/N, the input amplitude of that line (|Û|/N at Nyquist).
  core::FrequencyResponse response;
  std::vector<std::size_t> lines;                ///< DFT line index of each point
  /// Sample (co)variances over the periods of one period's unnormalised DFT
  /// (X(k) = Σ x[n] e^{−j2πkn/N}), per point: for white noise of variance σ² they equal N·σ².
  std::vector<double> noise_var_x, noise_var_y;
  std::vector<std::complex<double>> noise_cov_yx;  ///< E[(Y−Ȳ)·conj(X−X̄)]
  std::size_t period_samples = 0;
  std::size_t periods_used = 0;                  ///< P, after skipping
  std::size_t periods_skipped = 0;
  std::size_t samples_dropped = 0;               ///< trailing samples that do not fill a period
  double df_hz = 0.0;                            ///< line spacing 1/(N·ts)
};

/// Averages the DFTs of the periods, estimates the noise (co)variances from the period-to-period
/// scatter and returns G = Ȳ/X̄ on the excited lines with
/// σ²_G = |G|²/P·(σ²_Y/|Ȳ|² + σ²_X/|X̄|² − 2·Re(σ²_YX/(Ȳ·conj X̄)))  (Pintelon & Schoukens 2012, section 2.4,
/// sample means and sample (co)variances over the P periods).
/// Needs at least 2 used periods. quality_kind = kCoherence.
MultisineEstimate estimate_multisine(std::span<const double> x, std::span<const double> y, double ts,
                                     const MultisineOptions& options);

/// Closed-loop estimate of a plant from a record taken inside a loop whose reference r was excited
/// (issue 25 §3): the indirect (joint input-output) method P = S_ry / S_ru with Welch-averaged
/// cross spectra (Pintelon & Schoukens 2012, section 2.6.4; L. Ljung, "System Identification",
/// 2nd ed. 1999, section 13.5). Measurement and process noise feed back into u, so the open-loop
/// H1 = S_uy/S_uu is biased (towards −1/C where the noise dominates); r is uncorrelated with the
/// noise, so the ratio of the cross spectra with r is not.
/// Per point: quality = min(γ²_ru, γ²_ry), the weaker coherence of the two paths; std_dev from
/// first-order propagation, E|P̂ − P|² = S_zz·S_rr / (n·|S_ru|²) with z = y − P̂u (the part of y
/// not explained by the plant, uncorrelated with r) and n the effective number of averages;
/// amplitude = the reference's, as in estimate_h1. Lines where S_ru is 0 are left out.
/// quality_kind = kCoherence. r, u, y of the same length (core::InputError naming "reference"
/// otherwise, or "input"/"output" as estimate_h1).
core::FrequencyResponse estimate_closed_loop_h1(std::span<const double> r, std::span<const double> u,
                                                std::span<const double> y, double ts,
                                                const WelchOptions& options = {});

/// Closed-loop estimate with a periodic reference: the excited lines are detected on r (as
/// estimate_multisine does on its input, or taken from `options.excited_lines`), then
/// P = Ȳ/Ū on those lines over the periods: averaging removes the noise from both before the
/// ratio, and the noise (co)variances of U and Y, correlated through the loop, enter σ_G as in
/// estimate_multisine.
MultisineEstimate estimate_closed_loop_multisine(std::span<const double> r, std::span<const double> u,
                                                 std::span<const double> y, double ts,
                                                 const MultisineOptions& options);

}  // namespace servotwin::frf
