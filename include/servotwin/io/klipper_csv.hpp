#pragma once
/// \file
/// Klipper's resonance CSV files (peers A1):
///
/// * `resonances_<axis>_<date>.csv` (TEST_RESONANCES): header `freq,psd_x,psd_y,psd_z,psd_xyz`,
///   one row per frequency bin, PSD of the measured acceleration (not normalized).
/// * `calibration_data_<axis>_<date>.csv` (SHAPER_CALIBRATE): the same five columns followed by
///   one column per fitted shaper, named like `zv(21.0)` (the shaper's vibration ratio per bin);
///   since Klipper commit 2aff840 (2025-10) a `shapers:` marker column (empty on data rows)
///   separates them. The PSD in these files is already normalized (divided by f + 0.1, tapered
///   below 10 Hz), which Spectrum::normalized records. Klipper's own script recognizes only the
///   newer marker; this reader recognizes both (any shaper column means "normalized").
///
/// Checks: the five PSD columns present (in any order, case-insensitive), every value a finite
/// number, frequencies ≥ 0 and strictly increasing, PSD values ≥ 0, at least kMinSpectrumRows
/// rows. Every error is a core::InputError naming file:line:column and the offending value.

#include <iosfwd>
#include <string>

#include "servotwin/shaping/spectrum.hpp"

namespace servotwin::io {

/// Fewest frequency bins a spectrum must have to be worth fitting a shaper to.
inline constexpr std::size_t kMinSpectrumRows = 8;

/// Reads a Klipper PSD CSV from a stream; `source` names it in errors and in Spectrum::source.
shaping::Spectrum read_klipper_csv(std::istream& in, const std::string& source);

/// Opens and reads a Klipper PSD CSV file.
shaping::Spectrum load_klipper_csv(const std::string& path);

}  // namespace servotwin::io
