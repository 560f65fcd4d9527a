// Writers: layout of the thesis tables (Table 3.2 ISO, Table 4.4 Heidenhain, reproduced byte for
// byte), the number rule, and round trips through the readers (fixed programs and random ones).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <sstream>

#include "gcode_test_support.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion {
namespace {

using test::heidenhain;
using test::iso;
using ::testing::HasSubstr;

// Thesis Table 3.2 (first and last lines) in the writer's sign-column style. The table itself
// prints the first line as `X0.000` but every other positive value with the blank (`X 0.258`,
// `N2010 G01 X 0.000`); the writer is consistent.
constexpr const char* kTable32 =
    "N0000 G00 X 0.000 F12000\n"
    "N0010 G01 X 0.258\n"
    "N0020 G01 X-0.790\n"
    "N0030 G01 X-2.992\n"
    "N0040 G01 X-8.099\n"
    "N2000 G01 X-2.641\n"
    "N2010 G01 X 0.000\n";


TEST(GcodeWriter, ReproducesThesisTable44) {
  EXPECT_EQ(write_heidenhain(heidenhain(test::kThesisTable44)), test::kThesisTable44);
}

TEST(GcodeWriter, ReproducesThesisTable32) {
  WriteOptions o;
  o.sign_column = true;
  EXPECT_EQ(write_iso(iso(kTable32), o), kTable32);
  const std::string plain = write_iso(iso(kTable32));
  EXPECT_THAT(plain, HasSubstr("N0010 G01 X0.258\n"));
  EXPECT_THAT(plain, HasSubstr("N0020 G01 X-0.790\n"));
}

Program one_linear(double x) {
  Program p;
  Block b;
  b.type = BlockType::Linear;
  b.end = {x, 0.0, 0.0};
  b.axes = axis_bit(Axis::X);
  b.feed_mm_min = 100.0;
  p.blocks.push_back(b);
  return p;
}

std::string iso_line(double x, WriteOptions o = {}) {
  std::string s = write_iso(one_linear(x), o);
  return s.substr(0, s.size() - 1);
}

TEST(GcodeWriter, NumberRule) {
  // decimals (3) when exact, otherwise the shortest text that reads back to the same double.
  EXPECT_EQ(iso_line(0.258), "G01 X0.258 F100");
  EXPECT_EQ(iso_line(-0.79), "G01 X-0.790 F100");
  EXPECT_EQ(iso_line(-0.0), "G01 X0.000 F100");
  EXPECT_EQ(iso_line(1.0 / 3.0), "G01 X0.3333333333333333 F100");
  EXPECT_EQ(iso_line(1e-7), "G01 X0.0000001 F100");
  EXPECT_EQ(iso_line(123456789.5), "G01 X123456789.500 F100");
  EXPECT_EQ(iso_line(0.1 + 0.2), "G01 X0.30000000000000004 F100");
  WriteOptions one;
  one.decimals = 1;
  EXPECT_EQ(iso_line(0.5, one), "G01 X0.5 F100");
  EXPECT_EQ(iso_line(0.25, one), "G01 X0.25 F100");
  WriteOptions sign;
  sign.sign_column = true;
  EXPECT_EQ(iso_line(2.5, sign), "G01 X 2.500 F100");
  EXPECT_EQ(iso_line(-2.5, sign), "G01 X-2.500 F100");
}

TEST(GcodeWriter, NumbersReadBackBitForBit) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-12, 9);
  for (int i = 0; i < 5000; ++i) {
    double x = mantissa(rng) * std::pow(10.0, exponent(rng));
    if (std::fabs(x) > 1e9) x = std::copysign(1e9, x);
    const Program back = iso(write_iso(one_linear(x)));
    ASSERT_EQ(back.blocks.size(), 1U);
    ASSERT_EQ(back.blocks[0].end[0], x) << write_iso(one_linear(x));
    const Program hback = heidenhain(write_heidenhain(one_linear(x)));
    ASSERT_EQ(hback.blocks[0].end[0], x);
  }
}

TEST(GcodeWriter, IsoLayoutDetails) {
  Program p;
  Block comment;
  comment.comment = "setup (a) b";  // contains ')' -> written after ';'
  p.blocks.push_back(comment);
  Block empty;  // nothing to say: not written
  empty.number = 7;
  p.blocks.push_back(empty);
  Block rapid;
  rapid.type = BlockType::Rapid;
  rapid.end = {1.0, 2.0, 0.0};
  rapid.number = 5;
  rapid.m_codes = {3, 8};
  p.blocks.push_back(rapid);
  Block dwell;
  dwell.type = BlockType::Dwell;
  dwell.start = dwell.end = rapid.end;
  dwell.dwell_s = 0.5;
  p.blocks.push_back(dwell);
  WriteOptions o;
  o.iso_modal_preamble = true;
  // The preamble goes on the first line written, whatever it holds.
  EXPECT_EQ(write_iso(p, o), "G17 G21 G90 G94 ;setup (a) b\nN0005 G00 X1.000 Y2.000 M3 M8\nG04 P0.500\n");
  o.iso_number_width = 0;
  EXPECT_THAT(write_iso(p, o), HasSubstr("N5 G00"));
  const Program back = iso(write_iso(p));
  ASSERT_EQ(back.blocks.size(), 3U);
  EXPECT_EQ(back.blocks[0].comment, "setup (a) b");
}

TEST(GcodeWriter, HeidenhainNameAndLayoutDetails) {
  Program p = iso("G01 X1 F100\nG04 P2 M5 (hold)\n");
  p.name = "/tmp/dir/my part.v2.nc";
  const std::string text = write_heidenhain(p);
  EXPECT_EQ(text,
            "0 BEGIN PGM my_part_v2 MM\n"
            "1 L X+1.000 R0 F 100.000\n"
            "2 CYCL DEF 9.0 DWELL TIME\n"
            "3 CYCL DEF 9.1 DWELL 2.000 ;hold\n"
            "4 M5\n"
            "5 END PGM my_part_v2 MM\n");
  p.name.clear();
  EXPECT_THAT(write_heidenhain(p), HasSubstr("BEGIN PGM PGM MM"));
}

TEST(GcodeWriter, RejectsWhatCannotBeRead) {
  Program p = one_linear(1.0);
  p.blocks[0].feed_mm_min = 0.0;
  EXPECT_THAT(test::input_error([&] { (void)write_iso(p); }), HasSubstr("(blocks[0]): cannot write the program: feed must be in (0, 1e9]"));
  p = one_linear(std::nan(""));
  EXPECT_THROW((void)write_heidenhain(p), core::InputError);
  WriteOptions bad;
  bad.decimals = 12;
  EXPECT_THROW((void)write_iso(one_linear(1.0), bad), core::InputError);
}

// --- round trips -------------------------------------------------------------------------------

/// Same motion: types, start/end exactly, dwell, feeds of feed moves, arc plane and centre (to
/// rounding), M codes in order. Block numbers, planes of non-arcs and rapid feeds do not survive
/// a change of dialect.
void expect_same_motion(const Program& a, const Program& b) {
  std::vector<const Block*> ma, mb;
  std::vector<int> ca, cb;
  for (const Block& x : a.blocks) {
    if (x.type != BlockType::None) ma.push_back(&x);
    ca.insert(ca.end(), x.m_codes.begin(), x.m_codes.end());
  }
  for (const Block& x : b.blocks) {
    if (x.type != BlockType::None) mb.push_back(&x);
    cb.insert(cb.end(), x.m_codes.begin(), x.m_codes.end());
  }
  EXPECT_EQ(ca, cb);
  ASSERT_EQ(ma.size(), mb.size());
  for (std::size_t i = 0; i < ma.size(); ++i) {
    const Block& x = *ma[i];
    const Block& y = *mb[i];
    EXPECT_EQ(x.type, y.type) << i;
    EXPECT_EQ(x.start, y.start) << i;
    EXPECT_EQ(x.end, y.end) << i;
    EXPECT_EQ(x.dwell_s, y.dwell_s) << i;
    if (x.type != BlockType::Rapid) {
      EXPECT_EQ(x.feed_mm_min, y.feed_mm_min) << i;
    }
    if (test::is_arc(x.type)) {
      EXPECT_EQ(x.plane, y.plane) << i;
      for (std::size_t k = 0; k < kAxisCount; ++k) EXPECT_NEAR(x.center[k], y.center[k], 1e-9) << i;
    }
  }
}

constexpr const char* kIsoFeatures =
    "(all supported words)\n"
    "N10 G17 G21 G90 G94 G00 X0 Y0 Z5 M3 ; start\n"
    "N20 G01 Z0 F300\n"
    "N30 G01 X10 Y0 F1200\n"
    "N40 G02 X20 Y10 I10 J0\n"
    "N50 G03 X10 Y20 R10\n"
    "N60 G03 X10 Y20 I-5 J-5\n"
    "N70 G02 X0 Y10 R-10\n"
    "N80 G18 G02 X5 Z-5 I5 K0\n"
    "N90 G19 G03 Y5 Z0 J0 K5\n"
    "N100 G17 G91 G01 X1 Y1 Z-1\n"
    "N110 G90 G04 P0.5\n"
    "N130 G20 G01 X1 Y1 F10\n"
    "N140 G21 G90.1 G02 X50.4 Y0.4 I25.4 J0.4\n"
    "N150 G91.1 G03 X45.4 Y5.4 Z10 R5\n"
    "N155 G00 X0.1 Y0.2 F700\n"
    "N160 M5 M30\n";

TEST(GcodeWriter, IsoRoundTripKeepsEveryBlock) {
  const Program p = iso(kIsoFeatures);
  const Program back = iso(write_iso(p));
  // Everything survives, including block numbers, planes, rapid feeds and comments.
  test::expect_same_blocks(p, back, true, 1e-12);
  EXPECT_EQ(write_iso(back), write_iso(p));
}

TEST(GcodeWriter, HeidenhainRoundTripKeepsEveryBlockButNumbers) {
  const std::string text = test::read_text(std::string(SERVOTWIN_TEST_DATA_DIR) + "/../../fuzz/corpus/gcode/heidenhain_features.h");
  const Program p = heidenhain(text);
  const Program back = heidenhain(write_heidenhain(p));
  test::expect_same_blocks(p, back, false, 0.0);  // CC is absolute: centres exact
  EXPECT_EQ(write_heidenhain(back), write_heidenhain(p));
}

TEST(GcodeWriter, CrossDialectRoundTrips) {
  const Program from_iso = iso(kIsoFeatures);
  expect_same_motion(from_iso, heidenhain(write_heidenhain(from_iso)));
  const Program from_h = heidenhain(test::kThesisTable44);
  const Program via_iso = iso(write_iso(from_h));
  expect_same_motion(from_h, via_iso);
  // Heidenhain statements become ISO comments.
  EXPECT_EQ(via_iso.blocks[3].comment, "TOOL CALL 0 Z");
}

/// Random programs: lines, rapids, arcs in all planes by centre or radius (helical too), dwells,
/// M codes, incremental and inch sections. Arc end points are rounded to 1 um, so centres close
/// within the tolerance (radius error < 0.0008 mm).
std::string random_program(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> coord(-200.0, 200.0);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
  std::uniform_real_distribution<double> radius(0.5, 50.0);
  std::uniform_int_distribution<int> kind(0, 9);
  const auto fmt = [](double v) {
    std::ostringstream s;
    s.precision(3);
    s << std::fixed << v;
    return s.str();
  };
  std::ostringstream out;
  Point at{};
  out << "G21 G90 G01 X0 Y0 Z0 F1000\n";
  for (int i = 0; i < 40; ++i) {
    const int k = kind(rng);
    if (k <= 2) {
      Point to{std::round(coord(rng) * 1000) / 1000, std::round(coord(rng) * 1000) / 1000, at[2]};
      out << "N" << i * 10 << (k == 0 ? " G00" : " G01") << " X" << fmt(to[0]) << " Y" << fmt(to[1]);
      if (k == 2) out << " F" << 100 + 10 * i;
      out << "\n";
      at = to;
    } else if (k <= 6) {
      static const char* const kPlanes[] = {"G17", "G18", "G19"};
      const int plane = k % 3;
      const std::size_t u = plane == 0 ? 0 : plane == 1 ? 2 : 1;
      const std::size_t v = plane == 0 ? 1 : plane == 1 ? 0 : 2;
      const std::size_t n = 3 - u - v;
      const double r = radius(rng);
      const double a0 = angle(rng);
      // Centre such that the current point is on the circle, end point at another angle.
      const double cu = at[u] - r * std::cos(a0);
      const double cv = at[v] - r * std::sin(a0);
      const double a1 = angle(rng);
      Point to = at;
      to[u] = std::round((cu + r * std::cos(a1)) * 1000) / 1000;
      to[v] = std::round((cv + r * std::sin(a1)) * 1000) / 1000;
      if (k == 6) to[n] = std::round((at[n] + 3.0) * 1000) / 1000;
      const char* g = (i % 2 == 0) ? "G02" : "G03";
      const char* letters = "XYZ";
      const char* offsets = "IJK";
      out << kPlanes[plane] << " " << g << " " << letters[u] << fmt(to[u]) << " " << letters[v] << fmt(to[v]);
      if (k == 6) out << " " << letters[n] << fmt(to[n]);
      if (k == 5 && std::hypot(to[u] - at[u], to[v] - at[v]) > 0.01) {
        // By radius: the sign picks which of the two circles through both points.
        out << " R" << (i % 3 == 0 ? "-" : "") << fmt(r);
      } else {
        out << " " << offsets[u] << fmt(cu - at[u]) << " " << offsets[v] << fmt(cv - at[v]);
      }
      out << "\n";
      at = to;  // where the reader will be (R arcs may pick the other circle: same end point)
    } else if (k == 7) {
      out << "G04 P" << fmt(0.001 * static_cast<double>(rng() % 5000)) << " M" << rng() % 100 << "\n";
    } else if (k == 8) {
      out << "G91 G01 X" << fmt(1.5) << " Z" << fmt(-0.25) << " (incremental)\nG90\n";
      at[0] += 1.5;
      at[2] -= 0.25;
    } else {
      const double inches = std::round(coord(rng) / 25.4 * 1000) / 1000;
      out << "G20 G01 X" << fmt(inches) << "\nG21\n";
      at[0] = inches * 25.4;  // what the reader computes
    }
  }
  out << "M30\n";
  return out.str();
}

/// The program without None blocks that carry nothing (modal words only): writers skip those.
Program without_empty_none(Program p) {
  std::erase_if(p.blocks, [](const Block& b) {
    return b.type == BlockType::None && b.m_codes.empty() && b.comment.empty() && b.statement.empty();
  });
  return p;
}

TEST(GcodeWriter, RandomProgramsRoundTripInBothDialects) {
  std::mt19937_64 rng(2024);
  for (int trial = 0; trial < 150; ++trial) {
    const std::string text = random_program(rng);
    Program p;
    ASSERT_NO_THROW(p = iso(text)) << text;
    const Program same = iso(write_iso(p));
    test::expect_same_blocks(without_empty_none(p), same, true, 1e-9);
    const Program other = heidenhain(write_heidenhain(p));
    expect_same_motion(p, other);
    expect_same_motion(p, iso(write_iso(other)));
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "program:\n" << text;
      return;
    }
  }
}

}  // namespace
}  // namespace servotwin::motion
