// Multisine design (excitation_design.hpp): the period and its lines from the range and the
// duration, Schroeder's phases, then the time-frequency swapping iteration that lowers the crest
// factor while keeping the amplitude spectrum.
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <fmt/format.h>
#include <numbers>
#include <vector>

#include "offline_fft.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_design.hpp"

namespace servotwin::frf::detail {

namespace {

constexpr double kPi = std::numbers::pi;

struct Period {
  std::size_t samples = 0;
  std::size_t count = 0;
};

/// Periods and their length: with `periods` given, the longest period that fits that many times;
/// otherwise the shortest period whose line spacing reaches f_begin_hz, repeated as often as the
/// duration allows (averaging over periods is what gives each point its noise estimate). Period
/// lengths have no prime factor above 5.
Period choose_period(const ExcitationRequest& r) {
  const double total = std::floor(r.duration_s / r.ts + 1e-9);
  Period p;
  if (r.periods > 0) {
    if (r.periods < 2)
      throw core::InputError(core::at_field("periods"),
                             "expected at least 2 periods (the estimator averages over periods; add one more to skip "
                             "as transient)");
    p.count = r.periods;
  } else {
    const auto shortest = static_cast<double>(
        detail::smallest_fast_length(static_cast<std::size_t>(std::ceil(1.0 / (r.f_begin_hz * r.ts) - 1e-9))));
    p.count = static_cast<std::size_t>(std::floor(total / shortest));
    if (p.count < 2)
      throw core::InputError(core::at_field("duration_s"),
                             fmt::format("{} s holds fewer than 2 periods of {:.0f} samples (a line spacing of {} Hz "
                                         "at {} s per sample); give at least {} s or a higher range begin",
                                         r.duration_s, shortest, r.f_begin_hz, r.ts, 2.0 * shortest * r.ts));
  }
  p.samples = detail::largest_fast_length(static_cast<std::size_t>(std::floor(total / static_cast<double>(p.count))));
  const double df = p.samples == 0 ? std::numeric_limits<double>::infinity()
                                   : 1.0 / (static_cast<double>(p.samples) * r.ts);
  if (df > r.f_begin_hz * (1.0 + 1e-9))
    throw core::InputError(core::at_field(r.periods > 0 ? "periods" : "duration_s"),
                           fmt::format("{} periods of {} samples space the lines {:.4g} Hz apart, coarser than the "
                                       "range's begin {} Hz; use at most {:.0f} periods or a longer duration",
                                       p.count, p.samples, df, r.f_begin_hz,
                                       std::floor(total * r.ts * r.f_begin_hz + 1e-9)));
  return p;
}

/// The excited DFT lines of a period of n samples: every line in the range, or a quasi-logarithmic
/// subset (round(k_b·10^{j/m}), kept distinct by stepping at least one line).
std::vector<std::size_t> choose_lines(const ExcitationRequest& r, std::size_t n) {
  const double df = 1.0 / (static_cast<double>(n) * r.ts);
  const auto first = static_cast<std::size_t>(std::max(1.0, std::ceil(r.f_begin_hz / df - 1e-9)));
  const auto nyquist_below = (n - 1) / 2;  // the Nyquist line itself carries no phase
  const auto last = std::min(nyquist_below, static_cast<std::size_t>(std::floor(r.f_end_hz / df + 1e-9)));
  if (last < first)
    throw core::InputError(core::at_field("f_begin_hz"),
                           fmt::format("no DFT line lies in {} ... {} Hz: a period of {} samples spaces its lines "
                                       "{} Hz apart; widen the range or use fewer periods",
                                       r.f_begin_hz, r.f_end_hz, n, df));
  std::vector<std::size_t> lines;
  if (r.spacing == LineSpacing::kLinear) {
    for (std::size_t k = first; k <= last; ++k) lines.push_back(k);
    return lines;
  }
  const double ratio = std::pow(10.0, 1.0 / static_cast<double>(r.lines_per_decade));
  double target = static_cast<double>(first);
  std::size_t k = first;
  while (k <= last) {
    lines.push_back(k);
    target *= ratio;
    k = std::max(k + 1, static_cast<std::size_t>(std::llround(target)));
  }
  return lines;
}

/// One period from unit amplitudes and the given phases on `lines`.
void synthesize(const std::vector<std::size_t>& lines, const std::vector<double>& phases, std::size_t n,
                RealDft& dft, std::vector<std::complex<double>>& spectrum, std::vector<double>& period) {
  spectrum.assign(n / 2 + 1, {0.0, 0.0});
  for (std::size_t j = 0; j < lines.size(); ++j) spectrum[lines[j]] = std::polar(1.0, phases[j]);
  dft.inverse(spectrum, n, period);
}

}  // namespace

Excitation design_multisine(const ExcitationRequest& r) {
  const Period p = choose_period(r);
  Excitation e;
  e.period_samples = p.samples;
  e.periods = p.count;
  e.lines = choose_lines(r, p.samples);
  const std::size_t count = e.lines.size();

  // Schroeder (1970) eq. 11 for equal powers: phi_k = -pi k(k-1)/K, k = 1 … K.
  std::vector<double> phases(count);
  for (std::size_t j = 0; j < count; ++j)
    phases[j] = -kPi * static_cast<double>(j) * static_cast<double>(j + 1) / static_cast<double>(count);

  RealDft dft;
  std::vector<std::complex<double>> spectrum;
  std::vector<double> period, best;
  synthesize(e.lines, phases, p.samples, dft, spectrum, period);
  e.schroeder_crest_factor = crest_factor(period);
  best = period;
  double best_crest = e.schroeder_crest_factor;

  // Van der Ouderaa, Schoukens & Renneboog (1988): clip the time signal, keep the phases the
  // clipped signal has on the excited lines, restore the amplitudes. The clip level follows the
  // current peak; the best period seen is kept, so the result never exceeds Schroeder's.
  std::vector<double> clipped;
  for (std::size_t iteration = 0; iteration < r.crest_iterations && count > 1; ++iteration) {
    double peak = 0.0, sum_squares = 0.0;
    for (double v : period) {
      peak = std::max(peak, std::abs(v));
      sum_squares += v * v;
    }
    const double rms = std::sqrt(sum_squares / static_cast<double>(p.samples));
    // Clip a little below the peak, never below 1.2 rms (deeper clipping scrambles the phases).
    const double level = std::max(0.9 * peak, 1.2 * rms);
    clipped.resize(period.size());
    std::transform(period.begin(), period.end(), clipped.begin(),
                   [level](double v) { return std::clamp(v, -level, level); });
    dft.forward(clipped, spectrum);
    for (std::size_t j = 0; j < count; ++j) phases[j] = std::arg(spectrum[e.lines[j]]);
    synthesize(e.lines, phases, p.samples, dft, spectrum, period);
    const double crest = crest_factor(period);
    if (crest < best_crest) {
      best_crest = crest;
      best = period;
    }
  }

  e.samples.reserve(p.samples * p.count);
  for (std::size_t k = 0; k < p.count; ++k) e.samples.insert(e.samples.end(), best.begin(), best.end());
  scale_to_peak(e, r.amplitude);
  return e;
}

}  // namespace servotwin::frf::detail
