// Shaped toolpaths and their contour distortion. References: a closed form for a circle at
// constant speed (the shaped circle has radius R |IS(jΩ)|), a 90-degree corner computed by
// tools/reference/shaping_discrete_reference.py (numpy convolution + distance to the two
// half-lines), and straight lines (which a shaper must not leave).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/shaped_path.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::shaping {
namespace {

const nlohmann::json& corner_reference() {
  static const nlohmann::json doc = test::load_fixture("discrete_reference.json");
  return doc.at("corner").at(0);
}

TEST(ShapedPath, CircleShrinksToTheClosedFormRadius) {
  using std::numbers::pi;
  const double R = 10.0, big_omega = 2 * pi * 2.0, ts = 0.001;  // 10 mm at 2 rev/s
  const DiscreteShaper s = discretize(zv4_shaper(2 * pi * 10.0, 0.05, {-0.3, 0.3, 0.0}), ts);
  const std::size_t n = 3000;
  Columns path(2, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const double phi = big_omega * static_cast<double>(k) * ts;
    path[0][k] = R * std::cos(phi);
    path[1][k] = R * std::sin(phi);
  }
  const Columns shaped = shape_columns(path, s);
  ASSERT_EQ(shaped[0].size(), n + s.max_delay());
  const PathDeviation dev = path_deviation(path, shaped, s.max_delay());

  // Steady state: p_shaped(t) = R e^{jΩt} IS(jΩ), a circle of radius R |IS(jΩ)|.
  std::complex<double> is{0.0, 0.0};
  for (std::size_t i = 0; i < s.delays.size(); ++i)
    is += s.amplitudes[i] * std::polar(1.0, -big_omega * static_cast<double>(s.delays[i]) * ts);
  const double r = R * std::abs(is);
  ASSERT_GT(R - r, 0.1);  // a visible distortion
  // The polyline of samples lies between the circle and its chords (sag R (1 - cos(Ω ts / 2))).
  const double sag = R * (1 - std::cos(big_omega * ts / 2));
  for (std::size_t k = 2 * s.max_delay(); k < n - s.max_delay(); ++k) {
    EXPECT_NEAR(std::hypot(shaped[0][k], shaped[1][k]), r, 1e-9) << k;
    EXPECT_LE(dev.distance[k], R - r + 1e-12) << k;
    EXPECT_GE(dev.distance[k], R - r - sag - 1e-12) << k;
  }
  EXPECT_GE(dev.max, R - r - sag);
}

TEST(ShapedPath, CornerRoundingMatchesTheReference) {
  const auto& c = corner_reference();
  DiscreteShaper s;
  s.ts = c.at("ts").get<double>();
  s.delays = c.at("delays").get<std::vector<std::size_t>>();
  s.amplitudes = c.at("discrete_amplitudes").get<std::vector<double>>();
  // The library's own discretization of the same ZV4 agrees with the script's.
  const DiscreteShaper mine = discretize(zv4_shaper(c.at("omega").get<double>(), c.at("zeta").get<double>(),
                                                    {c.at("p1").get<double>(), c.at("p2").get<double>(), 0.0}),
                                         s.ts);
  ASSERT_EQ(mine.delays, s.delays);
  for (std::size_t i = 0; i < s.amplitudes.size(); ++i) EXPECT_NEAR(mine.amplitudes[i], s.amplitudes[i], 1e-12);

  const double v = c.at("v").get<double>();
  const auto before = c.at("n_before").get<std::size_t>(), after = c.at("n_after").get<std::size_t>();
  Columns path(2, std::vector<double>(before + after + 1, 0.0));
  for (std::size_t k = 0; k < path[0].size(); ++k) {
    const double tau = (static_cast<double>(k) - static_cast<double>(before)) * s.ts;
    path[0][k] = tau < 0 ? v * tau : 0.0;
    path[1][k] = tau > 0 ? v * tau : 0.0;
  }
  const Columns shaped = shape_columns(path, s);
  const PathDeviation dev = path_deviation(path, shaped, s.max_delay());
  EXPECT_EQ(dev.distance.size(), c.at("samples").get<std::size_t>());
  EXPECT_NEAR(dev.max, c.at("max_deviation").get<double>(), 1e-9);
  EXPECT_EQ(dev.max_index, c.at("max_index").get<std::size_t>());
  EXPECT_NEAR(dev.rms, c.at("rms_deviation").get<double>(), 1e-9);
  EXPECT_NEAR(dev.max_point[0], c.at("max_point")[0].get<double>(), 1e-9);
  EXPECT_NEAR(dev.max_point[1], c.at("max_point")[1].get<double>(), 1e-9);
  // The nearest commanded segment at the worst point touches the corner's neighbourhood.
  EXPECT_LE(dev.max_segment, before + 1);
  EXPECT_GE(dev.max_segment + s.max_delay(), before);
}

TEST(ShapedPath, StraightMovesStayOnTheirLine) {
  // A 3-axis move along (1, 2, -2) with a trapezoid-like speed change and a stop: the shaped
  // points are averages of points of the same line, so the distortion is rounding only, and the
  // shaped path ends exactly at the end point.
  const DiscreteShaper s = discretize(zv4_shaper(2 * std::numbers::pi * 15.0, 0.03, {0.2, 0.4, 0.0}), 0.0005);
  const std::size_t n = 2000;
  Columns path(3, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const double x = static_cast<double>(k) / static_cast<double>(n - 1);
    const double u = x < 0.5 ? 2 * x * x : 1 - 2 * (1 - x) * (1 - x);
    path[0][k] = 5.0 + 1.0 * 30.0 * u;
    path[1][k] = -3.0 + 2.0 * 30.0 * u;
    path[2][k] = 1.0 - 2.0 * 30.0 * u;
  }
  const Columns shaped = shape_columns(path, s);
  const PathDeviation dev = path_deviation(path, shaped, s.max_delay());
  EXPECT_LT(dev.max, 1e-12);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(shaped[i].front(), path[i].front(), 1e-14);
    EXPECT_NEAR(shaped[i].back(), path[i].back(), 1e-12);
  }
}

TEST(ShapedPath, EqualCornersGiveEqualDeviations) {
  // A square run at constant speed (0.05 mm per sample): its three inner corners are the same
  // corner rotated, so their rounding must be equal, and the largest deviation is one of them.
  const DiscreteShaper s = discretize(zv4_shaper(2 * std::numbers::pi * 20.0, 0.02, {0.0, 0.5, 0.0}), 0.001);
  Columns path(2);
  auto add = [&](double x, double y) {
    path[0].push_back(x);
    path[1].push_back(y);
  };
  for (int k = 0; k <= 400; ++k) add(0.05 * k, 0.0);   // along x
  for (int k = 1; k <= 400; ++k) add(20.0, 0.05 * k);  // up
  for (int k = 1; k <= 400; ++k) add(20.0 - 0.05 * k, 20.0);
  for (int k = 1; k <= 400; ++k) add(0.0, 20.0 - 0.05 * k);  // back to the start
  const Columns shaped = shape_columns(path, s);
  const PathDeviation dev = path_deviation(path, shaped, s.max_delay());
  // Three rounded corners of equal speed give equal deviations (the start is a standstill).
  const double corner_1 = *std::max_element(dev.distance.begin() + 350, dev.distance.begin() + 500);
  const double corner_2 = *std::max_element(dev.distance.begin() + 750, dev.distance.begin() + 900);
  EXPECT_GT(corner_1, 0.01);
  EXPECT_NEAR(corner_1, corner_2, 1e-9);
  EXPECT_NEAR(dev.max, corner_1, 1e-9);
}

TEST(ShapedPath, RejectsInconsistentColumns) {
  const DiscreteShaper s = discretize(zv4_shaper(1.0, 0.0, {0.0, 0.5, 0.0}), 0.1);
  EXPECT_THROW((void)shape_columns(Columns{}, s), core::InputError);
  EXPECT_THROW((void)shape_columns(Columns{{1.0, 2.0}, {1.0}}, s), core::InputError);
  EXPECT_THROW((void)shape_columns(Columns{{1.0, NAN}}, s), core::InputError);
  EXPECT_THROW((void)path_deviation(Columns{{1.0, 2.0}}, Columns{{1.0}, {2.0}}, 1), core::InputError);
  EXPECT_THROW((void)path_deviation(Columns{{}}, Columns{{1.0}}, 1), core::InputError);
}

}  // namespace
}  // namespace servotwin::shaping
