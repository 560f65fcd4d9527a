#include "servotwin/shaping/zv4.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "shaper_checks.hpp"

namespace servotwin::shaping {
namespace {

using std::numbers::pi;

void check_parameters(const Zv4Parameters& p) {
  if (!std::isfinite(p.p1) || p.p1 < -1.0 || p.p1 > 1.0)
    throw core::InputError(core::at_field("p1"), "expected p1 in [-1, 1], got " + detail::show(p.p1));
  if (!std::isfinite(p.p2) || p.p2 < 0.0 || p.p2 >= 1.0)
    throw core::InputError(core::at_field("p2"), "expected p2 in [0, 1), got " + detail::show(p.p2));
  if (!std::isfinite(p.p3) || p.p3 < 0.0 || p.p3 >= 1.0)
    throw core::InputError(core::at_field("p3"), "expected p3 in [0, 1), got " + detail::show(p.p3));
  if (p.p1 != 0.0 && p.p3 != 0.0)
    throw core::InputError(core::at_field("p3"),
                           "p3 = " + detail::show(p.p3) + " has no effect unless p1 = 0 (p1 = " + detail::show(p.p1) + "); leave p3 at 0");
}

// Undamped polygon sides a1..a4 (a1 = 1) of C6.2.
std::array<double, 4> polygon_sides(const Zv4Parameters& p) {
  if (p.p1 == 0.0) {
    const double a2 = p.p2 / (1.0 - p.p2);
    const double a3 = std::max(a2 - 1.0, p.p3 / (1.0 - p.p3));  // max, not the printed min (catalog §5 defect 1)
    return {1.0, a2, a3, 1.0 - a2 + a3};
  }
  const double alpha = std::abs(p.p1) * 2.0 * pi / 3.0;  // the sides are even in α
  const double s1 = std::sin(alpha);
  const double s2 = std::sin(2.0 * alpha);
  const double s3 = std::sin(3.0 * alpha);
  const double a2 = alpha <= pi / 2.0 ? std::max(0.0, 2.0 * std::cos(alpha)) + p.p2 / (1.0 - p.p2)
                                      : std::max(0.0, s3 / s2) * p.p2;
  return {1.0, a2, (a2 * s2 - s3) / s1, (a2 * s1 - s2) / s1};
}

}  // namespace

Shaper zv4_shaper(double omega, double zeta, const Zv4Parameters& parameters) {
  detail::check_design_mode(omega, zeta);
  check_parameters(parameters);
  std::array<double, 4> a = polygon_sides(parameters);
  const double largest = *std::max_element(a.begin(), a.end());
  for (double& side : a) {
    // Only rounding noise of the region-edge formulas can be negative here; the admissible region
    // guarantees a_i >= 0 exactly.
    if (side < 1e-12 * largest) side = 0.0;
  }
  const double omega_d = omega * std::sqrt(1.0 - zeta * zeta);
  const double alpha = parameters.p1 * 2.0 * pi / 3.0;
  const double spacing = (pi - alpha) / omega_d;
  Shaper shaper;
  shaper.type = "zv4";
  shaper.omega = omega;
  shaper.zeta = zeta;
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (a[k] == 0.0) continue;
    const double t = spacing * i;
    shaper.times.push_back(t);
    shaper.amplitudes.push_back(a[k] * std::exp(-zeta * omega * t));
    sum += shaper.amplitudes.back();
  }
  // The first impulse is a1 = 1 > 0, so the train always starts at t = 0.
  for (double& amplitude : shaper.amplitudes) amplitude /= sum;
  return shaper;
}

const std::vector<Zv4Preset>& zv4_presets() {
  static const std::vector<Zv4Preset> presets = {
      {"zv", {0.0, 0.5, 0.0}, "ZV, A = [1/2, 1/2] undamped"},
      {"zvd", {0.0, 2.0 / 3.0, 0.5}, "ZVD, A = [1/4, 1/2, 1/4] undamped"},
      {"zvdd", {0.0, 0.75, 0.75}, "ZVDD, A = [1/8, 3/8, 3/8, 1/8] undamped"},
      {"2hei5", {0.0, 0.6803, 0.6803}, "two-hump EI, 5 % humps (zeta = 0), printed row"},
      {"2hei2", {0.0, 0.713573, 0.713573}, "two-hump EI, 2 % humps (zeta = 0); printed 0.7075 gives 2.49 %"},
      {"2hei1", {0.0, 0.7274, 0.7274}, "two-hump EI, 1 % humps (zeta = 0), printed row"},
  };
  return presets;
}

Zv4Parameters zv4_preset(std::string_view name, std::string_view field) {
  std::string names;
  for (const Zv4Preset& preset : zv4_presets()) {
    if (preset.name == name) return preset.parameters;
    names += (names.empty() ? "" : ", ") + preset.name;
  }
  throw core::InputError(core::at_field(std::string(field)),
                         "unknown ZV4 preset '" + std::string(name) + "'; expected one of " + names);
}

}  // namespace servotwin::shaping
