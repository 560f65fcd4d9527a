#include "servotwin/shaping/firmware.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"

namespace servotwin::shaping {

namespace {

constexpr double kPi = std::numbers::pi;
/// Klipper's vibration tolerance of the EI family, 1/SHAPER_VIBRATION_REDUCTION.
constexpr double kKlipperVibrationTolerance = 0.05;

/// c0 + c1 z + c2 z^2 + c3 z^3.
double cubic(const std::array<double, 4>& c, double z) noexcept { return c[0] + z * (c[1] + z * (c[2] + z * c[3])); }

/// Singhose, Seering & Singer (1997): 2-hump and 3-hump EI for V = 5 %, times in undamped
/// periods and amplitudes as cubics in zeta (the fits Klipper evaluates).
constexpr std::array<std::array<double, 4>, 4> kTwoHumpTimes{{{0.0, 0.0, 0.0, 0.0},
                                                             {0.49890, 0.16270, -0.54262, 6.16180},
                                                             {0.99748, 0.18382, -1.58270, 8.17120},
                                                             {1.49920, -0.09297, -0.28338, 1.85710}}};
constexpr std::array<std::array<double, 4>, 4> kTwoHumpAmplitudes{{{0.16054, 0.76699, 2.26560, -1.22750},
                                                                  {0.33911, 0.45081, -2.58080, 1.73650},
                                                                  {0.34089, -0.61533, -0.68765, 0.42261},
                                                                  {0.15997, -0.60246, 1.00280, -0.93145}}};
constexpr std::array<std::array<double, 4>, 5> kThreeHumpTimes{{{0.0, 0.0, 0.0, 0.0},
                                                               {0.49974, 0.23834, 0.44559, 12.4720},
                                                               {0.99849, 0.29808, -2.36460, 23.3990},
                                                               {1.49870, 0.10306, -2.01390, 17.0320},
                                                               {1.99960, -0.28231, 0.61536, 5.40450}}};
constexpr std::array<std::array<double, 4>, 5> kThreeHumpAmplitudes{{{0.11275, 0.76632, 3.29160, -1.44380},
                                                                    {0.23698, 0.61164, -2.57850, 4.85220},
                                                                    {0.30008, -0.19062, -2.14560, 0.13744},
                                                                    {0.23775, -0.73297, 0.46885, -2.08650},
                                                                    {0.11244, -0.45439, 0.96382, -1.46000}}};

template <std::size_t N>
void fitted(const std::array<std::array<double, 4>, N>& times, const std::array<std::array<double, 4>, N>& amplitudes,
            double period, double zeta, Shaper& s) {
  for (std::size_t i = 0; i < N; ++i) {
    s.times.push_back(cubic(times[i], zeta) * period);
    s.amplitudes.push_back(cubic(amplitudes[i], zeta));
  }
}

}  // namespace

const std::vector<std::string>& klipper_shaper_types() {
  static const std::vector<std::string> types{"zv", "mzv", "zvd", "ei", "2hump_ei", "3hump_ei"};
  return types;
}

bool klipper_has(std::string_view type) noexcept {
  const auto& t = klipper_shaper_types();
  return std::find(t.begin(), t.end(), type) != t.end();
}

double klipper_max_damping(std::string_view type) {
  if (!klipper_has(type))
    throw core::InputError(core::at_field("type"), "Klipper has no shaper '" + std::string(type) + "'");
  if (type == "ei") return 0.4;
  if (type == "2hump_ei") return 0.3;
  if (type == "3hump_ei") return 0.2;
  return 0.99;
}

Shaper klipper_shaper(std::string_view type, double omega, double zeta) {
  if (!klipper_has(type))
    throw core::InputError(core::at_field("type"), "Klipper has no shaper '" + std::string(type) +
                                                       "' (its types: zv, mzv, zvd, ei, 2hump_ei, 3hump_ei)");
  if (!(std::isfinite(omega) && omega > 0.0)) throw core::InputError(core::at_field("omega"), "must be finite and > 0");
  if (!(zeta >= 0.0 && zeta < 1.0)) throw core::InputError(core::at_field("zeta"), "must lie in [0, 1)");
  Shaper s;
  s.type = std::string(type);
  s.omega = omega;
  s.zeta = zeta;
  const double f = omega / (2.0 * kPi);
  const double df = std::sqrt(1.0 - zeta * zeta);
  const double k = std::exp(-zeta * kPi / df);
  const double td = 1.0 / (f * df);
  if (type == "zv") {
    s.amplitudes = {1.0, k};
    s.times = {0.0, 0.5 * td};
  } else if (type == "zvd") {
    s.amplitudes = {1.0, 2.0 * k, k * k};
    s.times = {0.0, 0.5 * td, td};
  } else if (type == "mzv") {
    const double km = std::exp(-0.75 * zeta * kPi / df);
    const double a1 = 1.0 - 1.0 / std::sqrt(2.0);
    s.amplitudes = {a1, (std::sqrt(2.0) - 1.0) * km, a1 * km * km};
    s.times = {0.0, 0.375 * td, 0.75 * td};
  } else if (type == "ei") {
    const double v = kKlipperVibrationTolerance, z = zeta;
    const double a1 = (0.24968 + 0.24961 * v) + ((0.80008 + 1.23328 * v) + (0.49599 + 3.17316 * v) * z) * z;
    const double a3 = (0.25149 + 0.21474 * v) + ((-0.83249 + 1.41498 * v) + (0.85181 - 4.90094 * v) * z) * z;
    const double t2 = 0.4999 + (((0.46159 + 8.57843 * v) * v) +
                                (((4.26169 - 108.644 * v) * v) + ((1.75601 + 336.989 * v) * v) * z) * z) * z;
    s.amplitudes = {a1, 1.0 - a1 - a3, a3};
    s.times = {0.0, t2 * td, td};
  } else if (type == "2hump_ei") {
    fitted(kTwoHumpTimes, kTwoHumpAmplitudes, 1.0 / f, zeta, s);
  } else {
    fitted(kThreeHumpTimes, kThreeHumpAmplitudes, 1.0 / f, zeta, s);
  }
  double sum = 0.0;
  for (const double a : s.amplitudes) sum += a;
  for (double& a : s.amplitudes) a /= sum;
  return s;
}

}  // namespace servotwin::shaping
