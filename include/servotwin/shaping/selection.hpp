#pragma once
/// \file
/// Automatic input-shaper selection (issue 6 §4): from a measured vibration spectrum (Klipper's
/// resonance CSVs, io/klipper_csv.hpp) or from fitted modes of known frequency and damping.
///
/// ## The measure: remaining vibrations (as Klipper's calibrate_shaper defines it)
/// Klipper (klippy/extras/shaper_calibrate.py, studied, not copied; GPL) scores a shaper on a PSD:
/// 1. the raw PSD is normalized: divided by (f + 0.1) and, below 2·f_min = 10 Hz, multiplied by
///    exp(1 − (10/(f + 0.1))²) (files that are already normalized are used as they are);
/// 2. only bins f ≤ 200 Hz of the summed PSD `psd_xyz` are used;
/// 3. threshold θ = max(psd)/20 (a shaper cannot reduce vibrations more than 20×, so power below
///    1/20 of the peak is ignored);
/// 4. for a test damping ζ_t: R(ζ_t) = Σ_k max(psd_k·V(2πf_k, ζ_t) − θ, 0) / Σ_k max(psd_k − θ, 0),
///    V the shaper's residual vibration (sensitivity.hpp) at each bin's frequency;
/// 5. remaining vibrations = max over ζ_t ∈ {0.075, 0.1, 0.15} of R(ζ_t) (the plant damping is
///    unknown: pessimize over plausible values).
/// remaining_vibrations() implements exactly this for ANY shaper (single-mode, convolved,
/// ZV4...), so Klipper's pick and ours are scored by one measure. Klipper designs its shapers for
/// an assumed damping 0.1; so does select_shaper_from_spectrum by default (design_zeta).
///
/// ## How the choice is made — where it agrees with Klipper and where it differs
/// Agrees: same measure, same normalization, same frequency grid (multiples of 0.2 Hz up to
/// 200 Hz), same smoothing measure (smoothing.hpp, accel 5000, scv 5) and max_accel (0.12 target),
/// same families (plus ZVD, which Klipper can fit but does not auto-tune).
/// Differs, deliberately:
/// * Objective. Klipper ranks by an empirical score smoothing·(v^1.5 + 0.2·v + 0.01) and a chain
///   of relative thresholds (its own comment: "the formula itself does not have any special
///   meaning"), which changed in 2025 (commit c339bb0) and flips recommendations on noisy data.
///   Here the choice is a constrained minimization: least remaining vibration subject to
///   smoothing ≤ max_smoothing (or, without it, the suggested max_accel ≥ min_max_accel = 1500
///   mm/s², which is how Klipper chose its per-family minimum frequencies) and duration ≤
///   max_delay; among all (family, frequency) points whose vibration is within
///   `vibration_tolerance` (absolute) of the least achievable one, the one with least smoothing
///   wins — vibration differences below the tolerance are not resolvable on a 1.25 Hz-bin PSD.
/// * Multiple resonances: separated peaks of the normalized PSD are detected and two-mode shapers
///   (convolution of two single-mode shapers, one per peak) compete with the single-mode ones.
/// * EI family: our EI, 2-hump and 3-hump EI are the exact solutions of their defining conditions
///   (families.hpp), not Klipper's curve fits: for the same (type, freq) the impulses differ
///   slightly, so their remaining vibrations differ by a few tenths of a percent.
/// * The frequency scan uses a tabulated V(f/f_s) per family (the shape of a single-mode shaper
///   at fixed design damping is scale-invariant: times ∝ 1/f_s), interpolated linearly on a
///   grid of step 1/4096 in f/f_s (error < 1e-5); the points that matter are re-scored exactly.
///
/// ## Known damping (fitted models)
/// select_shaper_from_model designs every family with the FITTED damping of each mode (not
/// Klipper's assumed 0.1) and one factor per mode (convolution for several modes). It scores each
/// by the worst residual vibration over the modes, over a relative frequency uncertainty band and
/// a damping uncertainty, and reports what the same family designed for ζ = 0.1 would leave.
///
/// No file I/O here (design.md); frequencies in Hz on the interface of this file because spectra
/// and Klipper's results are in Hz (shapers themselves keep rad/s).

#include <optional>
#include <string>
#include <vector>

#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/shaper.hpp"
#include "servotwin/shaping/spectrum.hpp"

namespace servotwin::shaping {

/// Parameters of Klipper's remaining-vibration measure (defaults = Klipper's).
struct VibrationMeasure {
  std::vector<double> test_dampings = {0.075, 0.1, 0.15};
  double threshold_fraction = 1.0 / 20.0;  ///< θ = threshold_fraction · max(psd)
};

/// The PSD the measure works on: normalized, bins up to max_freq_hz.
struct PreparedSpectrum {
  std::vector<double> freq_hz;
  std::vector<double> psd;
};

/// Klipper's frequency normalization of a raw PSD: psd/(f + 0.1), tapered by
/// exp(1 − (2·f_min/(f + 0.1))²) below 2·f_min (f_min = 5 Hz). Sizes must agree.
std::vector<double> normalize_psd(const std::vector<double>& freq_hz, const std::vector<double>& psd,
                                  double min_freq_hz = 5.0);

/// Selects an axis, normalizes it unless spectrum.normalized, keeps bins f ≤ max_freq_hz.
/// core::InputError when the spectrum is inconsistent (sizes, non-increasing frequency, negative
/// or non-finite power), has fewer than 3 bins below max_freq_hz or no power at all.
PreparedSpectrum prepare_spectrum(const Spectrum& spectrum, SpectrumAxis axis = SpectrumAxis::kSum,
                                  double max_freq_hz = 200.0);

/// Remaining vibrations of `shaper` on the spectrum (0 … 1; see the file comment).
double remaining_vibrations(const Shaper& shaper, const PreparedSpectrum& spectrum,
                            const VibrationMeasure& measure = {});

/// A significant resonance peak of a (prepared) spectrum.
struct SpectrumPeak {
  double freq_hz = 0.0;
  double psd = 0.0;
};

/// Local maxima of the PSD with at least `min_fraction` of the largest value, separated from any
/// larger peak by a valley below half of their own height; largest first, at most `max_peaks`.
/// Maxima below `min_freq_hz` (default: the 10 Hz low-frequency taper of the normalization, where
/// the normalized PSD is shaped by the taper rather than by the machine) are ignored.
std::vector<SpectrumPeak> find_spectrum_peaks(const PreparedSpectrum& spectrum, double min_fraction = 0.2,
                                              int max_peaks = 3, double min_freq_hz = 10.0);

/// One evaluated shaper.
struct ShaperCandidate {
  std::string name;               ///< family name, or "mzv+zv" for a two-mode shaper
  std::vector<double> freq_hz;    ///< design frequency of each factor (one entry for single-mode)
  Shaper shaper;
  double vibrations = 0.0;        ///< remaining vibrations (spectrum) / worst residual (model)
  double smoothing = 0.0;         ///< smoothing at the options' accel and scv
  double max_accel = 0.0;         ///< suggested max_accel (smoothing 0.12 at scv); 0 when none meets it
  double duration_s = 0.0;
  /// Model path only: worst residual of the same family designed for ζ = 0.1 instead of the
  /// fitted damping (what a tool that cannot measure damping would leave). NaN otherwise.
  double vibrations_assumed_damping = 0.0;
};

/// Options of select_shaper_from_spectrum.
struct SpectrumSelectionOptions {
  std::vector<ShaperType> families = {ShaperType::kZv, ShaperType::kMzv, ShaperType::kZvd,
                                      ShaperType::kEi, ShaperType::kTwoHumpEi, ShaperType::kThreeHumpEi};
  SpectrumAxis axis = SpectrumAxis::kSum;
  double design_zeta = 0.1;              ///< damping the shapers are designed for (unknown plant: Klipper's 0.1)
  VibrationMeasure measure;
  double max_psd_freq_hz = 200.0;        ///< PSD bins used
  double min_shaper_freq_hz = 5.0;       ///< scan range of the shaper frequency
  double max_shaper_freq_hz = 200.0;
  double freq_step_hz = 0.2;
  std::optional<double> max_smoothing;   ///< limit on smoothing (accel, scv below)
  std::optional<double> max_delay_s;     ///< limit on the shaper duration
  double min_max_accel = 1500.0;         ///< without max_smoothing: suggested max_accel must reach this
  double accel = 5000.0;                 ///< smoothing measure's acceleration
  double scv = 5.0;                      ///< smoothing measure's square-corner velocity
  double max_accel_smoothing = 0.12;     ///< smoothing target of the suggested max_accel
  double vibration_tolerance = 0.005;    ///< absolute: vibrations closer than this count as equal
  bool multi_mode = true;                ///< consider two-mode (convolved) shapers when peaks are separated
  std::vector<ShaperType> multi_mode_families = {ShaperType::kZv, ShaperType::kMzv, ShaperType::kZvd,
                                                 ShaperType::kEi};
};

/// The result of a selection.
struct ShaperSelection {
  ShaperCandidate recommended;
  /// Best candidate of each family (the family's own choice by the same rule), then the best
  /// two-mode shaper when one was considered; the recommended one included, ordered by
  /// vibrations then smoothing.
  std::vector<ShaperCandidate> alternatives;
  std::vector<SpectrumPeak> peaks;      ///< spectrum path: detected resonance peaks
  std::vector<std::string> reasons;     ///< human-readable: why the winner wins
};

/// Chooses family and frequency from a spectrum (see the file comment). core::InputError when
/// the options are invalid or no shaper satisfies the limits (the message gives the least
/// smoothing / delay reachable).
ShaperSelection select_shaper_from_spectrum(const Spectrum& spectrum, const SpectrumSelectionOptions& options = {});

/// A mode of known frequency and damping (from a fitted plant model).
struct KnownMode {
  double freq_hz = 0.0;
  double zeta = 0.0;
};

/// Options of select_shaper_from_model.
struct ModelSelectionOptions {
  std::vector<ShaperType> families = {ShaperType::kZv, ShaperType::kMzv, ShaperType::kZvd, ShaperType::kZvdd,
                                      ShaperType::kEi, ShaperType::kTwoHumpEi, ShaperType::kThreeHumpEi};
  double freq_uncertainty = 0.05;   ///< relative ± band of each mode's frequency the shaper must cover
  double zeta_uncertainty = 0.02;   ///< absolute ± of each mode's damping (clipped to [0, 0.99])
  int band_points = 21;             ///< frequency points over the band (odd: includes the mode)
  std::optional<double> max_smoothing;
  std::optional<double> max_delay_s;
  double accel = 5000.0;
  double scv = 5.0;
  double max_accel_smoothing = 0.12;
  double vibration_tolerance = 0.005;
  double assumed_zeta = 0.1;        ///< damping a tool without a model would assume (for the comparison)
};

/// Chooses the family for modes of known damping: every candidate cancels every mode (one factor
/// per mode, convolved); the least worst-case residual under the limits wins (ties within the
/// tolerance → least smoothing). core::InputError for no modes, a mode with freq ≤ 0 or zeta
/// outside [0, 1), or when no shaper satisfies the limits.
ShaperSelection select_shaper_from_model(const std::vector<KnownMode>& modes, const ModelSelectionOptions& options = {});

}  // namespace servotwin::shaping
