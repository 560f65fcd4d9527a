#pragma once
/// \file
/// Klipper's smoothing measure of an input shaper (peers A1, `shaper_calibrate.py`), defined here
/// from what it measures rather than from Klipper's code.
///
/// A shaper is applied as a convolution of the commanded position with its impulses, shifted by
/// its centroid t_s = Σ A_i t_i / Σ A_i so that constant-velocity motion passes unchanged (the
/// shift Klipper applies in its real-time part). Writing τ_i = t_i − t_s, the shaped position at
/// time t is x_s(t) = Σ A_i x(t − τ_i) / Σ A_i. Smoothing is the distance of the shaped toolpath
/// from the programmed path at two worst-case corners, at acceleration `accel` and square-corner
/// velocity `scv`:
///
/// * 180° reversal: x(t) = ½ a t² (the axis reverses at t = 0 under constant acceleration). Then
///   x_s(0) = ½ a Σ A_i τ_i² / Σ A_i — the variance of the impulse train times a/2: the shaped
///   motion turns back short of the programmed turning point by this distance.
/// * 90° corner taken at speed v = scv: X arrives at the corner decelerating at a and stops there
///   (x(t) = v t − ½ a t² for t < 0, 0 after), Y starts at the corner with speed v accelerating
///   at a (y(t) = v t + ½ a t² for t > 0, 0 before). At t = 0 the shaped point sits at
///   (x_s, y_s) with x_s = −Σ_{τ_i ≥ 0} A_i (v + ½ a τ_i) τ_i / ΣA and
///   y_s = Σ_{τ_i < 0} A_i (v − ½ a τ_i)(−τ_i) / ΣA; the offset is |(x_s, y_s)|.
///
/// smoothing = max(offset_90, offset_180), in the length unit of accel and scv (Klipper: mm with
/// accel = 5000 mm/s², scv = 5 mm/s). This is the current Klipper definition (both corner legs,
/// combined by hypot); older Klipper versions took only the X leg times √2.

#include <optional>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// The two corner offsets and their maximum (length unit of accel and scv).
struct SmoothingOffsets {
  double corner_90 = 0.0;
  double reversal_180 = 0.0;
  [[nodiscard]] double smoothing() const noexcept { return corner_90 > reversal_180 ? corner_90 : reversal_180; }
};

/// The corner offsets defined above. Throws core::InputError naming the argument when accel or scv
/// is negative or not finite, or when the shaper is empty or its amplitudes do not have a positive
/// sum.
SmoothingOffsets smoothing_offsets(const Shaper& shaper, double accel = 5000.0, double scv = 5.0);

/// max(offset_90, offset_180): Klipper's "smoothing".
double shaper_smoothing(const Shaper& shaper, double accel = 5000.0, double scv = 5.0);

/// The largest acceleration whose smoothing stays at or below `max_smoothing` (Klipper's
/// "suggested max_accel", which uses 0.12 mm and scv = 5 mm/s). Smoothing grows monotonically with
/// accel, so the answer is found by bracketing and bisection (relative accuracy 1e-9).
double max_accel_for_smoothing(const Shaper& shaper, double max_smoothing = 0.12, double scv = 5.0);

/// max_accel_for_smoothing, or nullopt when no acceleration meets the limit because the corner at
/// scv alone smooths more than max_smoothing (long shapers for slow modes). Still throws
/// core::InputError for a max_smoothing that is not a length > 0.
std::optional<double> reachable_max_accel(const Shaper& shaper, double max_smoothing = 0.12, double scv = 5.0);

}  // namespace servotwin::shaping
