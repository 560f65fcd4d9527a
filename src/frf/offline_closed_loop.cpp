// Closed-loop frequency-response estimates (offline.hpp): the indirect method with the reference
// as instrument, from Welch cross spectra or from period averages.
#include <algorithm>
#include <cmath>
#include <complex>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/offline.hpp"

namespace servotwin::frf {

core::FrequencyResponse estimate_closed_loop_h1(std::span<const double> r, std::span<const double> u,
                                                std::span<const double> y, double ts, const WelchOptions& options) {
  if (r.size() != u.size() || r.size() != y.size())
    throw core::InputError(core::at_field("reference"), "reference, input and output must have the same number of samples");
  const WelchSpectra ru = welch_spectra(r, u, ts, options);
  const WelchSpectra ry = welch_spectra(r, y, ts, options);
  const WelchSpectra uy = welch_spectra(u, y, ts, options);
  // The reference's own H1 response supplies the frequencies, amplitudes and range selection.
  const core::FrequencyResponse reference = h1_from_spectra(ru, ts, r.size(), options);
  core::FrequencyResponse response;
  response.quality_kind = core::QualityKind::kCoherence;
  response.duration_s = static_cast<double>(r.size()) * ts;
  const double n = ru.effective_averages;
  for (const core::FrequencyPoint& line : reference.points) {
    const auto k = static_cast<std::size_t>(std::llround(line.freq_hz / ru.df_hz));
    const std::complex<double> s_ru = ru.sxy[k], s_ry = ry.sxy[k];
    if (std::abs(s_ru) == 0.0) continue;
    core::FrequencyPoint p;
    p.freq_hz = line.freq_hz;
    p.value = s_ry / s_ru;
    p.quality = std::min(coherence(ru, k), coherence(ry, k));
    // S_zz of z = y − P u: S_yy + |P|² S_uu − 2 Re(conj(P)·S_uy) with S_uy = E[conj(U)·Y].
    const double s_zz = std::max(0.0, uy.syy[k] + std::norm(p.value) * uy.sxx[k] -
                                          2.0 * std::real(std::conj(p.value) * uy.sxy[k]));
    p.std_dev = std::sqrt(s_zz * ru.sxx[k] / (n * std::norm(s_ru)));
    p.snr = p.std_dev > 0.0 ? std::abs(p.value) / p.std_dev : 0.0;
    p.amplitude = line.amplitude;
    response.points.push_back(p);
  }
  if (response.points.empty())
    throw core::InputError(core::at_field("reference"), "no line where the reference reaches the plant input");
  return response;
}

MultisineEstimate estimate_closed_loop_multisine(std::span<const double> r, std::span<const double> u,
                                                 std::span<const double> y, double ts,
                                                 const MultisineOptions& options) {
  if (r.size() != u.size() || r.size() != y.size())
    throw core::InputError(core::at_field("reference"), "reference, input and output must have the same number of samples");
  MultisineOptions o = options;
  if (o.excited_lines.empty()) {
    // The lines are the reference's: u carries them too, but also the noise fed back.
    try {
      o.excited_lines = estimate_multisine(r, r, ts, options).lines;
    } catch (const core::InputError& e) {
      if (e.where().field != "input") throw;
      throw core::InputError(core::at_field("reference"), e.reason());
    }
  }
  return estimate_multisine(u, y, ts, o);
}

}  // namespace servotwin::frf
