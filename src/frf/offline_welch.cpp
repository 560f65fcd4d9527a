// H1 estimator with Welch averaging: segments, window, detrend, averaged auto/cross spectra,
// coherence and Bendat & Piersol confidence.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "offline_fft.hpp"
#include "offline_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/frf/offline.hpp"

namespace servotwin::frf {

namespace {

std::vector<double> make_window(Window window, std::size_t length) {
  std::vector<double> w(length, 1.0);
  if (window == Window::kHann) {
    const double step = 2.0 * std::numbers::pi / static_cast<double>(length);
    for (std::size_t n = 0; n < length; ++n) w[n] = 0.5 - 0.5 * std::cos(step * static_cast<double>(n));
  }
  return w;
}

std::size_t step_of(std::size_t length, double overlap) {
  const auto overlap_samples = static_cast<std::size_t>(std::floor(overlap * static_cast<double>(length)));
  return std::max<std::size_t>(1, length - std::min(overlap_samples, length - 1));
}

std::size_t segment_count(std::size_t n, std::size_t length, std::size_t step) {
  return n < length ? 0 : (n - length) / step + 1;
}

/// The default segment: the largest power of two with at least 8 segments, at least 16 samples.
std::size_t default_segment_length(std::size_t n, double overlap) {
  std::size_t length = 16;
  while (2 * length <= n && segment_count(n, 2 * length, step_of(2 * length, overlap)) >= 8) length *= 2;
  return std::min(length, n);
}

/// Welch (1967) Eq. 11: variance of the averaged periodogram of white noise relative to one
/// segment's, 1/K·[1 + 2·Σ_j (1 − j/K)·ρ²(j)], ρ(j) = Σ w[n]·w[n + j·S] / Σ w²; its inverse is the
/// number of independent averages the overlapped segments are worth.
double effective_averages(const std::vector<double>& w, std::size_t step, std::size_t segments) {
  const double k = static_cast<double>(segments);
  double w2 = 0.0;
  for (double v : w) w2 += v * v;
  double sum = 1.0;
  for (std::size_t j = 1; j < segments && j * step < w.size(); ++j) {
    double rho = 0.0;
    for (std::size_t n = 0; n + j * step < w.size(); ++n) rho += w[n] * w[n + j * step];
    rho /= w2;
    sum += 2.0 * (1.0 - static_cast<double>(j) / k) * rho * rho;
  }
  return k / sum;
}

/// The options against a record of `samples` samples (the signals themselves checked by the caller).
void validate_options(std::size_t samples, const WelchOptions& o) {
  if (!(o.overlap >= 0.0 && o.overlap < 1.0))
    throw core::InputError(core::at_field("overlap"), "overlap must be a fraction in [0, 1), got " + std::to_string(o.overlap));
  if (o.segment_length != 0 && (o.segment_length < 16 || o.segment_length > samples))
    throw core::InputError(core::at_field("segment"),
                           "segment length must be between 16 samples and the record length (" +
                               std::to_string(samples) + "), got " + std::to_string(o.segment_length));
  if (!(o.min_freq_hz >= 0.0) || !(o.max_freq_hz > o.min_freq_hz))
    throw core::InputError(core::at_field("fmin/fmax"), "expected 0 <= fmin < fmax");
}

void validate(std::span<const double> x, std::span<const double> y, double ts, const WelchOptions& o) {
  detail::check_signals(x, y, ts);
  validate_options(x.size(), o);
}

}  // namespace

namespace {

/// The layout of a validated record, with the window it uses.
WelchLayout layout_of(std::size_t samples, double ts, const WelchOptions& options, const std::vector<double>& window) {
  WelchLayout l;
  l.segment_length = window.size();
  const std::size_t step = step_of(l.segment_length, options.overlap);
  l.segments = segment_count(samples, l.segment_length, step);
  l.df_hz = 1.0 / (static_cast<double>(l.segment_length) * ts);
  l.effective_averages = effective_averages(window, step, l.segments);
  return l;
}

std::size_t segment_length_of(std::size_t samples, const WelchOptions& options) {
  return options.segment_length != 0 ? options.segment_length : default_segment_length(samples, options.overlap);
}

}  // namespace

WelchLayout welch_layout(std::size_t samples, double ts, const WelchOptions& options) {
  if (!(std::isfinite(ts) && ts > 0.0)) throw core::InputError(core::at_field("ts"), "sample period must be > 0");
  if (samples < 16)
    throw core::InputError(core::at_field("input"),
                           "at least 16 samples are needed for a frequency response, got " + std::to_string(samples));
  validate_options(samples, options);
  return layout_of(samples, ts, options, make_window(options.window, segment_length_of(samples, options)));
}

WelchSpectra welch_spectra(std::span<const double> x, std::span<const double> y, double ts, const WelchOptions& options) {
  validate(x, y, ts, options);
  const std::size_t length = segment_length_of(x.size(), options);
  const std::size_t step = step_of(length, options.overlap);
  const std::vector<double> window = make_window(options.window, length);
  const WelchLayout layout = layout_of(x.size(), ts, options, window);
  const std::size_t segments = layout.segments;

  WelchSpectra s;
  s.segment_length = length;
  s.segments = segments;
  s.df_hz = layout.df_hz;
  for (double v : window) {
    s.window_sum += v;
    s.window_square_sum += v * v;
  }
  s.effective_averages = layout.effective_averages;
  const std::size_t lines = length / 2 + 1;
  s.sxx.assign(lines, 0.0);
  s.syy.assign(lines, 0.0);
  s.sxy.assign(lines, {0.0, 0.0});

  detail::RealDft dft;
  std::vector<double> bx(length), by(length);
  std::vector<std::complex<double>> fx, fy;
  for (std::size_t seg = 0; seg < segments; ++seg) {
    const std::size_t start = seg * step;
    std::copy_n(x.begin() + static_cast<std::ptrdiff_t>(start), length, bx.begin());
    std::copy_n(y.begin() + static_cast<std::ptrdiff_t>(start), length, by.begin());
    detail::detrend(bx, options.detrend);
    detail::detrend(by, options.detrend);
    for (std::size_t n = 0; n < length; ++n) {
      bx[n] *= window[n];
      by[n] *= window[n];
    }
    dft.forward(bx, fx);
    dft.forward(by, fy);
    for (std::size_t k = 0; k < lines; ++k) {
      s.sxx[k] += std::norm(fx[k]);
      s.syy[k] += std::norm(fy[k]);
      s.sxy[k] += std::conj(fx[k]) * fy[k];
    }
  }
  // scipy "density" scaling: 1/(fs·Σw²), averaged, one-sided (interior lines doubled).
  const double scale = ts / (s.window_square_sum * static_cast<double>(segments));
  for (std::size_t k = 0; k < lines; ++k) {
    const bool doubled = k != 0 && !(length % 2 == 0 && k == length / 2);
    const double f = scale * (doubled ? 2.0 : 1.0);
    s.sxx[k] *= f;
    s.syy[k] *= f;
    s.sxy[k] *= f;
  }
  return s;
}

double coherence(const WelchSpectra& spectra, std::size_t k) {
  const double denominator = spectra.sxx.at(k) * spectra.syy.at(k);
  if (!(denominator > 0.0)) return 0.0;
  return std::min(1.0, std::norm(spectra.sxy[k]) / denominator);
}

core::FrequencyResponse estimate_h1(std::span<const double> x, std::span<const double> y, double ts,
                                    const WelchOptions& options) {
  return h1_from_spectra(welch_spectra(x, y, ts, options), ts, x.size(), options);
}

core::FrequencyResponse h1_from_spectra(const WelchSpectra& s, double ts, std::size_t samples,
                                        const WelchOptions& options) {
  const std::size_t length = s.segment_length;
  // Density -> spectrum scaling: a sine of amplitude A on a line then shows A²/2 (one-sided).
  const double to_spectrum = s.window_square_sum / (ts * s.window_sum * s.window_sum);
  core::FrequencyResponse response;
  response.quality_kind = core::QualityKind::kCoherence;
  response.duration_s = static_cast<double>(samples) * ts;
  for (std::size_t k = 1; k < s.sxx.size(); ++k) {
    const double f = static_cast<double>(k) * s.df_hz;
    if (f < options.min_freq_hz || f > options.max_freq_hz) continue;
    if (!(s.sxx[k] > 0.0)) continue;
    core::FrequencyPoint p;
    p.freq_hz = f;
    p.value = s.sxy[k] / s.sxx[k];
    p.quality = coherence(s, k);
    p.std_dev = std::sqrt(std::max(0.0, (1.0 - p.quality) * s.syy[k] / (s.effective_averages * s.sxx[k])));
    p.snr = p.std_dev > 0.0 ? std::abs(p.value) / p.std_dev : 0.0;
    const bool nyquist = length % 2 == 0 && k == length / 2;
    p.amplitude = std::sqrt((nyquist ? 1.0 : 2.0) * s.sxx[k] * to_spectrum);
    response.points.push_back(p);
  }
  if (response.points.empty())
    throw core::InputError(core::at_field("fmin/fmax"), "no frequency line with input power in the requested range");
  return response;
}

double magnitude_std(const core::FrequencyPoint& point) { return point.std_dev / std::numbers::sqrt2; }

double phase_std_rad(const core::FrequencyPoint& point) {
  const double magnitude = std::abs(point.value);
  if (magnitude == 0.0) return std::numeric_limits<double>::infinity();
  return point.std_dev / (std::numbers::sqrt2 * magnitude);
}

}  // namespace servotwin::frf
