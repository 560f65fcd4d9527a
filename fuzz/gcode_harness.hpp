#pragma once
// Body of the G-code fuzzer, shared by fuzz/fuzz_gcode.cpp (clang + libFuzzer) and the replay test
// tests/motion/test_gcode_fuzz_replay.cpp (any compiler), so every corpus and regression input is
// checked in CI without clang.
//
// For one input it runs both readers, strict and lenient, and checks:
//  * only core::InputError escapes, and it names the source, a line and a column;
//  * strict success implies lenient success with the same blocks and no warnings, and lenient
//    success without warnings implies strict success;
//  * every accepted program is consistent: blocks chain (start = previous end), coordinates
//    finite and within +-1e9 mm, feeds > 0 on feed moves, arcs close within the tolerance;
//  * write_iso, write_linuxcnc and write_heidenhain produce text that the strict reader of that
//    dialect accepts, giving back the same motion (types, end points bit for bit, arc centres to
//    rounding, planes of arcs, feeds, dwell times) and the same M codes in order; through the
//    LinuxCNC dialect, which can state every mode, an ISO or LinuxCNC program keeps its
//    path-control modes and tolerances too.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::fuzz {

namespace gcode_detail {

using motion::Block;
using motion::BlockType;
using motion::Dialect;
using motion::Program;

inline constexpr std::string_view kSource = "fuzz.nc";

struct Outcome {
  std::optional<Program> program;
  std::string error;    ///< InputError message when rejected
  std::string failure;  ///< violated invariant (non-InputError exception, bad location)
};

inline Outcome parse(std::string_view text, Dialect dialect, bool lenient) {
  Outcome out;
  motion::ParseOptions options;
  options.lenient = lenient;
  try {
    out.program = motion::parse_program(text, kSource, options, dialect);
  } catch (const core::InputError& e) {
    out.error = e.what();
    const core::SourceLocation& w = e.where();
    if (w.file != kSource || w.line == 0 || w.column == 0)
      out.failure = "InputError without file:line:column: " + out.error;
  } catch (const std::exception& e) {
    out.failure = std::string("unexpected exception: ") + e.what();
  } catch (...) {
    out.failure = "unexpected non-standard exception";
  }
  return out;
}

inline bool is_arc(BlockType t) { return t == BlockType::ArcCw || t == BlockType::ArcCcw; }

inline bool finite_within(const motion::Point& p) {
  return std::all_of(p.begin(), p.end(), [](double v) { return std::isfinite(v) && std::fabs(v) <= 1e9; });
}

inline double max_abs(const motion::Point& a, const motion::Point& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < motion::kAxisCount; ++i) m = std::max({m, std::fabs(a[i]), std::fabs(b[i])});
  return m;
}

/// In-plane axes of an arc.
inline std::pair<std::size_t, std::size_t> plane_uv(motion::Plane p) {
  switch (p) {
    case motion::Plane::XY: return {0, 1};
    case motion::Plane::ZX: return {2, 0};
    case motion::Plane::YZ: return {1, 2};
  }
  return {0, 1};
}

inline std::string check_consistent(const Program& p, std::string_view what) {
  const std::string where = std::string(what) + ": ";
  motion::Point at = p.start;
  const motion::ParseOptions defaults;
  for (std::size_t i = 0; i < p.blocks.size(); ++i) {
    const Block& b = p.blocks[i];
    const std::string id = where + "block " + std::to_string(i) + ": ";
    if (b.start != at) return id + "does not start where the previous block ended";
    if (!finite_within(b.start) || !finite_within(b.end) || !finite_within(b.center)) return id + "coordinate not finite or beyond 1e9";
    if (b.type == BlockType::None && b.end != b.start) return id + "None block moves";
    if (b.type == BlockType::Dwell && (b.end != b.start || !(b.dwell_s >= 0.0))) return id + "bad dwell";
    if ((b.type == BlockType::Linear || is_arc(b.type)) && !(b.feed_mm_min > 0.0 && b.feed_mm_min <= 1e9))
      return id + "feed move without a positive feed";
    if (is_arc(b.type)) {
      const auto [u, v] = plane_uv(b.plane);
      const double rs = std::hypot(b.start[u] - b.center[u], b.start[v] - b.center[v]);
      const double re = std::hypot(b.end[u] - b.center[u], b.end[v] - b.center[v]);
      const double slack = 64.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::max(max_abs(b.start, b.end), max_abs(b.center, b.center)));
      const double tol = std::max(defaults.arc_tolerance_abs_mm, defaults.arc_tolerance_rel * std::max(rs, re)) + slack;
      if (!(rs > 0.0) || std::fabs(rs - re) > tol) return id + "arc does not close";
    }
    at = b.end;
  }
  return {};
}

inline bool same_point(const motion::Point& a, const motion::Point& b) { return a == b; }

/// Motion and M codes equal (see the file comment). Arc centres are compared to a few ulps: ISO
/// writes them as incremental offsets, which cannot always reproduce the double exactly.
inline std::string compare_motion(const Program& a, const Program& b, std::string_view what) {
  const std::string where = std::string(what) + ": ";
  std::vector<const Block*> ma, mb;
  std::vector<int> codes_a, codes_b;
  for (const Block& x : a.blocks) {
    if (x.type != BlockType::None) ma.push_back(&x);
    codes_a.insert(codes_a.end(), x.m_codes.begin(), x.m_codes.end());
  }
  for (const Block& x : b.blocks) {
    if (x.type != BlockType::None) mb.push_back(&x);
    codes_b.insert(codes_b.end(), x.m_codes.begin(), x.m_codes.end());
  }
  if (codes_a != codes_b) return where + "M codes differ";
  if (ma.size() != mb.size())
    return where + "motion block count " + std::to_string(ma.size()) + " became " + std::to_string(mb.size());
  for (std::size_t i = 0; i < ma.size(); ++i) {
    const Block& x = *ma[i];
    const Block& y = *mb[i];
    const std::string id = where + "motion block " + std::to_string(i) + " (line " + std::to_string(x.line) + "): ";
    if (x.type != y.type) return id + "type differs";
    if (!same_point(x.start, y.start) || !same_point(x.end, y.end)) return id + "end point differs";
    if (x.type == BlockType::Dwell && x.dwell_s != y.dwell_s) return id + "dwell differs";
    if ((x.type == BlockType::Linear || is_arc(x.type)) && x.feed_mm_min != y.feed_mm_min) return id + "feed differs";
    if (is_arc(x.type)) {
      if (x.plane != y.plane) return id + "arc plane differs";
      const auto [u, v] = plane_uv(x.plane);
      const double tol = 16.0 * std::numeric_limits<double>::epsilon() * (1.0 + max_abs(x.start, x.center));
      if (std::fabs(x.center[u] - y.center[u]) > tol || std::fabs(x.center[v] - y.center[v]) > tol)
        return id + "arc centre differs";
    }
  }
  return {};
}

/// Path-control modes and tolerances of the motion blocks equal.
inline std::string compare_modes(const Program& a, const Program& b, std::string_view what) {
  std::vector<const Block*> ma, mb;
  for (const Block& x : a.blocks)
    if (x.type != BlockType::None && x.type != BlockType::Dwell) ma.push_back(&x);
  for (const Block& x : b.blocks)
    if (x.type != BlockType::None && x.type != BlockType::Dwell) mb.push_back(&x);
  if (ma.size() != mb.size()) return std::string(what) + ": motion block count differs";
  for (std::size_t i = 0; i < ma.size(); ++i) {
    if (ma[i]->path_control != mb[i]->path_control || ma[i]->blend_tolerance_mm != mb[i]->blend_tolerance_mm ||
        ma[i]->cam_tolerance_mm != mb[i]->cam_tolerance_mm)
      return std::string(what) + ": path control of motion block " + std::to_string(i) + " differs";
  }
  return {};
}

inline std::string check_round_trips(const Program& p, std::string_view what) {
  for (const Dialect out : {Dialect::Iso, Dialect::LinuxCnc, Dialect::Heidenhain}) {
    const char* name = out == Dialect::Iso ? "write_iso" : out == Dialect::LinuxCnc ? "write_linuxcnc" : "write_heidenhain";
    std::string text;
    try {
      Program written = p;
      written.dialect = out;
      text = motion::write_program(written);
    } catch (const std::exception& e) {
      return std::string(what) + ": " + name + " threw: " + e.what();
    }
    Outcome back = parse(text, out, false);
    if (!back.program)
      return std::string(what) + ": " + name + " output rejected by the strict reader: " + back.error + back.failure +
             "\n--- written text ---\n" + text;
    std::string problem = compare_motion(p, *back.program, std::string(what) + " via " + name);
    if (problem.empty() && out == Dialect::LinuxCnc && p.dialect != Dialect::Heidenhain)
      problem = compare_modes(p, *back.program, std::string(what) + " via " + name);
    if (!problem.empty()) return problem + "\n--- written text ---\n" + text;
  }
  return {};
}

}  // namespace gcode_detail

/// Checks one fuzz input; returns a description of the first violated invariant, or nothing.
inline std::optional<std::string> check_gcode_input(const std::uint8_t* data, std::size_t size) {
  using namespace gcode_detail;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)motion::detect_dialect(text);
  for (const Dialect dialect : {Dialect::Iso, Dialect::LinuxCnc, Dialect::Heidenhain}) {
    const std::string name = dialect == Dialect::Iso ? "iso" : dialect == Dialect::LinuxCnc ? "linuxcnc" : "heidenhain";
    const Outcome strict = parse(text, dialect, false);
    const Outcome lenient = parse(text, dialect, true);
    if (!strict.failure.empty()) return name + " strict: " + strict.failure;
    if (!lenient.failure.empty()) return name + " lenient: " + lenient.failure;
    if (strict.program) {
      if (!lenient.program) return name + ": strict accepted but lenient rejected: " + lenient.error;
      if (!lenient.program->warnings.empty()) return name + ": lenient warned on input strict accepts";
      std::string same = compare_motion(*strict.program, *lenient.program, name + " strict vs lenient");
      if (!same.empty()) return same;
      if (strict.program->blocks.size() != lenient.program->blocks.size()) return name + ": strict and lenient block counts differ";
    } else if (lenient.program && lenient.program->warnings.empty()) {
      return name + ": lenient accepted without warnings but strict rejected: " + strict.error;
    }
    for (const Outcome* o : {&strict, &lenient}) {
      if (!o->program) continue;
      const std::string what = name + (o == &strict ? " strict" : " lenient");
      std::string problem = check_consistent(*o->program, what);
      if (problem.empty()) problem = check_round_trips(*o->program, what);
      if (!problem.empty()) return problem;
    }
  }
  return std::nullopt;
}

}  // namespace servotwin::fuzz
