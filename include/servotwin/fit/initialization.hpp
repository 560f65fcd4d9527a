#pragma once
/// \file
/// Starting values for the plant fit: the three-point interpolation of the two-mass class
/// (catalog C5.8) and peak picking for n modes.

#include <array>
#include <complex>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {

/// Result of the three-point interpolation of
///   P(s) = (b2 s² + b1 s + b0)/(s³ + a2 s² + a1 s + a0)   (velocity-equivalent data).
struct InterpolationResult {
  std::array<double, 3> numerator{};    ///< b2, b1, b0 (highest power first)
  std::array<double, 4> denominator{};  ///< 1, a2, a1, a0
  /// The model K/(s+a)·(s²+2ζzωz s+ωz²)/(s²+2ζnωn s+ωn²) backed out of the coefficients (or K/s·…
  /// when a0 was fixed to 0), or empty when the coefficients have no such reading.
  std::optional<PlantModel> model;
  std::string failure;                  ///< why `model` is empty
};

/// Exact interpolation through three points (C5.8): b(jω) − P(jω)a(jω) = 0 is linear in the six
/// coefficients, so three complex points give a 6×6 linear system (solved by column-pivoted QR
/// after scaling ω by the largest of the three and P by its magnitude there). With
/// `rigid == kIntegrator`, a0 = 0 and the 6 equations are solved for the other 5 in the least
/// squares sense. `values` are velocity-equivalent (multiply position data by jω first).
/// Throws std::invalid_argument for non-positive or repeated frequencies or non-finite values.
InterpolationResult three_point_interpolation(const std::array<double, 3>& omega_rad_s,
                                              const std::array<std::complex<double>, 3>& values,
                                              RigidKind rigid = RigidKind::kRealPole);

/// One extremum of the detrended log-magnitude found by peak picking.
struct Extremum {
  std::size_t index = 0;       ///< measured point at the extremum
  double omega_rad_s = 0.0;    ///< refined by a parabola through the neighbours in log ω
  double zeta = 0.0;           ///< half-power bandwidth estimate, or phase-slope estimate when the band is not resolved
  double prominence = 0.0;     ///< height above (depth below) the higher of its two bases [nepers]
  std::string zeta_method;     ///< "half-power" or "phase-slope"
};

/// Extrema of d(ω) = ln|ω·V(jω)|, V = velocity-equivalent response, i.e. of the magnitude with the
/// −20 dB/dec of a collocated plant removed, so that a resonance is a maximum and an antiresonance
/// a minimum. Extrema whose damping estimate is ≥ 1/√2 are dropped (such a pair has no peak: a
/// broad hump is a rigid pole meeting a lag pole). Sorted by decreasing prominence.
struct PeakPicking {
  std::vector<Extremum> resonances;
  std::vector<Extremum> antiresonances;
};

/// Peak picking on a response. Points are velocity-equivalent when `output` is kVelocity;
/// position data are multiplied by jω first. Responses of fewer than 3 points have no extrema.
PeakPicking pick_peaks(const core::FrequencyResponse& response, OutputKind output);

/// The n resonance/antiresonance pairs for a start: the n most prominent maxima, each paired with
/// the most prominent unused minimum below it (above it when none is below — non-collocated data).
/// Empty when fewer than n maxima or minima exist; `failure` then says which.
struct ModePairing {
  std::vector<std::pair<Extremum, Extremum>> pairs;  ///< (antiresonance, resonance), by resonance frequency
  std::string failure;
};
ModePairing pair_modes(const PeakPicking& peaks, std::size_t modes);
/// The same pairing for a given choice of resonances (any subset of peaks.resonances).
ModePairing pair_modes(const PeakPicking& peaks, std::vector<Extremum> resonances);

/// Alternative choices of n resonances for multi-start fitting: every n-subset of the n + 2 most
/// prominent maxima (most prominent first; a rigid-pole hump or a noise bump can outrank a real,
/// well-damped resonance), at most `limit` subsets.
std::vector<std::vector<Extremum>> resonance_choices(const PeakPicking& peaks, std::size_t modes, std::size_t limit = 10);

/// Automatic choice of the three interpolation points (C5.8): the lowest-frequency point, the
/// measured point at the antiresonance (magnitude minimum) and at the resonance (magnitude
/// maximum) of the most prominent mode. Empty when no mode is found.
std::optional<std::array<std::size_t, 3>> choose_interpolation_points(const core::FrequencyResponse& response,
                                                                      OutputKind output);

}  // namespace servotwin::fit
