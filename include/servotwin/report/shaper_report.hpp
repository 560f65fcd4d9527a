#pragma once
/// \file
/// The comparison of a set of input shapers for one axis (`servotwin shaper compare`, issue 6
/// sections 2 and 5): the cost and robustness measures of every shaper side by side
/// (shaping::compare_shapers, plus Klipper's suggested maximum acceleration), and the charts that
/// show them: residual vibration versus mode frequency and versus mode damping, the impulse
/// trains, and the shaped step command whose staircase makes the delay visible.
///
/// Shapers designed for different frequencies and dampings may be compared: each is evaluated at
/// its own design frequency and damping, and the frequency curves share one absolute Hz axis.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/report/document.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/shaper.hpp"

namespace servotwin::report {

/// A shaper with the name it is shown under (the CLI uses the file name).
struct NamedShaper {
  std::string name;
  shaping::Shaper shaper;
};

/// Options of shaper_comparison and shaper_report.
struct ShaperReportOptions {
  /// Vibration level of the insensitivity band and the accel / scv of the smoothing measure
  /// (Klipper's defaults: 5 %, 5000 mm/s², 5 mm/s).
  shaping::ComparisonOptions comparison;
  /// Smoothing limit of the suggested maximum acceleration (Klipper's 0.12 mm; evaluated at
  /// comparison.scv).
  double max_smoothing = 0.12;
  /// Frequency axis of the sensitivity chart [Hz]; by default 0 to 2.5 x the highest design
  /// frequency.
  std::optional<double> freq_min_hz;
  std::optional<double> freq_max_hz;
  /// Points of each sensitivity curve on the even grid (the design frequencies and band edges are
  /// added to it so that notches and crossings are drawn exactly); 2 to 100000.
  std::size_t curve_points = 1001;
  std::string title = "servotwin shaper compare";
};

/// One shaper's line of the comparison.
struct ShaperComparison {
  std::string name;
  shaping::ShaperComparisonRow row;  ///< exactly shaping::compare_shapers' row
  double freq_hz = 0.0;              ///< design frequency
  double zeta = 0.0;                 ///< design damping
  /// Largest acceleration whose smoothing stays at or below options.max_smoothing
  /// (shaping::max_accel_for_smoothing); +infinity for a single impulse (it never smooths), NaN
  /// when no acceleration meets the limit (the shaper smooths more than that at scv alone).
  double max_accel = 0.0;
};

/// The comparison table, one entry per shaper in the given order. core::InputError when `shapers`
/// is empty (field "shapers"), a shaper has no impulses or a design frequency that is not finite
/// and > 0 (field "shapers[i]" with its name), or an option is out of range (named).
std::vector<ShaperComparison> shaper_comparison(const std::vector<NamedShaper>& shapers,
                                                const ShaperReportOptions& options = {});

/// The report:
///  - "Comparison": the table of shaper_comparison (design frequency and damping, impulses,
///    duration, residual vibration at the design point, insensitivity band at the level, smoothing,
///    suggested maximum acceleration);
///  - "Sensitivity to frequency": V(f) [%] of every shaper (at its design damping) over the
///    frequency range, with the level as a line;
///  - "Sensitivity to damping": V [%] at each shaper's design frequency versus the damping of the
///    mode, from 0 to max(0.25, 2 x the highest design damping) (at most 0.9);
///  - "Impulses": each impulse train, every impulse drawn as a narrow spike from 0 to A_i at t_i;
///  - "Step response": the shaped unit step Σ_{t_i <= t} A_i (a staircase ending at the shaper's
///    duration) of every shaper with the unshaped step.
/// Errors as shaper_comparison, plus (fields "freq_min_hz", "freq_max_hz", "curve_points") for an
/// empty or negative frequency range or a point count out of range.
Document shaper_report(const std::vector<NamedShaper>& shapers, const ShaperReportOptions& options = {});

}  // namespace servotwin::report
