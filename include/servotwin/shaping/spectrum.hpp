#pragma once
/// \file
/// A measured vibration spectrum (power spectral density of the acceleration versus frequency), as
/// Klipper's resonance test writes it: one PSD per accelerometer axis and their sum. The input of
/// the automatic shaper selection (selection.hpp); read from files by io/klipper_csv.hpp.

#include <string>
#include <vector>

namespace servotwin::shaping {

/// Which PSD of a spectrum to use.
enum class SpectrumAxis { kX, kY, kZ, kSum };

/// A PSD table on a common, strictly increasing frequency grid.
struct Spectrum {
  std::vector<double> freq_hz;  ///< bin frequencies [Hz], strictly increasing, ≥ 0
  std::vector<double> psd_x;    ///< PSD per accelerometer axis (≥ 0, same length as freq_hz)
  std::vector<double> psd_y;
  std::vector<double> psd_z;
  std::vector<double> psd_sum;  ///< psd_x + psd_y + psd_z (Klipper's `psd_xyz`, the one it fits)
  /// True when the PSD is already divided by (f + 0.1) with the low-frequency taper applied
  /// (Klipper's calibration_data files); false for raw PSDs (resonances_* files).
  bool normalized = false;
  std::string source;  ///< file name or label, for messages

  /// The PSD of one axis.
  [[nodiscard]] const std::vector<double>& psd(SpectrumAxis axis) const noexcept {
    switch (axis) {
      case SpectrumAxis::kX: return psd_x;
      case SpectrumAxis::kY: return psd_y;
      case SpectrumAxis::kZ: return psd_z;
      case SpectrumAxis::kSum: break;
    }
    return psd_sum;
  }
};

/// "x", "y", "z", "xyz".
[[nodiscard]] std::string to_string(SpectrumAxis axis);
/// Parses "x", "y", "z", "xyz" (also "all", "sum"); core::InputError naming `field` otherwise.
[[nodiscard]] SpectrumAxis parse_spectrum_axis(const std::string& name, const std::string& field = "axis");

}  // namespace servotwin::shaping
