#pragma once
/// \file
/// Robustness and cost of input shapers (catalog C6.3; the measures Klipper reports, peers A1):
/// residual vibration V(ω, ζ), sensitivity curves versus frequency and damping error, the
/// insensitivity bandwidth at a vibration level, and a comparison table for a set of shapers.
/// The smoothing measure lives in smoothing.hpp.

#include <string>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// Residual vibration of a shaper on a mode (omega [rad/s], zeta), the standard normalized
/// definition V(ω, ζ) of catalog C6.3 (Singer–Seering; also Klipper's `_estimate_shaper`):
///
///   V = e^{−ζω t_n} · |Σ A_i e^{ζω t_i} e^{j ω_d t_i}| / Σ A_i,   ω_d = ω √(1−ζ²),
///
/// the peak of the vibration left after the last impulse relative to the vibration of an unshaped
/// unit impulse. It is computed as |Σ A_i e^{−ζω(t_n−t_i)} e^{j ω_d t_i}| / Σ A_i so that nothing
/// overflows for long shapers. V = 0 is exact cancellation, V = 1 no reduction; ω = 0 gives 1.
/// Throws core::InputError naming the argument when omega is negative or not finite, zeta is
/// outside [0, 1), or the shaper is empty / has times and amplitudes of different lengths.
/// Allocation-free.
double residual_vibration(const Shaper& shaper, double omega, double zeta);

/// One point of a sensitivity curve.
struct SensitivityPoint {
  double omega = 0.0;     ///< mode frequency evaluated [rad/s]
  double vibration = 0.0; ///< V(omega, zeta)
};

/// Sensitivity curve S(ω) = V(ω, ζ) of C6.3 on `count` points evenly spaced over
/// [omega_min, omega_max] (count ≥ 2, 0 ≤ omega_min < omega_max). zeta is the mode's damping
/// (usually the design damping; pass another value to see the effect of a damping error).
std::vector<SensitivityPoint> sensitivity_curve(const Shaper& shaper, double omega_min, double omega_max,
                                                int count, double zeta);

/// Residual vibration at the design frequency versus the actual damping of the mode: one value of
/// V(shaper.omega, ζ) per entry of `zetas` (each in [0, 1)).
std::vector<double> damping_sensitivity(const Shaper& shaper, const std::vector<double>& zetas);

/// The frequency band around the design frequency in which V stays at or below a level.
struct InsensitiveBand {
  double omega_low = 0.0;   ///< lower edge [rad/s] (V(omega_low) = level)
  double omega_high = 0.0;  ///< upper edge [rad/s]
  /// (omega_high − omega_low)/shaper.omega: Singer–Seering's normalized insensitivity.
  double normalized_width = 0.0;
};

/// Insensitivity bandwidth at `level` (e.g. 0.05 for 5 %), for a mode with damping `zeta`: the
/// connected interval containing the frequency of least vibration near the design frequency
/// where V(ω, zeta) ≤ level. The edges are found by scanning outward on a fine grid and refined by
/// bisection (relative accuracy 1e-10). Throws core::InputError when level is not in (0, 1) or
/// when V exceeds level everywhere near the design frequency (the band is empty).
InsensitiveBand insensitivity_band(const Shaper& shaper, double level, double zeta);

/// One row of a shaper comparison (all the cost and robustness measures of one shaper).
struct ShaperComparisonRow {
  std::string type;
  double duration_s = 0.0;               ///< delay added to a move [s]
  double residual_at_design = 0.0;       ///< V(shaper.omega, shaper.zeta)
  double band_width_normalized = 0.0;    ///< insensitivity width at `level`, /ω (0 when empty)
  double band_low_ratio = 0.0;           ///< band edges as ω/shaper.omega (0 when empty)
  double band_high_ratio = 0.0;
  double smoothing = 0.0;                ///< Klipper's smoothing measure (smoothing.hpp) at the given accel/scv
  int impulse_count = 0;
};

/// Options of compare_shapers.
struct ComparisonOptions {
  double level = 0.05;        ///< vibration level for the insensitivity band
  double accel = 5000.0;      ///< acceleration for the smoothing measure [length/s²] (Klipper's default 5000 mm/s²)
  double scv = 5.0;           ///< square-corner velocity for the smoothing measure [length/s] (Klipper's 5 mm/s)
};

/// One row per shaper, in the given order, each evaluated at its own design frequency and
/// damping.
std::vector<ShaperComparisonRow> compare_shapers(const std::vector<Shaper>& shapers,
                                                 const ComparisonOptions& options = {});

}  // namespace servotwin::shaping
