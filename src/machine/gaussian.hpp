#pragma once
// Reproducible standard normal deviates (see simulator.hpp for the exact recipe, which
// tools/reference/machine_reference.py reimplements to generate the test fixture).

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace servotwin::machine::detail {

inline std::uint64_t splitmix64(std::uint64_t x) noexcept {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

class GaussianSource {
 public:
  GaussianSource(std::uint64_t seed, std::uint64_t stream)
      : engine_(splitmix64(seed ^ (0x9E3779B97F4A7C15ULL * (stream + 1)))) {}

  double operator()() noexcept {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double theta = 2.0 * std::numbers::pi * u2;
    spare_ = r * std::sin(theta);
    has_spare_ = true;
    return r * std::cos(theta);
  }

 private:
  // In (0, 1): the log above never sees 0.
  double uniform() noexcept { return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53; }

  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace servotwin::machine::detail
