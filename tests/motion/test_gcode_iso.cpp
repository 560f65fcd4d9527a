// ISO G-code reader. Expected values are the thesis's printed program (Table 3.2) and closed-form
// arc geometry worked out in the comments.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gcode_test_support.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace gcode_iso_test {

using test::iso;
using test::iso_error;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr std::uint8_t kX = axis_bit(Axis::X);
constexpr std::uint8_t kY = axis_bit(Axis::Y);
constexpr std::uint8_t kZ = axis_bit(Axis::Z);

// First and last lines of thesis Table 3.2, spelled as printed (blank between letter and value).
TEST(GcodeIso, ReadsThesisTable32) {
  const Program p = iso(
      "N0000 G00 X0.000 F12000\n"
      "N0010 G01 X 0.258\n"
      "N0020 G01 X-0.790\n"
      "N0030 G01 X-2.992\n"
      "N0040 G01 X-8.099\n"
      "N1830 G01 X9.849\n"
      "N2000 G01 X-2.641\n"
      "N2010 G01 X 0.000\n");
  ASSERT_EQ(p.blocks.size(), 8U);
  EXPECT_EQ(p.dialect, Dialect::Iso);
  EXPECT_EQ(p.name, "t.nc");
  const Block& first = p.blocks[0];
  EXPECT_EQ(first.type, BlockType::Rapid);
  EXPECT_EQ(first.number, 0);
  EXPECT_EQ(first.feed_mm_min, 12000.0);
  EXPECT_EQ(first.axes, kX);
  const double x[] = {0.0, 0.258, -0.790, -2.992, -8.099, 9.849, -2.641, 0.0};
  const long n[] = {0, 10, 20, 30, 40, 1830, 2000, 2010};
  for (std::size_t i = 1; i < p.blocks.size(); ++i) {
    const Block& b = p.blocks[i];
    EXPECT_EQ(b.type, BlockType::Linear) << i;
    EXPECT_EQ(b.number, n[i]);
    EXPECT_EQ(b.line, i + 1);
    EXPECT_EQ(b.end[0], x[i]) << i;
    EXPECT_EQ(b.start[0], x[i - 1]) << i;
    EXPECT_EQ(b.feed_mm_min, 12000.0) << "F is modal, set on the G00 line";
    EXPECT_EQ(b.end[1], 0.0);
  }
  EXPECT_EQ(p.used_axes(), kX);
}

// A full circle ends where it starts, yet both axes of its plane move (G18: Z and X).
TEST(GcodeIso, FullCircleUsesBothAxesOfItsPlane) {
  EXPECT_EQ(iso("G17 G02 I5 J0 F100\n").used_axes(), kX | kY);
  EXPECT_EQ(iso("G18 G03 I5 K0 F100\n").used_axes(), kZ | kX);
}

TEST(GcodeIso, CaseInsensitiveCommentsTapeMarksAndBlankLines) {
  const Program p = iso(
      "%\n"
      "\n"
      "(program start)\n"
      "n10 g1 x1 y2 f300 (first) ; second part\r\n"
      "   \t\n"
      "N20 x3 M3 m8\n"
      "%\n");
  ASSERT_EQ(p.blocks.size(), 3U);
  EXPECT_EQ(p.blocks[0].type, BlockType::None);
  EXPECT_EQ(p.blocks[0].comment, "program start");
  const Block& b = p.blocks[1];
  EXPECT_EQ(b.type, BlockType::Linear);
  EXPECT_EQ(b.number, 10);
  EXPECT_EQ(b.end, (Point{1.0, 2.0, 0.0}));
  EXPECT_EQ(b.axes, kX | kY);
  EXPECT_EQ(b.comment, "first second part");
  EXPECT_EQ(p.blocks[2].type, BlockType::Linear) << "G01 is modal";
  EXPECT_EQ(p.blocks[2].end, (Point{3.0, 2.0, 0.0}));
  EXPECT_THAT(p.blocks[2].m_codes, ElementsAre(3, 8));
  EXPECT_EQ(p.blocks[2].line, 6U);
}

TEST(GcodeIso, SeveralModalGroupsOnOneLineAndNumberForms) {
  const Program p = iso("G17 G21 G90 G94 G40 G1 X+3. Y-.5 Z 0.25 F 100\n");
  ASSERT_EQ(p.blocks.size(), 1U);
  EXPECT_EQ(p.blocks[0].end, (Point{3.0, -0.5, 0.25}));
  EXPECT_EQ(p.blocks[0].feed_mm_min, 100.0);
}

TEST(GcodeIso, IncrementalAndAbsolute) {
  const Program p = iso("G91 G01 X1 Y1 F100\nX1\nG90 X0\n");
  EXPECT_EQ(p.blocks[0].end, (Point{1.0, 1.0, 0.0}));
  EXPECT_EQ(p.blocks[1].end, (Point{2.0, 1.0, 0.0}));
  EXPECT_EQ(p.blocks[2].end, (Point{0.0, 1.0, 0.0}));
}

TEST(GcodeIso, StartPositionFromOptions) {
  ParseOptions o;
  o.start = {5.0, 6.0, 7.0};
  const Program p = parse_iso("G91 G00 X1\n", "s.nc", o);
  EXPECT_EQ(p.start, o.start);
  EXPECT_EQ(p.blocks[0].start, o.start);
  EXPECT_EQ(p.blocks[0].end, (Point{6.0, 6.0, 7.0}));
}

TEST(GcodeIso, InchConvertsLengthsAndFeeds) {
  // 1 in = 25.4 mm; F10 in/min = 254 mm/min. G20 applies to its own line.
  const Program p = iso("G20 G01 X1 Y2 F10\nG02 X3 Y0 R2\nG21 G01 X1\n");
  EXPECT_EQ(p.blocks[0].end[0], 25.4);
  EXPECT_EQ(p.blocks[0].end[1], 50.8);
  EXPECT_DOUBLE_EQ(p.blocks[0].feed_mm_min, 254.0);
  // Arc from (1, 2) in to (3, 0) in with R 2 in: chord sqrt(8), centre (1, 0) in or (3, 2) in.
  // G02 with R > 0 is the short clockwise arc: centre (1, 0) in = (25.4, 0) mm.
  EXPECT_NEAR(p.blocks[1].center[0], 25.4, 1e-12);
  EXPECT_NEAR(p.blocks[1].center[1], 0.0, 1e-12);
  EXPECT_EQ(p.blocks[2].end[0], 1.0) << "G21 back to mm";
}

// Swept angle of an arc in its plane, in (0, 2 pi], from the block geometry.
double swept_angle(const Block& b) {
  const std::size_t u = b.plane == Plane::XY ? 0 : b.plane == Plane::ZX ? 2 : 1;
  const std::size_t v = b.plane == Plane::XY ? 1 : b.plane == Plane::ZX ? 0 : 2;
  const double a0 = std::atan2(b.start[v] - b.center[v], b.start[u] - b.center[u]);
  const double a1 = std::atan2(b.end[v] - b.center[v], b.end[u] - b.center[u]);
  double d = b.type == BlockType::ArcCcw ? a1 - a0 : a0 - a1;
  while (d <= 0.0) d += 2.0 * std::numbers::pi;
  while (d > 2.0 * std::numbers::pi) d -= 2.0 * std::numbers::pi;
  return d;
}

TEST(GcodeIso, ArcByCentreOffsets) {
  // From (10, 0) counterclockwise to (0, 10) about (0, 0): a quarter circle.
  const Program p = iso("G00 X10 Y0\nG03 X0 Y10 I-10 J0 F500\n");
  const Block& b = p.blocks[1];
  EXPECT_EQ(b.type, BlockType::ArcCcw);
  EXPECT_EQ(b.plane, Plane::XY);
  EXPECT_EQ(b.center[0], 0.0);
  EXPECT_EQ(b.center[1], 0.0);
  EXPECT_NEAR(swept_angle(b), std::numbers::pi / 2, 1e-12);
}

TEST(GcodeIso, ArcByRadiusPicksShortOrLongArc) {
  // Chord from (0, 0) to (8, 0), |R| = 5: half chord 4, centre offset sqrt(25 - 16) = 3, so the
  // centre is (4, -3) or (4, 3). Seen along the chord (+x), the short clockwise arc has its centre
  // on the right (y < 0), the short counterclockwise arc on the left; R < 0 swaps them.
  struct Case {
    const char* g;
    double r;
    double cy;
    bool long_arc;
  };
  const Case cases[] = {{"G02", 5, -3, false}, {"G02", -5, 3, true}, {"G03", 5, 3, false}, {"G03", -5, -3, true}};
  for (const Case& c : cases) {
    const Program p = iso(std::string("G01 X0 Y0 F100\n") + c.g + " X8 Y0 R" + std::to_string(c.r) + "\n");
    const Block& b = p.blocks[1];
    EXPECT_NEAR(b.center[0], 4.0, 1e-12) << c.g << " R" << c.r;
    EXPECT_NEAR(b.center[1], c.cy, 1e-12) << c.g << " R" << c.r;
    // Swept angle 2 asin(4/5) = 106.26 deg for the short arc, 360 deg minus that for the long one.
    const double short_angle = 2.0 * std::asin(0.8);
    EXPECT_NEAR(swept_angle(b), c.long_arc ? 2.0 * std::numbers::pi - short_angle : short_angle, 1e-12);
  }
}

TEST(GcodeIso, RadiusEqualToHalfChordIsAHalfCircle) {
  const Program p = iso("G01 X0 Y0 F100\nG02 X10 Y0 R5\nG02 X0 Y0 R5.001\n");
  EXPECT_NEAR(p.blocks[1].center[0], 5.0, 1e-12);
  EXPECT_NEAR(p.blocks[1].center[1], 0.0, 1e-12);
  EXPECT_NEAR(swept_angle(p.blocks[1]), std::numbers::pi, 1e-12);
  // R 5.001 (> half chord 5) is a proper arc just short of a half circle.
  EXPECT_LT(swept_angle(p.blocks[2]), std::numbers::pi);
}

TEST(GcodeIso, RadiusSlightlyBelowHalfChordWithinToleranceIsAHalfCircle) {
  // Half chord 5, R 4.999: short by 0.001 < tolerance 0.002 mm.
  const Program p = iso("G01 X0 Y0 F100\nG02 X10 Y0 R4.999\n");
  EXPECT_NEAR(p.blocks[1].center[0], 5.0, 1e-12);
  EXPECT_NEAR(p.blocks[1].center[1], 0.0, 1e-12);
  EXPECT_THAT(iso_error("G01 X0 Y0 F100\nG02 X10 Y0 R4.99\n"),
              HasSubstr("t.nc:2:12: arc radius 4.99 mm is smaller than half the distance to the end point (5 mm)"));
}

TEST(GcodeIso, FullCircleAndHelix) {
  const Program p = iso("G00 X10 Y0 Z0\nG02 X10 Y0 I-5 F200\nG03 X0 Y10 Z5 I-10 J0\n");
  const Block& full = p.blocks[1];
  EXPECT_EQ(full.type, BlockType::ArcCw);
  EXPECT_EQ(full.start, full.end);
  EXPECT_EQ(full.center[0], 5.0);
  EXPECT_EQ(full.center[1], 0.0);
  EXPECT_NEAR(swept_angle(full), 2.0 * std::numbers::pi, 1e-12);
  const Block& helix = p.blocks[2];
  EXPECT_EQ(helix.end, (Point{0.0, 10.0, 5.0}));
  EXPECT_EQ(helix.center[2], 0.0) << "the normal coordinate of the centre holds the start's";
  EXPECT_EQ(helix.axes, kX | kY | kZ);
}

TEST(GcodeIso, ArcsInOtherPlanes) {
  // G18 (Z-X plane): from (0, 0, 0) clockwise seen from +Y to (x 5, z -5) about (x 5, z 0).
  const Program p = iso("G01 X0 Y0 Z0 F100\nG18 G02 X5 Z-5 I5 K0\nG19 G03 Y5 Z0 J0 K5\n");
  const Block& zx = p.blocks[1];
  EXPECT_EQ(zx.plane, Plane::ZX);
  EXPECT_EQ(zx.center[0], 5.0);
  EXPECT_EQ(zx.center[2], 0.0);
  // In ZX, (u, v) = (z, x): start angle atan2(x - 5, z) = atan2(-5, 0) = -90 deg, end atan2(0, -5) =
  // 180 deg; clockwise from -90 to 180 sweeps 90 deg.
  EXPECT_NEAR(swept_angle(zx), std::numbers::pi / 2, 1e-12);
  const Block& yz = p.blocks[2];
  EXPECT_EQ(yz.plane, Plane::YZ);
  EXPECT_EQ(yz.center[1], 0.0);
  EXPECT_EQ(yz.center[2], 0.0);
  EXPECT_EQ(p.blocks[2].end, (Point{5.0, 5.0, 0.0}));
}

TEST(GcodeIso, AbsoluteArcCentreMode) {
  const Program p = iso("G01 X10 Y0 F100\nG90.1 G03 X0 Y10 I0 J0\nG91.1 G03 X-10 Y0 I-10 J0\n");
  EXPECT_EQ(p.blocks[1].center[0], 0.0);
  EXPECT_EQ(p.blocks[1].center[1], 0.0);
  EXPECT_EQ(p.blocks[2].center[0], -10.0);
  EXPECT_EQ(p.blocks[2].center[1], 10.0);
  EXPECT_THAT(iso_error("G01 X10 Y0 F100\nG90.1 G03 X0 Y10 I0\n"), HasSubstr("needs both I and J"));
}

TEST(GcodeIso, Dwell) {
  const Program p = iso("G04 P1.5\nG4 X2\nG04 P0\n");
  ASSERT_EQ(p.blocks.size(), 3U);
  EXPECT_EQ(p.blocks[0].type, BlockType::Dwell);
  EXPECT_EQ(p.blocks[0].dwell_s, 1.5);
  EXPECT_EQ(p.blocks[1].dwell_s, 2.0);
  EXPECT_EQ(p.blocks[1].end, (Point{0.0, 0.0, 0.0})) << "X is the time, not a move";
  EXPECT_EQ(p.blocks[2].dwell_s, 0.0);
  EXPECT_THAT(iso_error("G04\n"), HasSubstr("t.nc:1:1: G04 needs the dwell time P or X in seconds"));
  EXPECT_THAT(iso_error("G04 P-1\n"), HasSubstr("t.nc:1:5: dwell time must be >= 0 s"));
  EXPECT_THAT(iso_error("G04 P1 X1\n"), HasSubstr("not both"));
  EXPECT_THAT(iso_error("G04 P1 Y1\n"), HasSubstr("t.nc:1:8: 'Y1' is not allowed with G04"));
  EXPECT_THAT(iso_error("G01 G04 P1 X1 F100\n"), HasSubstr("t.nc:1:1: G04 and G01 on one line"));
}

TEST(GcodeIso, ModalWordsAloneMakeNoMotion) {
  const Program p = iso("N5 G01 F100\nG00\nG02\nX1 R5\n");
  ASSERT_EQ(p.blocks.size(), 4U);
  EXPECT_EQ(p.blocks[0].type, BlockType::None);
  EXPECT_EQ(p.blocks[0].number, 5);
  EXPECT_EQ(p.blocks[0].feed_mm_min, 0.0);
  EXPECT_EQ(p.blocks[1].type, BlockType::None);
  EXPECT_EQ(p.blocks[3].type, BlockType::ArcCw) << "modal G02 with an end point only";
}

TEST(GcodeIso, ErrorsNameFileLineColumnAndWord) {
  // The issue's example: line 12, column 9.
  std::string text;
  for (int i = 0; i < 11; ++i) text += "G01 X1 F100\n";
  text += "N12 G01 Q5 X1\n";
  EXPECT_EQ(iso_error(text), "t.nc:12:9: unknown word 'Q5'");
  EXPECT_EQ(iso_error("G01 X1 F100\nG01 X1..2\n"),
            "t.nc:2:5: malformed number in 'X1..2' (expected a plain decimal such as 12, -0.5 or +3.25)");
}

TEST(GcodeIso, MalformedNumbersAndNonFiniteTextAreErrors) {
  for (const char* bad : {"G01 X F100", "G01 X1.2.3 F100", "G01 Xnan F100", "G01 Xinf F100", "G01 X-inf F100",
                          "G01 X-- F100", "G01 X+ F100", "G01 X. F100", "G01 X1-2 F100", "G01 X1 F1e3"}) {
    const std::string e = iso_error(bad);
    EXPECT_THAT(e, HasSubstr("t.nc:1:")) << bad;
    EXPECT_FALSE(e.empty()) << bad;
  }
  EXPECT_THAT(iso_error("G01 Xnan F100"), HasSubstr("t.nc:1:5: expected a number after 'X'"));
  EXPECT_THAT(iso_error("G01 X10000000000 F100"), HasSubstr("number out of range in 'X10000000000'"));
  EXPECT_THAT(iso_error("G01 X999999999999999999999999999999999999999 F1"), HasSubstr("out of range"));
  EXPECT_THAT(iso_error("G1.5 X1"), HasSubstr("unknown word 'G1.5'"));
  EXPECT_THAT(iso_error("M3.5"), HasSubstr("M takes a non-negative whole number"));
  EXPECT_THAT(iso_error("N-5"), HasSubstr("N takes a non-negative whole number"));
  EXPECT_THAT(iso_error("G-1"), HasSubstr("G takes a non-negative number"));
}

TEST(GcodeIso, FeedRules) {
  EXPECT_THAT(iso_error("G01 X1\n"), HasSubstr("t.nc:1:1: no feed programmed: G01 needs F > 0"));
  EXPECT_THAT(iso_error("G00 X1\nG02 X1 Y0 I1\n"), HasSubstr("t.nc:2:1: no feed programmed: G02"));
  EXPECT_THAT(iso_error("G01 X1 F0\n"), HasSubstr("t.nc:1:8: feed F must be > 0 (got 0)"));
  EXPECT_THAT(iso_error("G01 X1 F-5\n"), HasSubstr("feed F must be > 0 (got -5)"));
  EXPECT_THAT(iso_error("G00 X1 F0\n"), HasSubstr("feed F must be > 0"));
  // A rapid needs no feed; its block carries the modal feed (0 when none).
  const Program p = iso("G00 X1\nG01 X2 F50\nG00 X3\n");
  EXPECT_EQ(p.blocks[0].feed_mm_min, 0.0);
  EXPECT_EQ(p.blocks[2].feed_mm_min, 50.0);
}

TEST(GcodeIso, ArcErrors) {
  EXPECT_THAT(iso_error("G01 X1 F100\nG02 X2 Y1\n"), HasSubstr("t.nc:2:1: arc needs its centre (IJ in G17) or a radius R"));
  EXPECT_THAT(iso_error("G01 X1 F100\nG02 X1 R5\n"), HasSubstr("t.nc:2:8: an arc by radius R needs an end point different"));
  EXPECT_THAT(iso_error("G01 X1 F100\nG02 X3 R0\n"), HasSubstr("radius R must not be 0"));
  EXPECT_THAT(iso_error("G01 X1 F100\nG02 X3 I1 R1\n"), HasSubstr("either R or its centre"));
  EXPECT_THAT(iso_error("G01 X1 F100\nG02 X2 Y1 I1 K1\n"),
              HasSubstr("t.nc:2:14: 'K1' is not in the XY plane (G17)"));
  EXPECT_THAT(iso_error("G18 G01 X1 F100\nG02 X2 Z1 J1\n"), HasSubstr("'J1' is not in the ZX plane (G18)"));
  EXPECT_THAT(iso_error("G01 X0 F100\nG02 X0 Y0 I0 J0\n"), HasSubstr("radius 0"));
  EXPECT_THAT(iso_error("G01 X1 I1 F100\n"), HasSubstr("t.nc:1:8: I/J/K and R are only used with arcs (G02/G03), not with G01"));
  EXPECT_THAT(iso_error("G00 X1 R1\n"), HasSubstr("not with G00"));
}

TEST(GcodeIso, ArcRadiusMustCloseWithinTolerance) {
  // Start radius 10 about (0, 0); end (0, 10.001) radius 10.001: difference 0.001 < 0.002 (abs)
  // and 0.01 (rel 1e-3 x 10) -> accepted. End (0, 10.05): 0.05 > 0.01 -> rejected.
  EXPECT_NO_THROW(iso("G01 X10 Y0 F100\nG03 X0 Y10.001 I-10 J0\n"));
  EXPECT_THAT(iso_error("G01 X10 Y0 F100\nG03 X0 Y10.05 I-10 J0\n"),
              HasSubstr("arc does not close: radius 10 mm at the start, 10.05 mm at the end"));
  ParseOptions tight;
  tight.arc_tolerance_abs_mm = 0.0;
  tight.arc_tolerance_rel = 0.0;
  EXPECT_THROW(parse_iso("G01 X10 Y0 F100\nG03 X0 Y10.001 I-10 J0\n", "t.nc", tight), core::InputError);
  ParseOptions bad;
  bad.arc_tolerance_abs_mm = -1.0;
  EXPECT_THROW(parse_iso("G00 X1\n", "t.nc", bad), core::InputError);
}

TEST(GcodeIso, ModalGroupConflictsAndRepeatedWords) {
  EXPECT_EQ(iso_error("G00 G01 X1 F100\n"), "t.nc:1:5: G00 and G01 on one line are in the same modal group (motion)");
  EXPECT_THAT(iso_error("G17 G18\n"), HasSubstr("same modal group (plane selection)"));
  EXPECT_THAT(iso_error("G20 G21\n"), HasSubstr("same modal group (units)"));
  EXPECT_THAT(iso_error("G90 G91\n"), HasSubstr("same modal group (distance mode)"));
  EXPECT_THAT(iso_error("G01 X1 X2 F100\n"), HasSubstr("t.nc:1:8: word X appears twice on the line"));
  EXPECT_THAT(iso_error("N1 N2\n"), HasSubstr("second N number"));
  EXPECT_THAT(iso_error("X1 Y2\n"), HasSubstr("t.nc:1:1: axis words without a motion mode"));
  EXPECT_THAT(iso_error("G01 X1 P2 F100\n"), HasSubstr("P is only used with G04"));
  EXPECT_THAT(iso_error("G01 X1 (open comment\n"), HasSubstr("t.nc:1:8: comment '(' is not closed"));
}

TEST(GcodeIso, UnsupportedFeaturesAreErrorsOrWarnings) {
  EXPECT_THAT(iso_error("G95 G01 X1 F1\n"), HasSubstr("only feed per minute (G94) is supported"));
  EXPECT_THAT(iso_error("G41 G01 X1 F1\n"), HasSubstr("cutter radius compensation is not supported"));
  EXPECT_THAT(iso_error("G01 X1 F1 #5\n"), HasSubstr("t.nc:1:11: unexpected character '#'"));
  EXPECT_THAT(iso_error("G01 X1 F1 S1000 T2\n"), HasSubstr("unknown word 'S1000'"));

  const Program p = iso("G01 X1 F100 S1000 Q-5.5 #\nG65 G01 X2\n\xff", true);
  ASSERT_EQ(p.blocks.size(), 2U) << "a line of ignored garbage makes no block";
  EXPECT_EQ(p.blocks[0].end[0], 1.0);
  EXPECT_EQ(p.blocks[1].end[0], 2.0);
  ASSERT_EQ(p.warnings.size(), 5U);
  EXPECT_EQ(p.warnings[0].line, 1U);
  EXPECT_EQ(p.warnings[0].column, 13U);
  EXPECT_EQ(p.warnings[0].message, "unknown word 'S1000' (ignored)");
  EXPECT_EQ(p.warnings[1].column, 19U);
  EXPECT_EQ(p.warnings[1].message, "unknown word 'Q-5.5' (ignored)");
  EXPECT_EQ(p.warnings[2].message, "unexpected character '#' (ignored)");
  EXPECT_EQ(p.warnings[3].line, 2U);
  EXPECT_EQ(p.warnings[3].message, "unknown word 'G65' (ignored)");
  EXPECT_EQ(p.warnings[4].message, "unexpected character '\\xff' (ignored)");
  // Malformed numbers stay errors in lenient mode.
  EXPECT_THROW(iso("G01 X1..2 F100\n", true), core::InputError);
  // So does an exponent (issue 27 §3.9): read as F1 and an unknown word e30, F1e30 made a 1200 s
  // move of 10 mm.
  for (const char* exp : {"G01 X10 F1e30\n", "G01 X10 F1E+3\n", "G01 X1.5e-2 F100\n"}) {
    try {
      (void)iso(exp, true);
      ADD_FAILURE() << exp;
    } catch (const core::InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("G-code numbers have no exponent")) << exp;
    }
  }
  EXPECT_THAT(iso_error("G01 X10 F1e30\n"), HasSubstr("t.nc:1:9: malformed number in 'F1e30'"));
  // A letter E after a blank is a word of its own (unknown, a warning here).
  EXPECT_EQ(iso("G01 X10 F100 E5\n", true).warnings.size(), 1U);
}

TEST(GcodeIso, WarningListIsCapped) {
  std::string text;
  for (int i = 0; i < 3000; ++i) text += "Q1\n";
  const Program p = iso(text, true);
  EXPECT_EQ(p.warnings.size(), 1001U);
  EXPECT_THAT(p.warnings.back().message, HasSubstr("more than 1000 warnings"));
}

TEST(GcodeIso, CoordinatesOutOfRangeAfterIncrementalSums) {
  EXPECT_THAT(iso_error("G91 G00 X999999999\nX999999999\n"), HasSubstr("t.nc:2:1: coordinate out of range"));
}

TEST(GcodeIso, BinaryGarbageIsAnInputError) {
  const std::string garbage("\x00\x01\x02\x80\xfe", 5);
  EXPECT_THAT(iso_error(garbage), HasSubstr("t.nc:1:1: unexpected character '\\x00'"));
  EXPECT_NO_THROW(iso(garbage, true));
}

TEST(GcodeIso, EmptyProgram) {
  EXPECT_TRUE(iso("").blocks.empty());
  EXPECT_TRUE(iso("%\n\n%\n").blocks.empty());
}

}  // namespace gcode_iso_test
}  // namespace
}  // namespace servotwin::motion
