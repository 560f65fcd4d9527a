// Heidenhain conversational reader. Expected values: thesis Tables 4.3/4.4 as printed (the OCR'd
// table columns re-assembled, the elided middle cut) and closed-form arc geometry.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "gcode_test_support.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion {
namespace {

using test::heidenhain;
using test::heidenhain_error;
using test::hh;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr std::uint8_t kX = axis_bit(Axis::X);
constexpr std::uint8_t kY = axis_bit(Axis::Y);
constexpr std::uint8_t kZ = axis_bit(Axis::Z);


TEST(GcodeHeidenhain, ReadsThesisTable44) {
  const Program p = heidenhain(test::kThesisTable44);
  EXPECT_EQ(p.dialect, Dialect::Heidenhain);
  EXPECT_EQ(p.name, "RAPIDIDENT");
  EXPECT_TRUE(p.warnings.empty());
  ASSERT_EQ(p.blocks.size(), 18U);
  EXPECT_EQ(p.blocks[0].type, BlockType::None);
  EXPECT_EQ(p.blocks[0].number, -1);
  EXPECT_EQ(p.blocks[0].comment, "Rapid Identification on TNC 430 5 axis machine");
  EXPECT_EQ(p.blocks[1].statement, "BLK FORM 0.1 Z X-50.000 Y-50.000 Z-50.000");
  EXPECT_EQ(p.blocks[2].statement, "BLK FORM 0.2 X+50.000 Y+50.000 Z+50.000");
  EXPECT_EQ(p.blocks[3].statement, "TOOL CALL 0 Z");
  EXPECT_EQ(p.blocks[3].number, 3);

  const Block& retract = p.blocks[4];
  EXPECT_EQ(retract.type, BlockType::Rapid);
  EXPECT_EQ(retract.end, (Point{0.0, 0.0, 200.0}));
  EXPECT_EQ(retract.axes, kZ);
  EXPECT_EQ(retract.feed_mm_min, 0.0) << "no numeric feed yet";
  const Block& position = p.blocks[5];
  EXPECT_EQ(position.type, BlockType::Rapid);
  EXPECT_EQ(position.axes, kX | kY);
  EXPECT_THAT(position.m_codes, ElementsAre(3));
  EXPECT_EQ(p.blocks[6].end, (Point{0.0, 0.0, 0.0}));

  const double x[] = {-9.375, 9.375, -5.280, -5.552, 0.158, 6.539, -1.538, -9.375, 9.375, 0.0};
  for (std::size_t i = 0; i < 10; ++i) {
    const Block& b = p.blocks[7 + i];
    EXPECT_EQ(b.type, BlockType::Linear) << i;
    EXPECT_EQ(b.end[0], x[i]) << i;
    EXPECT_EQ(b.feed_mm_min, 15000.0) << "F is modal after F MAX blocks";
    EXPECT_EQ(b.number, static_cast<long>(7 + i));
  }
  EXPECT_THAT(p.blocks[17].m_codes, ElementsAre(30));
  EXPECT_EQ(p.used_axes(), kX | kY | kZ);
}

TEST(GcodeHeidenhain, ReadsThesisTable43Start) {
  // Table 4.3 prints `X-0.000` and `X+0.000`: both are the centre (and -0 is stored as +0).
  const Program p = heidenhain(
      "0 BEGIN PGM RAPIDIDENT MM\n"
      "5 L X+0.000 Y+0.000 R0 F MAX M3\n"
      "7 L X-0.000 F 15000.000\n"
      "8 L X+0.000\n"
      "9 L X-0.002\n"
      "10 L X-0.002\n"
      "11 L X-0.004\n"
      "206 M30\n"
      "207 END PGM RAPIDIDENT MM\n");
  ASSERT_EQ(p.blocks.size(), 7U);
  EXPECT_EQ(p.blocks[1].end[0], 0.0);
  EXPECT_FALSE(std::signbit(p.blocks[1].end[0]));
  EXPECT_EQ(p.blocks[3].end[0], -0.002);
  EXPECT_EQ(p.blocks[5].end[0], -0.004);
}

TEST(GcodeHeidenhain, IncrementalFmaxCaseAndOptionalNumbers) {
  const Program p = heidenhain(hh("l x+1 y+2 fmax\nL IX+1.5 IY-1 F500\n7 L IZ-3\n"));
  ASSERT_EQ(p.blocks.size(), 3U);
  EXPECT_EQ(p.blocks[0].type, BlockType::Rapid);
  EXPECT_EQ(p.blocks[0].number, -1);
  EXPECT_EQ(p.blocks[1].end, (Point{2.5, 1.0, 0.0}));
  EXPECT_EQ(p.blocks[1].feed_mm_min, 500.0);
  EXPECT_EQ(p.blocks[2].end, (Point{2.5, 1.0, -3.0}));
  EXPECT_EQ(p.blocks[2].axes, kZ);
}

TEST(GcodeHeidenhain, InchProgram) {
  const Program p = heidenhain("0 BEGIN PGM A INCH\n1 L X+1 F 10\n2 BLK FORM 0.1 Z X+1 Y+2 Z-1\n3 END PGM A INCH\n");
  EXPECT_EQ(p.blocks[0].end[0], 25.4);
  EXPECT_DOUBLE_EQ(p.blocks[0].feed_mm_min, 254.0);
  EXPECT_EQ(p.blocks[1].statement, "BLK FORM 0.1 Z X+25.400 Y+50.800 Z-25.400") << "statements are kept in mm";
}

TEST(GcodeHeidenhain, CircleAboutCcAndFullCircle) {
  // From (10, 0) about CC (10, 10), radius 10: DR+ to (20, 10) is a quarter circle counterclockwise.
  const Program p = heidenhain(hh("L X+10 Y+0 F 100\nCC X+10 Y+10\nC X+20 Y+10 DR+\nC X+20 Y+10 DR-\n"));
  ASSERT_EQ(p.blocks.size(), 3U) << "CC makes no block";
  const Block& quarter = p.blocks[1];
  EXPECT_EQ(quarter.type, BlockType::ArcCcw);
  EXPECT_EQ(quarter.plane, Plane::XY);
  EXPECT_EQ(quarter.center[0], 10.0);
  EXPECT_EQ(quarter.center[1], 10.0);
  EXPECT_EQ(quarter.feed_mm_min, 100.0);
  const Block& full = p.blocks[2];
  EXPECT_EQ(full.type, BlockType::ArcCw);
  EXPECT_EQ(full.start, full.end);
}

TEST(GcodeHeidenhain, CcCoordinatesChooseThePlane) {
  // CC Z X: the arc turns in the Z-X plane. From (10, 0, 0) about (x 0, z 0) to (x 0, z 10).
  Program p = heidenhain(hh("L X+10 Y+0 Z+0 F 100\nCC Z+0 X+0\nC X+0 Z+10 DR-\n"));
  EXPECT_EQ(p.blocks[1].plane, Plane::ZX);
  EXPECT_EQ(p.blocks[1].center[0], 0.0);
  EXPECT_EQ(p.blocks[1].center[2], 0.0);
  // One coordinate: the other comes from the current position.
  p = heidenhain(hh("L X+10 Y+5 F 100\nCC X+0\nC X+0 Y+15 DR+\n"));
  EXPECT_EQ(p.blocks[1].center[0], 0.0);
  EXPECT_EQ(p.blocks[1].center[1], 5.0);
  // Incremental centre, relative to the current position.
  p = heidenhain(hh("L X+10 Y+5 F 100\nCC IX-10\nC X+0 Y+15 DR+\n"));
  EXPECT_EQ(p.blocks[1].center[0], 0.0);
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC Z+5\n")), HasSubstr("t.h:3:1: CC Z is not in the working plane XY"));
  EXPECT_THAT(heidenhain_error(hh("CC X+1 Y+2 Z+3\n")), HasSubstr("at most two coordinates"));
  EXPECT_THAT(heidenhain_error(hh("CC X+1 Y+2 F 100\n")), HasSubstr("CC takes only the coordinates"));
}

TEST(GcodeHeidenhain, RadiusArcs) {
  // Same closed form as the ISO test: chord (0,0)->(8,0), |R| = 5, centre (4, -3) or (4, 3).
  const Program p = heidenhain(hh("L X+0 Y+0 F 100\nCR X+8 Y+0 R+5 DR-\nCR X+0 Y+0 R-5 DR-\n"));
  EXPECT_EQ(p.blocks[1].type, BlockType::ArcCw);
  EXPECT_NEAR(p.blocks[1].center[0], 4.0, 1e-12);
  EXPECT_NEAR(p.blocks[1].center[1], -3.0, 1e-12);
  // Back from (8, 0) to (0, 0): the chord points along -x, so "right" is +y; R- takes the far side.
  EXPECT_NEAR(p.blocks[2].center[0], 4.0, 1e-12);
  EXPECT_NEAR(p.blocks[2].center[1], -3.0, 1e-12);
  EXPECT_THAT(heidenhain_error(hh("L X+0 Y+0 F 100\nCR X+8 Y+0 DR-\n")), HasSubstr("CR needs the radius R"));
  EXPECT_THAT(heidenhain_error(hh("L X+0 Y+0 F 100\nCR X+0 Y+0 R+5 DR-\n")), HasSubstr("end point different"));
  EXPECT_THAT(heidenhain_error(hh("L X+0 Y+0 F 100\nCR X+20 R+5 DR-\n")), HasSubstr("smaller than half the distance"));
}

TEST(GcodeHeidenhain, ToolAxisSetsTheWorkingPlane) {
  // TOOL CALL ... Y: the working plane is Z-X, so CR turns there.
  const Program p = heidenhain(hh("TOOL CALL 2 Y S5000\nL X+0 Y+0 Z+0 F 100\nCR Z+8 X+0 R+5 DR-\n"));
  EXPECT_EQ(p.blocks[0].statement, "TOOL CALL 2 Y S5000");
  EXPECT_EQ(p.blocks[0].plane, Plane::ZX);
  EXPECT_EQ(p.blocks[2].plane, Plane::ZX);
  EXPECT_EQ(p.blocks[1].plane, Plane::ZX);
  EXPECT_NEAR(p.blocks[2].center[2], 4.0, 1e-12);
  EXPECT_NEAR(std::fabs(p.blocks[2].center[0]), 3.0, 1e-12);
  const Program named = heidenhain(hh("TOOL CALL \"MILL D10\" Z\n"));
  EXPECT_EQ(named.blocks[0].statement, "TOOL CALL \"MILL D10\" Z");
}

TEST(GcodeHeidenhain, HelicalArc) {
  const Program p = heidenhain(hh("L X+10 Y+0 Z+0 F 100\nCC X+0 Y+0\nC X+0 Y+10 Z+5 DR+\n"));
  EXPECT_EQ(p.blocks[1].end, (Point{0.0, 10.0, 5.0}));
  EXPECT_EQ(p.blocks[1].center[2], 0.0);
}

TEST(GcodeHeidenhain, Dwell) {
  const Program p = heidenhain(hh("CYCL DEF 9.0 DWELL TIME\nCYCL DEF 9.1 DWELL 1.5 ;wait\n"));
  ASSERT_EQ(p.blocks.size(), 1U);
  EXPECT_EQ(p.blocks[0].type, BlockType::Dwell);
  EXPECT_EQ(p.blocks[0].dwell_s, 1.5);
  EXPECT_EQ(p.blocks[0].comment, "wait");
  EXPECT_THAT(heidenhain_error(hh("CYCL DEF 9.1 DWELL 1.5\n")), HasSubstr("without CYCL DEF 9.0"));
  EXPECT_THAT(heidenhain_error(hh("CYCL DEF 9.0 DWELL TIME\nL X+1 F 100\n")), HasSubstr("t.h:2:1: CYCL DEF 9.0 must be followed"));
  EXPECT_THAT(heidenhain_error(hh("CYCL DEF 9.0 DWELL TIME\nCYCL DEF 9.1 DWELL -1\n")), HasSubstr("dwell time must be >= 0"));
  EXPECT_THAT(heidenhain_error(hh("CYCL DEF 7.0 DATUM SHIFT\n")), HasSubstr("t.h:2:10: cycle '7.0' is not supported"));
}

TEST(GcodeHeidenhain, FeedRules) {
  EXPECT_THAT(heidenhain_error(hh("L X+1\n")), HasSubstr("t.h:2:1: no feed programmed: L needs F"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F MAX\nL X+2\n")), HasSubstr("t.h:3:1: no feed programmed"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 0\n")), HasSubstr("t.h:2:7: feed F must be > 0 (got 0)"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F -5\n")), HasSubstr("feed F must be > 0"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F MAX F 100\n")), HasSubstr("feed given twice"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F FAST\n")), HasSubstr("F takes a feed in mm/min or MAX"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+0 Y+0\nC X-1 DR+ F MAX\n")), HasSubstr("F MAX is only allowed on straight lines"));
  // L without coordinates moves nothing but sets the feed.
  const Program p = heidenhain(hh("L F 250 M8\nL X+1\n"));
  EXPECT_EQ(p.blocks[0].type, BlockType::None);
  EXPECT_THAT(p.blocks[0].m_codes, ElementsAre(8));
  EXPECT_EQ(p.blocks[1].feed_mm_min, 250.0);
}

TEST(GcodeHeidenhain, ArcErrors) {
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nC X+2 DR+\n")), HasSubstr("t.h:3:1: C needs a circle centre: program CC first"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+0 Y+0\nC X-1\n")), HasSubstr("C needs the direction DR+"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+0 Y+0\nC DR+\n")), HasSubstr("C needs an end point"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+0 Y+0\nC X+3 DR+\n")), HasSubstr("arc does not close"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+1 Y+0\nC X+3 DR+\n")), HasSubstr("radius 0"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 DR+ F 100\n")), HasSubstr("t.h:2:7: 'DR+' is only used with C and CR"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+0 Y+0\nC X-1 DR\n")), HasSubstr("DR needs a direction"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 F 100\nCC X+0 Y+0\nC X-1 DR+5\n")), HasSubstr("DR takes only a sign"));
}

TEST(GcodeHeidenhain, RadiusCompensation) {
  EXPECT_THAT(heidenhain_error(hh("L X+1 RL F 100\n")), HasSubstr("t.h:2:7: radius compensation 'RL' is not supported"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 R5 F 100\n")), HasSubstr("only R0 (no radius compensation)"));
  const Program p = heidenhain(hh("L X+1 RR F 100\n"), true);
  ASSERT_EQ(p.blocks.size(), 1U);
  EXPECT_EQ(p.blocks[0].end[0], 1.0);
  ASSERT_EQ(p.warnings.size(), 1U);
  EXPECT_EQ(p.warnings[0].line, 2U);
  EXPECT_EQ(p.warnings[0].column, 7U);
  EXPECT_EQ(p.warnings[0].message, "radius compensation 'RR' is not supported (ignored)");
}

TEST(GcodeHeidenhain, ProgramFrame) {
  EXPECT_THAT(heidenhain_error("1 L X+1 F 100\n"), HasSubstr("t.h:1:3: expected 'BEGIN PGM name MM' as the first block, found 'L'"));
  EXPECT_THAT(heidenhain_error(""), HasSubstr("no 'BEGIN PGM name MM' found"));
  EXPECT_THAT(heidenhain_error("0 BEGIN PGM A MM\n1 END PGM B MM\n"), HasSubstr("t.h:2:3: 'END PGM B MM' does not match 'BEGIN PGM A MM'"));
  EXPECT_THAT(heidenhain_error("0 BEGIN PGM A MM\n1 END PGM A INCH\n"), HasSubstr("does not match"));
  EXPECT_THAT(heidenhain_error("0 BEGIN PGM A CM\n"), HasSubstr("t.h:1:15: expected MM or INCH"));
  EXPECT_THAT(heidenhain_error("0 BEGIN PGM A MM\n1 L X+1 F 100\n"), HasSubstr("t.h:2:1: missing 'END PGM A MM' at the end"));
  EXPECT_THAT(heidenhain_error("0 BEGIN PGM A MM\n1 END PGM A MM\n2 L X+1\n"), HasSubstr("t.h:3:1: text after END PGM"));
  EXPECT_THAT(heidenhain_error("0 BEGIN PGM A MM\n1 BEGIN PGM A MM\n"), HasSubstr("second BEGIN PGM"));
  EXPECT_THAT(heidenhain_error(hh("5L X+1 F 100\n")), HasSubstr("block number must be followed by a blank"));
  const Program lenient = heidenhain("0 BEGIN PGM A MM\n1 L X+1 F 100\n", true);
  ASSERT_EQ(lenient.warnings.size(), 1U);
  EXPECT_THAT(lenient.warnings[0].message, HasSubstr("missing 'END PGM A MM'"));
  // Comment lines may come first; a program after blank lines is still found.
  EXPECT_NO_THROW(heidenhain("\n; header\n0 BEGIN PGM A MM\n1 END PGM A MM\n\n"));
}

TEST(GcodeHeidenhain, UnsupportedStatementsAreErrorsOrSkippedWithWarnings) {
  EXPECT_THAT(heidenhain_error(hh("RND R5\n")), HasSubstr("t.h:2:1: 'RND' is not supported"));
  EXPECT_THAT(heidenhain_error(hh("LP PR+10 PA+30\n")), HasSubstr("'LP' is not supported"));
  EXPECT_THAT(heidenhain_error(hh("FOO 1\n")), HasSubstr("unknown word 'FOO'"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 Q5 F 100\n")), HasSubstr("t.h:2:7: unknown word 'Q5'"));
  const Program p = heidenhain(hh("RND R5\nL X+1 F 100 Q7\n"), true);
  ASSERT_EQ(p.blocks.size(), 1U);
  ASSERT_EQ(p.warnings.size(), 2U);
  EXPECT_EQ(p.warnings[0].message, "'RND' is not supported (ignored)");
  EXPECT_EQ(p.warnings[1].column, 13U);
}

TEST(GcodeHeidenhain, MalformedNumbers) {
  EXPECT_THAT(heidenhain_error(hh("L X+1.2.3 F 100\n")), HasSubstr("t.h:2:3: malformed number in 'X+1.2.3'"));
  EXPECT_THAT(heidenhain_error(hh("L X+nan F 100\n")), HasSubstr("malformed number"));
  EXPECT_THAT(heidenhain_error(hh("L X+10 F1e3\n")), HasSubstr("malformed number in 'F1e3': G-code numbers have no exponent"));
  EXPECT_THAT(heidenhain_error(hh("L X F 100\n")), HasSubstr("expected a number after 'X'"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 X+2 F 100\n")), HasSubstr("axis X given twice"));
  EXPECT_THAT(heidenhain_error(hh("L X+1 IX+2 F 100\n")), HasSubstr("axis X given twice"));
  EXPECT_THAT(heidenhain_error(hh("BLK FORM 0.3 X+1\n")), HasSubstr("expected 0.1 or 0.2 after BLK FORM"));
  EXPECT_THAT(heidenhain_error(hh("BLK FORM 0.1 Q X+1\n")), HasSubstr("t.h:2:14: expected the tool axis"));
  EXPECT_THAT(heidenhain_error(hh("TOOL CALL Z\n")), HasSubstr("expected a tool number"));
  EXPECT_THAT(heidenhain_error(hh("M3.5\n")), HasSubstr("M takes a non-negative whole number"));
}

TEST(GcodeHeidenhain, DetectsDialect) {
  EXPECT_EQ(detect_dialect(test::kThesisTable44), Dialect::Heidenhain);
  EXPECT_EQ(detect_dialect("; note\n\n  0   begin pgm X mm\n"), Dialect::Heidenhain);
  EXPECT_EQ(detect_dialect("%\n(BEGIN PGM in a comment)\nN10 G00 X0\n"), Dialect::Iso);
  EXPECT_EQ(detect_dialect("BEGINNING X1\n"), Dialect::Iso);
  EXPECT_EQ(detect_dialect(""), Dialect::Iso);
  EXPECT_EQ(parse_program(test::kThesisTable44, "a").dialect, Dialect::Heidenhain);
  EXPECT_EQ(parse_program("G00 X1\n", "a").dialect, Dialect::Iso);
  EXPECT_THROW(parse_program("G00 X1\n", "a", {}, Dialect::Heidenhain), core::InputError);
}

}  // namespace
}  // namespace servotwin::motion
