#pragma once
/// \file
/// A measured frequency response: complex points on increasing frequencies with their quality
/// indices, as the real-time identification block or an offline estimator produces them and as the
/// model fit consumes them (design.md "frequency-response CSV"). A plain data type in `core` so that
/// `frf` (producer) and `fit` (consumer) need not know each other.

#include <complex>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace servotwin::core {

/// One measured point of a frequency response P(jω).
struct FrequencyPoint {
  double freq_hz = 0.0;                 ///< excitation frequency [Hz], strictly increasing along a response
  std::complex<double> value;           ///< P(j 2π freq_hz), output over input
  double quality = 0.0;                 ///< coherence (0..1) for broadband estimates, THD (0..) for swept-sine points
  double snr = 0.0;                     ///< signal-to-noise ratio of the point (linear, not dB); 0 when unknown
  double amplitude = 0.0;               ///< excitation amplitude used for the point (input units); 0 when unknown
  double std_dev = 0.0;                 ///< standard deviation of `value` (absolute, complex circular); 0 when unknown
  /// False when the measurement could not bring the point within its quality limits (THD, SNR):
  /// kept for the record, left out of fits (issue 25 §1).
  bool valid = true;
  std::string note = {};                ///< why the point is invalid (empty when valid)
};

/// What `quality` means for a response.
enum class QualityKind { kCoherence, kThd };

/// A measured frequency response.
struct FrequencyResponse {
  std::vector<FrequencyPoint> points;   ///< strictly increasing freq_hz
  QualityKind quality_kind = QualityKind::kCoherence;
  std::optional<double> duration_s;     ///< how long the experiment took [s], when known

  [[nodiscard]] std::size_t size() const noexcept { return points.size(); }
  /// The same response without its invalid points.
  [[nodiscard]] FrequencyResponse valid_only() const {
    FrequencyResponse out{{}, quality_kind, duration_s};
    for (const FrequencyPoint& p : points)
      if (p.valid) out.points.push_back(p);
    return out;
  }
};

}  // namespace servotwin::core
