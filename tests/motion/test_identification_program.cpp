// Identification-program generator. References:
//  * tests/data/motion/identification_reference.json from tools/reference/
//    identification_program_reference.py: an independent Python implementation of MT19937-64
//    (checked against the C++ standard's mandated value) and of the documented draw rule and
//    shapes, giving the expected target of every move, and the chi-square / KS statistics of
//    10000 targets with scipy's critical values;
//  * golden programs tests/data/motion/identification_*.{nc,h} written once by this code and
//    reviewed against the layout of thesis Tables 3.2, 4.3 and 4.4.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "gcode_test_support.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/identification_program.hpp"

namespace servotwin::motion {
namespace {

using ::testing::HasSubstr;

const std::string kData = std::string(SERVOTWIN_TEST_DATA_DIR) + "/motion/";

nlohmann::json reference() {
  std::ifstream in(kData + "identification_reference.json");
  return nlohmann::json::parse(in);
}

IdentificationSet set_of(const std::string& s) {
  return s == "low" ? IdentificationSet::Low : s == "high" ? IdentificationSet::High : IdentificationSet::Standard;
}

std::vector<Axis> axes_of(const std::string& s) {
  std::vector<Axis> axes;
  for (const char c : s) axes.push_back(static_cast<Axis>(c - 'X'));
  return axes;
}

/// The linear moves of a generated program.
std::vector<const Block*> moves_of(const Program& p) {
  std::vector<const Block*> out;
  for (const Block& b : p.blocks)
    if (b.type == BlockType::Linear) out.push_back(&b);
  return out;
}

TEST(IdentificationProgram, DefaultsFollowTheThesis) {
  const IdentificationOptions s = identification_defaults(IdentificationSet::Standard);
  EXPECT_EQ(s.moves, 200U);  // Table 3.2: 200 random linear movements ...
  EXPECT_EQ(s.range_mm, 10.0);  // ... within +-10 mm ...
  EXPECT_EQ(s.feed_mm_min, 12000.0);  // ... at 200 mm/s (F12000 in the table)
  const IdentificationOptions low = identification_defaults(IdentificationSet::Low);
  EXPECT_EQ(low.range_mm, 0.03);  // section 4.3.3: travel distances up to 30 um
  EXPECT_EQ(low.feed_mm_min, 15000.0);  // 250 mm/s, `F 15000.000` in Table 4.3
  EXPECT_EQ(low.moves, 200U);
  const IdentificationOptions high = identification_defaults(IdentificationSet::High);
  EXPECT_EQ(high.range_mm, 10.0);
  EXPECT_EQ(high.feed_mm_min, 15000.0);
  EXPECT_EQ(high.moves, 100U);
  EXPECT_EQ(high.set, IdentificationSet::High);
}

TEST(IdentificationProgram, TargetsMatchIndependentReference) {
  const nlohmann::json ref = reference();
  ASSERT_GE(ref["cases"].size(), 5U);
  for (const auto& c : ref["cases"]) {
    SCOPED_TRACE(c["name"].get<std::string>());
    IdentificationOptions o = identification_defaults(set_of(c["set"]));
    o.axes = axes_of(c["axes"]);
    o.moves = c["moves"];
    o.seed = std::stoull(c["seed"].get<std::string>());
    o.range_mm = c["range_mm"];
    o.decimals = c["decimals"];
    const double scale = std::pow(10.0, o.decimals);
    const Program p = make_identification_program(o);
    const auto moves = moves_of(p);
    const auto& expected = c["offsets"];
    ASSERT_EQ(moves.size(), expected.size());
    for (std::size_t i = 0; i < moves.size(); ++i) {
      for (std::size_t j = 0; j < o.axes.size(); ++j) {
        const double want = static_cast<double>(expected[i][j].get<long long>()) / scale;
        EXPECT_EQ(moves[i]->end[static_cast<std::size_t>(o.axes[j])], want) << "move " << i << " axis " << j;
      }
    }
  }
}

Program generate(IdentificationSet set, const std::string& axes, std::size_t moves, std::uint64_t seed, Dialect d) {
  IdentificationOptions o = identification_defaults(set);
  o.axes = axes_of(axes);
  o.moves = moves;
  o.seed = seed;
  o.dialect = d;
  return make_identification_program(o);
}

TEST(IdentificationProgram, GoldenProgramsInTheThesisLayout) {
  WriteOptions table32;
  table32.sign_column = true;
  // Table 3.2 as printed states no path-control mode; servotwin's default adds G61 (below).
  Program table = generate(IdentificationSet::Standard, "X", 12, 7, Dialect::Iso);
  for (Block& b : table.blocks) b.path_control = PathControl::Unstated;
  EXPECT_EQ(write_program(table, table32), test::read_text(kData + "identification_standard_x_seed7.nc"));
  EXPECT_EQ(write_program(generate(IdentificationSet::Low, "X", 12, 7, Dialect::Heidenhain)),
            test::read_text(kData + "identification_low_x_seed7.h"));
  EXPECT_EQ(write_program(generate(IdentificationSet::High, "XY", 8, 42, Dialect::Heidenhain)),
            test::read_text(kData + "identification_high_xy_seed42.h"));
}

TEST(IdentificationProgram, StandardShapeIsoTable32) {
  const Program p = generate(IdentificationSet::Standard, "X", 200, 3, Dialect::Iso);
  ASSERT_EQ(p.blocks.size(), 203U);  // G00, 200 random moves, back to the centre, M30
  const Block& first = p.blocks.front();
  EXPECT_EQ(first.type, BlockType::Rapid);
  EXPECT_EQ(first.number, 0);
  EXPECT_EQ(first.feed_mm_min, 12000.0);
  for (std::size_t i = 1; i <= 201; ++i) {
    EXPECT_EQ(p.blocks[i].type, BlockType::Linear);
    EXPECT_EQ(p.blocks[i].number, static_cast<long>(10 * i));
  }
  EXPECT_EQ(p.blocks[201].end[0], 0.0) << "last move back to the centre (N2010 in Table 3.2)";
  EXPECT_EQ(p.blocks[201].number, 2010);
  EXPECT_EQ(p.blocks[202].m_codes, std::vector<int>{30});
  const std::string text = write_iso(p);
  // Table 3.2's first block with the exact-stop mode stated (a controller's default, e.g. LinuxCNC's
  // blending, must not decide how the identification moves end).
  EXPECT_EQ(text.substr(0, text.find('\n')), "N0000 G61 G00 X0.000 F12000");
  EXPECT_EQ(std::count(text.begin(), text.end(), 'F'), 1) << "F only on the first block";
}

TEST(IdentificationProgram, HeidenhainFramingSelectedAxesOnly) {
  // X only: no Y or Z anywhere in the motion blocks (the virtual machines have X and Y only).
  std::string text = write_program(generate(IdentificationSet::High, "X", 20, 1, Dialect::Heidenhain));
  EXPECT_THAT(text, HasSubstr("3 TOOL CALL 0 Z\n4 L X+0.000 R0 F MAX M3\n5 L X-10.000 F 15000.000\n6 L X+10.000\n"));
  const std::string moves_part = text.substr(text.find("4 L"));
  EXPECT_EQ(moves_part.find(" Y"), std::string::npos);
  EXPECT_EQ(moves_part.find(" Z"), std::string::npos);
  EXPECT_THAT(text, HasSubstr("29 L X+0.000\n30 M30\n31 END PGM RAPIDIDENT MM\n"));
  // Z selected: the plane axes first (R0 F MAX M3), then the tool axis, as blocks 5/6 of Table 4.4.
  text = write_program(generate(IdentificationSet::Standard, "XYZ", 3, 1, Dialect::Heidenhain));
  EXPECT_THAT(text, HasSubstr("4 L X+0.000 Y+0.000 R0 F MAX M3\n5 L Z+0.000 F MAX\n6 L X"));
  text = write_program(generate(IdentificationSet::Standard, "Z", 3, 1, Dialect::Heidenhain));
  EXPECT_THAT(text, HasSubstr("4 L Z+0.000 F MAX M3\n5 L Z"));
}

TEST(IdentificationProgram, ShapesOfLowAndHigh) {
  const Program low = generate(IdentificationSet::Low, "X", 50, 9, Dialect::Iso);
  auto m = moves_of(low);
  ASSERT_EQ(m.size(), 53U);  // sweep -, sweep +, 50 random, centre
  EXPECT_EQ(m[0]->end[0], -0.03);
  EXPECT_EQ(m[1]->end[0], 0.03);
  EXPECT_EQ(m.back()->end[0], 0.0);
  const Program high = generate(IdentificationSet::High, "X", 100, 9, Dialect::Iso);
  m = moves_of(high);
  ASSERT_EQ(m.size(), 105U);  // sweep, 100 random, sweep, centre
  EXPECT_EQ(m[0]->end[0], -10.0);
  EXPECT_EQ(m[1]->end[0], 10.0);
  EXPECT_EQ(m[102]->end[0], -10.0);
  EXPECT_EQ(m[103]->end[0], 10.0);
  EXPECT_EQ(m[104]->end[0], 0.0);
  // Second half of the random moves mirrors the first (Table 4.4, blocks 9-11 vs 103-101).
  for (std::size_t j = 0; j < 50; ++j) EXPECT_EQ(m[2 + 50 + j]->end[0], -m[2 + 49 - j]->end[0]) << j;
}

struct PropertyCase {
  IdentificationSet set;
  const char* axes;
  std::size_t moves;
  double range;
  Point center;
  int decimals;
};

TEST(IdentificationProgram, EveryMoveMovesAndStaysInRange) {
  const PropertyCase cases[] = {
      {IdentificationSet::Standard, "X", 2000, 10.0, {}, 3},
      {IdentificationSet::Standard, "XY", 500, 0.001, {5.0, -7.5, 0.0}, 3},  // 3 grid values: many redraws
      {IdentificationSet::Low, "Y", 1000, 0.03, {0.0, 100.0, 0.0}, 3},
      {IdentificationSet::High, "XYZ", 301, 25.0, {-1.0, 2.0, 3.0}, 3},
      {IdentificationSet::High, "X", 2, 10.0, {}, 3},
      {IdentificationSet::Standard, "Z", 300, 0.5, {0.0, 0.0, 12.3456}, 4},
  };
  for (const PropertyCase& c : cases) {
    SCOPED_TRACE(std::string(c.axes) + " moves " + std::to_string(c.moves));
    IdentificationOptions o = identification_defaults(c.set);
    o.axes = axes_of(c.axes);
    o.moves = c.moves;
    o.range_mm = c.range;
    o.center = c.center;
    o.decimals = c.decimals;
    o.seed = 77;
    const Program p = make_identification_program(o);
    const double step = std::pow(10.0, -c.decimals);
    std::uint8_t mask = 0;
    for (const Axis a : o.axes) mask = static_cast<std::uint8_t>(mask | axis_bit(a));
    for (const Block* b : moves_of(p)) {
      for (std::size_t a = 0; a < kAxisCount; ++a) {
        if (mask & axis_bit(static_cast<Axis>(a))) {
          ASSERT_NE(b->end[a], b->start[a]) << "line " << b->number;
          ASSERT_GE(b->end[a], c.center[a] - c.range - 1e-12);
          ASSERT_LE(b->end[a], c.center[a] + c.range + 1e-12);
          const double steps = b->end[a] / step;
          ASSERT_NEAR(steps, std::round(steps), 1e-6) << "targets on the output grid";
        } else {
          ASSERT_EQ(b->end[a], 0.0) << "axes not selected never move";
        }
      }
    }
    EXPECT_EQ(p.used_axes(), mask);
  }
}

TEST(IdentificationProgram, TargetsAreUniform) {
  const nlohmann::json u = reference()["uniformity"];
  IdentificationOptions o = identification_defaults(IdentificationSet::Standard);
  o.moves = u["moves"];
  o.seed = u["seed"];
  o.range_mm = u["range_mm"];
  const Program p = make_identification_program(o);
  auto moves = moves_of(p);
  moves.pop_back();  // the final return to the centre is not drawn
  const std::size_t n = moves.size();
  ASSERT_EQ(n, 10000U);
  const int bins = u["bins"];
  std::vector<int> counts(static_cast<std::size_t>(bins), 0);
  std::vector<double> x;
  for (const Block* b : moves) {
    const double v = b->end[0];
    x.push_back(v);
    const int bin = std::min(static_cast<int>((v + o.range_mm) / (2.0 * o.range_mm) * bins), bins - 1);
    ++counts[static_cast<std::size_t>(bin)];
  }
  const double expected = static_cast<double>(n) / bins;
  double chi2 = 0.0;
  for (const int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  // The same counts and statistic as the Python reference (same draws), and below scipy's
  // chi2.ppf(0.999, bins - 1).
  EXPECT_EQ(counts, u["counts"].get<std::vector<int>>());
  EXPECT_NEAR(chi2, u["chi2"].get<double>(), 1e-9);
  EXPECT_LT(chi2, u["chi2_critical_0999"].get<double>());
  // Kolmogorov-Smirnov against U(-range, range): D = max |F_n - F|.
  std::sort(x.begin(), x.end());
  double d = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double f = (x[i] + o.range_mm) / (2.0 * o.range_mm);
    d = std::max({d, static_cast<double>(i + 1) / static_cast<double>(n) - f, f - static_cast<double>(i) / static_cast<double>(n)});
  }
  EXPECT_NEAR(d, u["ks_statistic"].get<double>(), 1e-12);
  EXPECT_LT(d, u["ks_critical_0999"].get<double>());
}

TEST(IdentificationProgram, DeterministicPerSeed) {
  const auto text = [](std::uint64_t seed) {
    return write_program(generate(IdentificationSet::High, "XY", 40, seed, Dialect::Heidenhain));
  };
  EXPECT_EQ(text(5), text(5));
  EXPECT_NE(text(5), text(6));
}

TEST(IdentificationProgram, RoundTripsThroughTheReaders) {
  for (const Dialect d : {Dialect::Iso, Dialect::Heidenhain}) {
    for (const IdentificationSet set : {IdentificationSet::Standard, IdentificationSet::Low, IdentificationSet::High}) {
      const Program p = generate(set, "XY", 30, 11, d);
      const std::string text = write_program(p);
      const Program back = parse_program(text, "id");
      EXPECT_EQ(back.dialect, d);
      test::expect_same_blocks(p, back, true, 0.0);
      if (d == Dialect::Heidenhain) {
        EXPECT_EQ(back.name, "RAPIDIDENT");
      }
    }
  }
}

TEST(IdentificationProgram, RejectsBadOptions) {
  const auto error = [](const std::function<void(IdentificationOptions&)>& change) {
    IdentificationOptions o;
    change(o);
    return test::input_error([&] { (void)make_identification_program(o); });
  };
  EXPECT_THAT(error([](auto& o) { o.axes.clear(); }), HasSubstr("(axes): select at least one axis"));
  EXPECT_THAT(error([](auto& o) { o.axes = {Axis::X, Axis::X}; }), HasSubstr("axis X selected twice"));
  EXPECT_THAT(error([](auto& o) { o.moves = 0; }), HasSubstr("(moves)"));
  EXPECT_THAT(error([](auto& o) { o.range_mm = 0.0; }), HasSubstr("(range_mm): range must be at least one output step"));
  EXPECT_THAT(error([](auto& o) { o.range_mm = -1.0; }), HasSubstr("(range_mm)"));
  EXPECT_THAT(error([](auto& o) { o.range_mm = std::nan(""); }), HasSubstr("(range_mm)"));
  EXPECT_THAT(error([](auto& o) { o.range_mm = 0.0004; }), HasSubstr("at least one output step (0.001 mm)"));
  EXPECT_THAT(error([](auto& o) { o.range_mm = 2e9; }), HasSubstr("range too large"));
  EXPECT_THAT(error([](auto& o) { o.feed_mm_min = 0.0; }), HasSubstr("(feed_mm_min)"));
  EXPECT_THAT(error([](auto& o) { o.decimals = 10; }), HasSubstr("(decimals)"));
  EXPECT_THAT(error([](auto& o) { o.center[0] = 0.0005; }), HasSubstr("centre X = 0.0005 mm is not a multiple of the output step"));
  EXPECT_THAT(error([](auto& o) { o.center[1] = HUGE_VAL; }), HasSubstr("(center)"));
  EXPECT_EQ(error([](auto& o) { o.center[1] = 0.0005; }), "") << "Y is not selected: only the BLK FORM uses it";
  EXPECT_THAT(error([](auto& o) { o.name = "MY PROG"; }), HasSubstr("(name)"));
  // A range off the grid is cut to whole steps (never beyond the range).
  IdentificationOptions o;
  o.range_mm = 0.0025;
  o.moves = 100;
  const Program cut = make_identification_program(o);
  for (const Block* b : moves_of(cut)) EXPECT_LE(std::fabs(b->end[0]), 0.002 + 1e-15);
}

}  // namespace
}  // namespace servotwin::motion
