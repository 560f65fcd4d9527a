#pragma once
// Helpers shared by the G-code and identification-program tests.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion::test {

// Thesis Table 4.4, blocks 0..13 as printed, then the program end (blocks 104..108 renumbered);
// shared by the reader and writer tests.
inline constexpr const char* kThesisTable44 =
    "0 BEGIN PGM RAPIDIDENT MM\n"
    ";Rapid Identification on TNC 430 5 axis machine\n"
    "1 BLK FORM 0.1 Z X-50.000 Y-50.000 Z-50.000\n"
    "2 BLK FORM 0.2 X+50.000 Y+50.000 Z+50.000\n"
    "3 TOOL CALL 0 Z\n"
    "4 L Z+200.000 F MAX\n"
    "5 L X+0.000 Y+0.000 R0 F MAX M3\n"
    "6 L Z+0.000 F MAX\n"
    "7 L X-9.375 F 15000.000\n"
    "8 L X+9.375\n"
    "9 L X-5.280\n"
    "10 L X-5.552\n"
    "11 L X+0.158\n"
    "12 L X+6.539\n"
    "13 L X-1.538\n"
    "14 L X-9.375\n"
    "15 L X+9.375\n"
    "16 L X+0.000\n"
    "17 M30\n"
    "18 END PGM RAPIDIDENT MM\n";

/// Message of the core::InputError thrown by `f`, or "" when it does not throw one (other
/// exceptions propagate and fail the test).
inline std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  return {};
}

inline Program iso(std::string_view text, bool lenient = false) {
  ParseOptions o;
  o.lenient = lenient;
  return parse_iso(text, "t.nc", o);
}

inline Program heidenhain(std::string_view text, bool lenient = false) {
  ParseOptions o;
  o.lenient = lenient;
  return parse_heidenhain(text, "t.h", o);
}

inline std::string iso_error(std::string_view text) {
  return input_error([&] { (void)iso(text); });
}

inline std::string heidenhain_error(std::string_view text) {
  return input_error([&] { (void)heidenhain(text); });
}

/// Wraps path blocks into a minimal Heidenhain program (BEGIN on line 1, so the first given line
/// is line 2).
inline std::string hh(std::string_view body) {
  return "0 BEGIN PGM T MM\n" + std::string(body) + "99 END PGM T MM\n";
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline bool is_arc(BlockType t) { return t == BlockType::ArcCw || t == BlockType::ArcCcw; }

/// Field-by-field equality of two blocks; centres to `centre_tol` (ISO writes incremental I/J/K).
inline ::testing::AssertionResult same_block(const Block& a, const Block& b, bool compare_numbers = true,
                                             double centre_tol = 0.0) {
  std::ostringstream why;
  if (a.type != b.type) why << "type " << static_cast<int>(a.type) << " vs " << static_cast<int>(b.type) << "; ";
  if (a.start != b.start) why << "start; ";
  if (a.end != b.end) why << "end; ";
  if (a.plane != b.plane) why << "plane; ";
  if (a.feed_mm_min != b.feed_mm_min) why << "feed " << a.feed_mm_min << " vs " << b.feed_mm_min << "; ";
  if (a.dwell_s != b.dwell_s) why << "dwell; ";
  if (a.axes != b.axes) why << "axes " << int{a.axes} << " vs " << int{b.axes} << "; ";
  if (a.m_codes != b.m_codes) why << "m codes; ";
  if (compare_numbers && a.number != b.number) why << "number " << a.number << " vs " << b.number << "; ";
  if (a.comment != b.comment) why << "comment '" << a.comment << "' vs '" << b.comment << "'; ";
  if (a.statement != b.statement) why << "statement '" << a.statement << "' vs '" << b.statement << "'; ";
  if (is_arc(a.type)) {
    for (std::size_t i = 0; i < kAxisCount; ++i)
      if (!(std::fabs(a.center[i] - b.center[i]) <= centre_tol)) why << "centre[" << i << "] " << a.center[i] << " vs " << b.center[i] << "; ";
  }
  if (why.str().empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << why.str();
}

/// All blocks equal (see same_block).
inline void expect_same_blocks(const Program& a, const Program& b, bool compare_numbers = true, double centre_tol = 0.0) {
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  for (std::size_t i = 0; i < a.blocks.size(); ++i)
    EXPECT_TRUE(same_block(a.blocks[i], b.blocks[i], compare_numbers, centre_tol)) << "block " << i;
}

}  // namespace servotwin::motion::test
