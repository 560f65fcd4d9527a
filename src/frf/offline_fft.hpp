#pragma once
// Private: real-input DFT of the offline estimators, on Eigen's FFT module (kissfft backend,
// mixed radix 2/3/4/5 plus a generic butterfly, so any length works; lengths with a large prime
// factor are slower, O(N·p)).

#include <algorithm>
#include <complex>
#include <cstddef>
#include <unsupported/Eigen/FFT>
#include <vector>

namespace servotwin::frf::detail {

/// The largest length <= n with no prime factor above 5 (the FFT's fast radices; the swapping
/// iteration runs hundreds of FFTs of the period, and a large prime factor would make each
/// O(N·p)). At most 6.7 % shorter than n for n >= 50.
inline std::size_t largest_fast_length(std::size_t n) {
  std::size_t best = 0;
  for (std::size_t p5 = 1; p5 <= n; p5 *= 5)
    for (std::size_t p35 = p5; p35 <= n; p35 *= 3) {
      std::size_t candidate = p35;
      while (candidate * 2 <= n) candidate *= 2;
      best = std::max(best, candidate);
    }
  return best;
}

/// The smallest length >= n with no prime factor above 5.
inline std::size_t smallest_fast_length(std::size_t n) {
  std::size_t best = 1;
  while (best < n) best *= 2;
  for (std::size_t p5 = 1; p5 < best; p5 *= 5)
    for (std::size_t p35 = p5; p35 < best; p35 *= 3) {
      std::size_t candidate = p35;
      while (candidate < n) candidate *= 2;
      best = std::min(best, candidate);
    }
  return best;
}

/// Computes X(k) = Σ x[n] e^{−j2πkn/N}, k = 0 … N/2, reusing its plan and buffers across calls
/// of the same length.
class RealDft {
 public:
  RealDft() { fft_.SetFlag(Eigen::FFT<double>::HalfSpectrum); }

  /// `in` holds N samples; `out` receives N/2 + 1 lines (resized only when N changes).
  void forward(const std::vector<double>& in, std::vector<std::complex<double>>& out) {
    out.resize(in.size() / 2 + 1);
    fft_.fwd(out.data(), in.data(), static_cast<Eigen::Index>(in.size()));
  }

  /// The inverse: `in` holds lines 0 … n/2 of a real sequence of n samples; `out` receives
  /// x[m] = (1/n) Σ_k X(k) e^{+j2πkm/n} over the full (Hermitian) spectrum.
  void inverse(const std::vector<std::complex<double>>& in, std::size_t n, std::vector<double>& out) {
    out.resize(n);
    fft_.inv(out.data(), in.data(), static_cast<Eigen::Index>(n));
  }

 private:
  Eigen::FFT<double> fft_;
};

}  // namespace servotwin::frf::detail
