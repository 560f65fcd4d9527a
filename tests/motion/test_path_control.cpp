// Path-control modes (ISO modal group 13, Heidenhain Cycle 32): what each dialect reads and writes,
// as specified by the LinuxCNC G-code reference (G61 exact path, G61.1 exact stop, G64 P<p> Q<q>
// in program units, P0 = plain G64), Fanuc's operator's manual (G61 exact stop mode, G64 cutting
// mode without a tolerance) and Heidenhain's Cycle 32 (`CYCL DEF 32.0 TOLERANCE`, `32.1 T<tol>`,
// a bare 32.1 restores the machine's value); how the generators state a mode; and how the
// planner honours it at each junction (exact stop / run on), checked on the plan's junction speeds.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {

using ::testing::HasSubstr;

/// Path control of the motion blocks, in order.
std::vector<PathControl> modes_of(const Program& p) {
  std::vector<PathControl> out;
  for (const Block& b : p.blocks)
    if (b.type != BlockType::None && b.type != BlockType::Dwell) out.push_back(b.path_control);
  return out;
}

void expect_error(const std::function<void()>& f, const std::string& text) {
  EXPECT_THAT(f, testing::ThrowsMessage<core::InputError>(HasSubstr(text)));
}

TEST(PathControl, IsoReadsG61AndG64PerBlockModally) {
  const Program p = parse_iso("G01 X1 F1000\nG61\nG01 X2\nX3\nG64 G01 X4\nX5\n", "modes.nc");
  EXPECT_EQ(modes_of(p), (std::vector<PathControl>{PathControl::Unstated, PathControl::ExactStop, PathControl::ExactStop,
                                                    PathControl::Blend, PathControl::Blend}));
  EXPECT_FALSE(parse_iso("G01 X1 F1000\n", "none.nc").states_path_control());
  EXPECT_TRUE(p.states_path_control());
  EXPECT_TRUE(p.blends());
  for (const Block& b : p.blocks) EXPECT_EQ(b.blend_tolerance_mm, 0.0);
}

TEST(PathControl, IsoPointsLinuxCncSyntaxToTheLinuxCncDialect) {
  expect_error([] { (void)parse_iso("G64 P0.01 G01 X1 F100\n", "p.nc"); }, "--dialect linuxcnc");
  expect_error([] { (void)parse_iso("G61.1\n", "p.nc"); }, "--dialect linuxcnc");
  expect_error([] { (void)parse_iso("G61 G64\n", "p.nc"); }, "same modal group");
}

TEST(PathControl, LinuxCncReadsExactPathExactStopAndTolerances) {
  const Program p = parse_linuxcnc("G21 G61 G01 X1 F1000\nG61.1 X2\nG64 P0.05 Q0.01 X3\nG64 X4\nG64 P0 X5\n", "l.ngc");
  EXPECT_EQ(p.dialect, Dialect::LinuxCnc);
  EXPECT_EQ(modes_of(p), (std::vector<PathControl>{PathControl::ExactPath, PathControl::ExactStop, PathControl::Blend,
                                                    PathControl::Blend, PathControl::Blend}));
  EXPECT_DOUBLE_EQ(p.blocks[2].blend_tolerance_mm, 0.05);
  EXPECT_DOUBLE_EQ(p.blocks[2].cam_tolerance_mm, 0.01);
  EXPECT_EQ(p.blocks[3].blend_tolerance_mm, 0.0);  // G64 alone resets the tolerance
  EXPECT_LT(p.blocks[3].cam_tolerance_mm, 0.0);
  EXPECT_EQ(p.blocks[4].blend_tolerance_mm, 0.0);  // "G64 P0 has the same effect as G64 alone"
  // P is in program units: G20 inch.
  const Program inch = parse_linuxcnc("G20 G64 P0.001 G01 X1 F10\n", "i.ngc");
  EXPECT_DOUBLE_EQ(inch.blocks[0].blend_tolerance_mm, 0.0254);
  // The dwell keeps its P; a mode on the same line as a dwell cannot have one too.
  EXPECT_DOUBLE_EQ(parse_linuxcnc("G64 P0.1\nG04 P0.5\n", "d.ngc").blocks[1].dwell_s, 0.5);
  expect_error([] { (void)parse_linuxcnc("G64 P0.1 G04 P1\n", "d.ngc"); }, "appears twice");
  expect_error([] { (void)parse_linuxcnc("G64 P-1\n", "n.ngc"); }, "must be >= 0");
  expect_error([] { (void)parse_linuxcnc("G64 Q0.1\n", "q.ngc"); }, "needs P");
  expect_error([] { (void)parse_linuxcnc("G61 P0.1\n", "q.ngc"); }, "P is only used with G04");
  expect_error([] { (void)parse_linuxcnc("G01 X1 F10 Q3\n", "q.ngc"); }, "Q is only used with G64");
  // parse_program picks the reader by the given dialect.
  EXPECT_EQ(parse_program("G64 P0.1\n", "a.ngc", {}, Dialect::LinuxCnc).dialect, Dialect::LinuxCnc);
}

TEST(PathControl, WritersStateTheModeWhenItChangesAndReadBackTheSame) {
  const Program linuxcnc =
      parse_linuxcnc("G61.1 G01 X1 F1000\nX2\nG61 X3\nG64 P0.02 X4\nG64 P0.02 Q0.005 X5\nG04 P1\nG64 X6\n", "w.ngc");
  const std::string text = write_linuxcnc(linuxcnc);
  EXPECT_THAT(text, HasSubstr("G61.1 G01 X1.000 F1000\nG01 X2.000\nG61 G01 X3.000\nG64 P0.020 G01 X4.000\n"
                              "G64 P0.020 Q0.005 G01 X5.000\nG04 P1.000\nG64 G01 X6.000\n"));
  const Program back = parse_linuxcnc(text, "back.ngc");
  ASSERT_EQ(back.blocks.size(), linuxcnc.blocks.size());
  for (std::size_t i = 0; i < back.blocks.size(); ++i) {
    EXPECT_EQ(back.blocks[i].path_control, linuxcnc.blocks[i].path_control) << i;
    EXPECT_EQ(back.blocks[i].blend_tolerance_mm, linuxcnc.blocks[i].blend_tolerance_mm) << i;
    EXPECT_EQ(back.blocks[i].cam_tolerance_mm, linuxcnc.blocks[i].cam_tolerance_mm) << i;
  }
  // ISO has no tolerance word and no exact path: G61 (the stricter exact stop) and plain G64.
  const std::string iso = write_iso(linuxcnc);
  EXPECT_THAT(iso, HasSubstr("G61 G01 X1.000 F1000\nG01 X2.000\nG01 X3.000\nG64 G01 X4.000\n"));
  EXPECT_THAT(iso, testing::Not(HasSubstr("P0.02")));
  EXPECT_EQ(modes_of(parse_iso(iso, "iso.nc")),
            (std::vector<PathControl>{PathControl::ExactStop, PathControl::ExactStop, PathControl::ExactStop,
                                      PathControl::Blend, PathControl::Blend, PathControl::Blend}));
  // A mode change at a dwell goes on a line of its own (G64's P and G04's P would clash).
  const std::string dwell = write_linuxcnc(parse_linuxcnc("G61.1 G01 X1 F100\nG64 P0.1\nG04 P2\nG01 X2\n", "dw.ngc"));
  EXPECT_THAT(dwell, HasSubstr("\nG64 P0.100\nG04 P2.000\n"));
}

TEST(PathControl, HeidenhainCycle32IsItsMeans) {
  const std::string text =
      "0 BEGIN PGM T MM\n1 TOOL CALL 0 Z\n2 L X+0 Y+0 R0 F MAX\n3 CYCL DEF 32.0 TOLERANCE\n4 CYCL DEF 32.1 T0.05\n"
      "5 CYCL DEF 32.2 HSC-MODE:0 TA0.5\n6 L X+10 F 6000\n7 CYCL DEF 32.0 TOLERANCE\n8 CYCL DEF 32.1\n9 L X+20\n"
      "10 END PGM T MM\n";
  const Program p = parse_heidenhain(text, "t.h");
  EXPECT_EQ(modes_of(p), (std::vector<PathControl>{PathControl::Unstated, PathControl::Blend, PathControl::Unstated}));
  const auto x10 = std::find_if(p.blocks.begin(), p.blocks.end(), [](const Block& b) { return b.end[0] == 10.0; });
  ASSERT_NE(x10, p.blocks.end());
  EXPECT_DOUBLE_EQ(x10->blend_tolerance_mm, 0.05);
  // The written program states the same and reads back the same.
  const std::string written = write_heidenhain(p);
  EXPECT_THAT(written, HasSubstr("CYCL DEF 32.0 TOLERANCE\n4 CYCL DEF 32.1 T0.050\n5 CYCL DEF 32.2 HSC-MODE:0 TA0.5\n"));
  EXPECT_THAT(written, HasSubstr("CYCL DEF 32.0 TOLERANCE\n8 CYCL DEF 32.1\n9 L X+20.000\n"));
  EXPECT_EQ(modes_of(parse_heidenhain(written, "w.h")), modes_of(p));
  // An ISO mode Klartext cannot state is kept as a comment, once.
  const std::string from_iso = write_heidenhain(parse_iso("G61 G01 X1 F100\nX2\n", "e.nc"));
  EXPECT_THAT(from_iso, HasSubstr(";path control: exact stop at every block end - not expressible in Klartext"));
  const std::string h = "0 BEGIN PGM T MM\n";
  expect_error([&] { (void)parse_heidenhain(h + "1 CYCL DEF 32.1 T0.1\n", "a.h"); }, "without CYCL DEF 32.0");
  expect_error([&] { (void)parse_heidenhain(h + "1 CYCL DEF 32.0 TOLERANCE\n2 L X+1 F 100\n", "b.h"); },
               "must be followed by CYCL DEF 32.1");
  expect_error([&] { (void)parse_heidenhain(h + "1 CYCL DEF 32.0 TOLERANCE\n2 CYCL DEF 32.1 T0\n", "c.h"); },
               "tolerance T must be > 0");
}

TEST(PathControl, GeneratorsStateExactStopByDefaultAndWhatTheDialectAllows) {
  IdentificationOptions o;
  o.moves = 4;
  EXPECT_EQ(write_program(make_identification_program(o)).substr(0, 10), "N0000 G61 ");
  o.dialect = Dialect::LinuxCnc;
  EXPECT_EQ(write_program(make_identification_program(o)).substr(0, 12), "N0000 G61.1 ");
  o.path_control = PathControl::Blend;
  o.blend_tolerance_mm = 0.02;
  EXPECT_EQ(write_program(make_identification_program(o)).substr(0, 16), "N0000 G64 P0.020");
  o.dialect = Dialect::Iso;
  EXPECT_THAT([&] { (void)make_identification_program(o); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("path_control")));
  // Heidenhain: nothing by default (the thesis's Tables 4.3/4.4 as printed), Cycle 32 on request.
  IdentificationOptions h;
  h.dialect = Dialect::Heidenhain;
  h.moves = 4;
  EXPECT_THAT(write_program(make_identification_program(h)), testing::Not(HasSubstr("CYCL DEF 32")));
  h.path_control = PathControl::ExactStop;
  EXPECT_THAT([&] { (void)make_identification_program(h); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("Klartext")));
  ContourProgramOptions c;
  c.path_control = PathControl::Unstated;
  EXPECT_FALSE(make_diamond_program(c).states_path_control());
  EXPECT_EQ(modes_of(make_diamond_program({})), std::vector<PathControl>(6, PathControl::ExactStop));
}

/// Plan of two collinear moves and a shallow (0.5 deg) corner, all in one mode.
MotionPlan plan_in(const std::string& mode) {
  const Program p = parse_linuxcnc(mode + " G01 X10 Y0 F6000\nX20\nX30 Y0.0873\n", "j.ngc");
  InterpolationLimits l;
  l.corner_angle_deg = 1.0;
  return plan_motion(p, l);
}

TEST(PathControl, PlannerStopsWhereTheModeSays) {
  // Exact stop: every block ends at rest.
  const MotionPlan stop = plan_in("G61.1");
  for (const auto& m : stop.moves()) EXPECT_EQ(m.v_end, 0.0);
  // Exact path: the collinear join and the 0.5 deg corner... the corner stops, the collinear join runs on.
  const MotionPlan path = plan_in("G61");
  EXPECT_GT(path.moves()[0].v_end, 50.0);
  EXPECT_EQ(path.moves()[1].v_end, 0.0);
  // Blend (and unstated): the corner rule (1 deg): both joins run on.
  for (const char* mode : {"G64", "G64 P0.01", ""}) {
    const MotionPlan blend = plan_in(mode);
    EXPECT_GT(blend.moves()[0].v_end, 50.0) << mode;
    EXPECT_GT(blend.moves()[1].v_end, 10.0) << mode;
  }
  // A controller without look-ahead stops everywhere whatever the program says.
  InterpolationLimits simple;
  simple.exact_stop_every_block = true;
  const MotionPlan no_look_ahead = plan_motion(parse_linuxcnc("G64 G01 X10 F6000\nX20\n", "s.ngc"), simple);
  for (const auto& m : no_look_ahead.moves()) EXPECT_EQ(m.v_end, 0.0);
}

}  // namespace
}  // namespace servotwin::motion
