// Alignment of a played excitation with its recording, and period detection (excitation_recording.hpp),
// both from FFT-based correlations.
#include <algorithm>
#include <cmath>
#include <complex>
#include <fmt/format.h>
#include <numeric>
#include <vector>

#include "offline_fft.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_recording.hpp"

namespace servotwin::frf {

namespace {

// A drive's record of what it applied matches the table to within noise and quantization; 0.9
// still admits noise of half the signal's rms, while a response through the plant (a speed, a
// position) stays well below it (0.73 for the resonance of the tests).
constexpr double kLeastCorrelation = 0.9;

/// Linear (not circular) correlation sums c(d) = Σ_n a[n + d] b[n] for d = −(nb − 1) … na − 1,
/// returned at index d + nb − 1, through zero-padded FFTs.
std::vector<double> correlate(std::span<const double> a, std::span<const double> b) {
  const std::size_t length = detail::smallest_fast_length(a.size() + b.size());
  detail::RealDft dft;
  std::vector<double> pa(length, 0.0), pb(length, 0.0);
  std::copy(a.begin(), a.end(), pa.begin());
  std::copy(b.begin(), b.end(), pb.begin());
  std::vector<std::complex<double>> fa, fb;
  dft.forward(pa, fa);
  dft.forward(pb, fb);
  for (std::size_t k = 0; k < fa.size(); ++k) fa[k] *= std::conj(fb[k]);
  std::vector<double> circular;
  dft.inverse(fa, length, circular);
  std::vector<double> c(a.size() + b.size() - 1);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const auto d = static_cast<std::ptrdiff_t>(i) - static_cast<std::ptrdiff_t>(b.size() - 1);
    c[i] = circular[static_cast<std::size_t>(d >= 0 ? d : static_cast<std::ptrdiff_t>(length) + d)];
  }
  return c;
}

}  // namespace

Alignment align_excitation(std::span<const double> recorded, std::span<const double> excitation) {
  if (recorded.empty() || excitation.empty())
    throw core::InputError(core::at_field("input"), "an empty recording or excitation cannot be aligned");
  const std::vector<double> c = correlate(recorded, excitation);
  const auto nr = static_cast<std::ptrdiff_t>(recorded.size());
  const auto ne = static_cast<std::ptrdiff_t>(excitation.size());
  const std::ptrdiff_t least_overlap = std::max<std::ptrdiff_t>(1, std::min(nr, ne) / 2);
  const auto admissible = [&](std::size_t i) {
    const std::ptrdiff_t d = static_cast<std::ptrdiff_t>(i) - (ne - 1);
    return std::min(nr, d + ne) - std::max<std::ptrdiff_t>(0, d) >= least_overlap;
  };
  double best_value = 0.0;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (admissible(i)) best_value = std::max(best_value, std::abs(c[i]));
  Alignment best;
  std::size_t best_index = 0;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (admissible(i) && std::abs(c[i]) == best_value) best_index = i;
  best.offset = static_cast<std::ptrdiff_t>(best_index) - (ne - 1);
  // A periodic sequence matches equally well a whole number of periods apart when the recording
  // holds only part of it; take the latest such shift, which reads the first recorded period as
  // the sequence's first (skipped as transient: the safe reading). When the best shift holds the
  // whole sequence there is no such tie (a shift by one period of P loses 1/P of the match, which
  // the noise tolerance below could not tell from a tie once P reaches 1000).
  const bool whole = best.offset >= 0 && best.offset + ne <= nr;
  if (!whole)
    for (std::size_t i = c.size(); i-- > 0;)
      if (admissible(i) && std::abs(c[i]) >= (1.0 - 1e-3) * best_value) {
        best.offset = static_cast<std::ptrdiff_t>(i) - (ne - 1);
        break;
      }
  // Gain and correlation coefficient over the overlap, summed directly (exact, and cheap).
  const std::ptrdiff_t first = std::max<std::ptrdiff_t>(0, best.offset);
  const std::ptrdiff_t last = std::min(nr, best.offset + ne);
  double re = 0.0, ee = 0.0, rr = 0.0;
  for (std::ptrdiff_t n = first; n < last; ++n) {
    const double r = recorded[static_cast<std::size_t>(n)];
    const double e = excitation[static_cast<std::size_t>(n - best.offset)];
    re += r * e;
    ee += e * e;
    rr += r * r;
  }
  best.overlap = static_cast<std::size_t>(last - first);
  best.gain = ee > 0.0 ? re / ee : 0.0;
  best.correlation = ee > 0.0 && rr > 0.0 ? std::abs(re) / std::sqrt(ee * rr) : 0.0;
  if (best.correlation < kLeastCorrelation)
    throw core::InputError(core::at_field("input"),
                           fmt::format("does not hold the excitation: the best match (at sample {}) correlates only "
                                       "{:.3f} with it; is it the column the drive played?",
                                       best.offset, best.correlation));
  return best;
}

PeriodDetection detect_period(std::span<const double> x, std::size_t min_period) {
  PeriodDetection result;
  const std::size_t n = x.size();
  min_period = std::max<std::size_t>(min_period, 2);
  if (n < 2 * min_period + 2) return result;
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(n);
  std::vector<double> centred(n);
  std::transform(x.begin(), x.end(), centred.begin(), [mean](double v) { return v - mean; });
  const std::vector<double> c = correlate(centred, centred);  // lag L at index L + n - 1
  // Energies of the two overlapping parts, from prefix sums of the squares.
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + centred[i] * centred[i];
  const std::size_t max_lag = n / 2;
  std::vector<double> rho(max_lag + 2, 0.0);
  double largest = -1.0;
  // From one below the shortest lag: a peak needs both neighbours (a slowly varying signal falls
  // smoothly from lag 0 and must not read as a period at min_period).
  for (std::size_t lag = min_period - 1; lag <= max_lag + 1 && lag < n; ++lag) {
    const double head = prefix[n - lag], tail = prefix[n] - prefix[lag];
    rho[lag] = head > 0.0 && tail > 0.0 ? c[lag + n - 1] / std::sqrt(head * tail) : 0.0;
    if (lag >= min_period && lag <= max_lag) largest = std::max(largest, rho[lag]);
  }
  if (largest < 0.8) return result;
  for (std::size_t lag = min_period; lag <= max_lag; ++lag) {
    const bool peak = rho[lag] >= rho[lag - 1] && rho[lag] >= rho[lag + 1];
    if (peak && rho[lag] >= largest - 0.02) {
      result.period_samples = lag;
      result.correlation = rho[lag];
      return result;
    }
  }
  return result;
}

}  // namespace servotwin::frf
