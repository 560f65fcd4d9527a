// Sample-by-sample comparison with the independent Python implementation in
// tools/reference/interpolation_reference.py (fixture tests/data/motion/interpolation_reference.json):
// closed-form double-S moves on lines, circles and a G18 helix, and velocity-envelope profiles of
// trapezoidal chains (two feeds, tangent line -> arc), each cross-checked there by brute force.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {

nlohmann::json load_fixture() {
  const std::string path = std::string(SERVOTWIN_TEST_DATA_DIR) + "/motion/interpolation_reference.json";
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot open " << path;
  return nlohmann::json::parse(in);
}

Point to_point(const nlohmann::json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

Program to_program(const nlohmann::json& blocks) {
  Program p;
  p.start = to_point(blocks.at(0).at("start"));
  for (const auto& jb : blocks) {
    Block b;
    const std::string type = jb.at("type");
    b.type = type == "linear" ? BlockType::Linear : type == "arc_ccw" ? BlockType::ArcCcw : BlockType::ArcCw;
    b.start = to_point(jb.at("start"));
    b.end = to_point(jb.at("end"));
    b.center = to_point(jb.at("center"));
    const std::string plane = jb.at("plane");
    b.plane = plane == "XY" ? Plane::XY : plane == "ZX" ? Plane::ZX : Plane::YZ;
    b.feed_mm_min = jb.at("feed_mm_min");
    b.line = p.blocks.size() + 1;
    p.blocks.push_back(b);
  }
  return p;
}

TEST(InterpolationReference, MatchesIndependentPythonImplementation) {
  const nlohmann::json fixture = load_fixture();
  ASSERT_EQ(fixture.at("format"), "servotwin.test-fixture/1");
  const auto& cases = fixture.at("cases");
  ASSERT_GE(cases.size(), 10U);
  for (const auto& c : cases) {
    const std::string name = c.at("name");
    SCOPED_TRACE(name);
    const Program program = to_program(c.at("blocks"));
    InterpolationLimits lim;
    lim.ts = c.at("limits").at("ts");
    lim.accel = c.at("limits").at("accel");
    if (c.at("limits").contains("jerk")) lim.jerk = c.at("limits").at("jerk").get<double>();
    const Trajectory tr = interpolate(program, lim, {Axis::X, Axis::Y, Axis::Z});
    const auto& expected = c.at("positions");
    ASSERT_EQ(tr.size(), c.at("samples").get<std::size_t>());
    ASSERT_EQ(expected.size(), tr.size());
    double worst = 0.0;
    for (std::size_t k = 0; k < tr.size(); ++k)
      for (std::size_t a = 0; a < kAxisCount; ++a) worst = std::max(worst, std::abs(tr.positions[a][k] - expected[k][a].get<double>()));
    // Both sides evaluate the same exact profile in double precision (the reference root
    // finding is exact to ~1e-15 s): agreement to 1e-9 mm.
    EXPECT_LT(worst, 1e-9) << name;
    // Exact end point.
    for (std::size_t a = 0; a < kAxisCount; ++a) EXPECT_EQ(tr.positions[a].back(), expected.back()[a].get<double>());
  }
}

}  // namespace
}  // namespace servotwin::motion
