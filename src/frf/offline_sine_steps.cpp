// Stepped-sine estimate (excitation_recording.hpp): single-line DFTs over each step's measuring
// window of whole cycles, so the fundamental and its harmonics fall on DFT lines (no leakage) and
// the residual after them measures the noise.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "servotwin/frf/excitation_recording.hpp"

namespace servotwin::frf {

namespace {

// Harmonics 2 … 5 count as distortion (THD), not noise.
constexpr std::size_t kHarmonics = 5;

/// e^{−j2πk/n} for k = 0 … n−1: every harmonic line of a window indexes it through (line·i) mod n,
/// so the DFTs need no trigonometric call per sample (the steps share one window length).
class Twiddles {
 public:
  const std::vector<std::complex<double>>& of(std::size_t n) {
    if (table_.size() != n) {
      table_.resize(n);
      const double step = 2.0 * std::numbers::pi / static_cast<double>(n);
      for (std::size_t k = 0; k < n; ++k)
        table_[k] = {std::cos(step * static_cast<double>(k)), -std::sin(step * static_cast<double>(k))};
    }
    return table_;
  }

 private:
  std::vector<std::complex<double>> table_;
};

/// Σ v[i] e^{−j2π line i / n}, the angle reduced exactly through (line·i) mod n.
std::complex<double> line_dft(std::span<const double> v, std::size_t line,
                              const std::vector<std::complex<double>>& twiddle) {
  const std::size_t n = v.size();
  std::complex<double> sum{0.0, 0.0};
  std::size_t index = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += v[i] * twiddle[index];
    index += line;
    if (index >= n) index -= n;
  }
  return sum;
}

struct WindowLines {
  std::vector<std::complex<double>> harmonics;  // line h·m for h = 1 … (as far as below n/2)
  double residual_variance = 0.0;
};

/// The harmonic lines of a window and the variance of what they and the mean leave.
WindowLines analyse(std::span<const double> v, std::size_t cycles, const std::vector<std::complex<double>>& twiddle) {
  const std::size_t n = v.size();
  WindowLines w;
  for (std::size_t h = 1; h <= kHarmonics && 2 * h * cycles < n; ++h)
    w.harmonics.push_back(line_dft(v, h * cycles, twiddle));
  double mean = 0.0;
  for (double s : v) mean += s;
  mean /= static_cast<double>(n);
  double energy = 0.0;
  for (double s : v) energy += (s - mean) * (s - mean);
  // Parseval: a line k (0 < k < n/2) holds 2|V_k|²/n of the energy.
  for (const auto& line : w.harmonics) energy -= 2.0 * std::norm(line) / static_cast<double>(n);
  const double dof = static_cast<double>(n) - 1.0 - 2.0 * static_cast<double>(w.harmonics.size());
  w.residual_variance = dof > 0.0 ? std::max(0.0, energy) / dof : 0.0;
  return w;
}

}  // namespace

core::FrequencyResponse estimate_sine_steps(std::span<const double> x, std::span<const double> y, double ts,
                                            const std::vector<SineStep>& steps, std::ptrdiff_t offset) {
  core::FrequencyResponse response;
  response.quality_kind = core::QualityKind::kThd;
  response.duration_s = static_cast<double>(x.size()) * ts;
  const auto n_record = static_cast<std::ptrdiff_t>(std::min(x.size(), y.size()));
  Twiddles twiddles;
  for (const SineStep& s : steps) {
    const std::ptrdiff_t first = offset + static_cast<std::ptrdiff_t>(s.begin + s.settle_samples);
    const auto n = static_cast<std::ptrdiff_t>(s.measure_samples);
    if (first < 0 || first + n > n_record) continue;
    const auto at = static_cast<std::size_t>(first);
    const auto& twiddle = twiddles.of(s.measure_samples);
    const WindowLines in = analyse(x.subspan(at, s.measure_samples), s.cycles, twiddle);
    const WindowLines out = analyse(y.subspan(at, s.measure_samples), s.cycles, twiddle);
    if (in.harmonics.empty() || std::abs(in.harmonics.front()) == 0.0) continue;
    const std::complex<double> X = in.harmonics.front(), Y = out.harmonics.front();
    core::FrequencyPoint p;
    p.freq_hz = s.freq_hz;
    p.value = Y / X;
    double distortion = 0.0;
    for (std::size_t h = 1; h < out.harmonics.size(); ++h) distortion += std::norm(out.harmonics[h]);
    p.quality = std::abs(Y) > 0.0 ? std::sqrt(distortion) / std::abs(Y) : 0.0;
    // White noise of variance σ² puts N·σ² on each line; first-order propagation through Y/X.
    const double window = static_cast<double>(s.measure_samples);
    const double relative = window * out.residual_variance / std::max(std::norm(Y), 1e-300) +
                            window * in.residual_variance / std::norm(X);
    p.std_dev = std::abs(p.value) * std::sqrt(relative);
    p.snr = p.std_dev > 0.0 ? std::abs(p.value) / p.std_dev : 0.0;
    p.amplitude = 2.0 * std::abs(X) / window;
    response.points.push_back(p);
  }
  return response;
}

}  // namespace servotwin::frf
