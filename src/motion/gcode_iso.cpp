// ISO G-code reader (the subset documented in gcode.hpp).
#include <charconv>
#include <climits>
#include <cmath>
#include <string>

#include "gcode_common.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion {

namespace {

using detail::Cursor;
using detail::NumberStatus;
using detail::Reporter;
using detail::ScannedNumber;
using detail::ValueWord;

/// One G word kept per modal group: its code (10 x the G number, so G90.1 = 901) and column.
struct GroupWord {
  int code = -1;
  std::size_t column = 0;
};

/// Everything one line says, before it is applied to the modal state.
struct LineWords {
  GroupWord motion, dwell, plane, units, distance, arc_distance, feed_mode, compensation, control;
  std::array<ValueWord, kAxisCount> axis{};
  std::array<ValueWord, kAxisCount> offset{};
  ValueWord radius, p, q, feed;
  std::size_t first_geometry_column = 0;  ///< column of the first axis/offset/R word
  bool has_number = false;
  bool content = false;
};

/// Modal state carried from line to line.
struct IsoState {
  int motion = -1;           ///< 0, 10, 20, 30 or -1 before any motion word
  Plane plane = Plane::XY;
  bool inch = false;
  bool incremental = false;
  bool arc_absolute = false;  ///< G90.1
  double feed = 0.0;          ///< mm/min, 0 = none programmed yet
  Point position{};
  PathControl control = PathControl::Unstated;
  double blend_tolerance = 0.0;  ///< mm
  double cam_tolerance = -1.0;   ///< mm, < 0: not written
};

std::string g_name(int code) {
  std::string s = (code < 100 ? "G0" : "G") + std::to_string(code / 10);
  if (code % 10 != 0) s += "." + std::to_string(code % 10);
  return s;
}

class IsoReader {
 public:
  IsoReader(std::string_view source, const ParseOptions& options, Program& program)
      : program_(program), linuxcnc_(program.dialect == Dialect::LinuxCnc), report_(source, options.lenient, program.warnings),
        tolerance_{options.arc_tolerance_abs_mm, options.arc_tolerance_rel} {
    state_.position = options.start;
  }

  void read(std::string_view text) {
    detail::LineSplitter lines(text);
    std::string_view line;
    while (lines.next(line)) read_line(line, lines.line_number());
  }

 private:
  Program& program_;
  bool linuxcnc_;
  Reporter report_;
  detail::ArcTolerance tolerance_;
  IsoState state_;
  std::size_t line_no_ = 0;
  std::string_view line_;

  [[noreturn]] void fail(std::size_t column, const std::string& message) const { report_.error(line_no_, column, message); }

  void read_line(std::string_view line, std::size_t line_no) {
    line_ = line;
    line_no_ = line_no;
    Cursor c{line, 0};
    c.skip_blanks();
    if (c.at_end() || c.peek() == '%') return;  // blank line or tape mark
    LineWords w;
    Block block;
    block.line = line_no;
    scan_words(c, w, block);
    if (!w.content) return;
    apply(w, block);
    program_.blocks.push_back(std::move(block));
  }

  void add_comment(Block& block, std::string_view text) {
    text = detail::trim(text);
    if (text.empty()) return;
    if (!block.comment.empty()) block.comment += ' ';
    block.comment.append(text);
  }

  void scan_words(Cursor& c, LineWords& w, Block& block) {
    while (true) {
      c.skip_blanks();
      if (c.at_end()) return;
      const char ch = c.peek();
      const std::size_t col = c.column();
      if (ch == '(') {
        const std::size_t close = line_.find(')', c.pos + 1);
        if (close == std::string_view::npos) fail(col, "comment '(' is not closed on this line");
        add_comment(block, line_.substr(c.pos + 1, close - c.pos - 1));
        c.pos = close + 1;
        w.content = true;
        continue;
      }
      if (ch == ';') {
        add_comment(block, line_.substr(c.pos + 1));
        w.content = true;
        return;
      }
      if (!detail::is_alpha(ch)) {
        report_.unsupported(line_no_, col, "unexpected character '" + detail::printable(line_.substr(c.pos, 1)) + "'");
        ++c.pos;
        continue;
      }
      const char letter = detail::to_upper(ch);
      ++c.pos;
      w.content = true;
      switch (letter) {
        case 'G': read_g(c, w, col); break;
        case 'M': block.m_codes.push_back(static_cast<int>(read_integer(c, col, "M", INT_MAX))); break;
        case 'N':
          if (w.has_number) fail(col, "second N number on the line");
          w.has_number = true;
          block.number = read_integer(c, col, "N", LONG_MAX);
          break;
        case 'X': read_value(c, w.axis[0], col, "X", &w); break;
        case 'Y': read_value(c, w.axis[1], col, "Y", &w); break;
        case 'Z': read_value(c, w.axis[2], col, "Z", &w); break;
        case 'I': read_value(c, w.offset[0], col, "I", &w); break;
        case 'J': read_value(c, w.offset[1], col, "J", &w); break;
        case 'K': read_value(c, w.offset[2], col, "K", &w); break;
        case 'R': read_value(c, w.radius, col, "R", &w); break;
        case 'P': read_value(c, w.p, col, "P", nullptr); break;
        case 'Q':
          if (!linuxcnc_) {
            skip_unknown(c, col);
          } else {
            read_value(c, w.q, col, "Q", nullptr);
          }
          break;
        case 'F': read_value(c, w.feed, col, "F", nullptr); break;
        default: skip_unknown(c, col); break;
      }
    }
  }

  void skip_unknown(Cursor& c, std::size_t col) {
    report_.unsupported(line_no_, col, "unknown word '" + detail::word_text(line_, col - 1) + "'");
    while (!c.at_end() && !detail::is_blank(c.peek()) && !detail::is_alpha(c.peek()) && c.peek() != '(' &&
           c.peek() != ';')
      ++c.pos;
  }

  ScannedNumber scan_checked(Cursor& c, std::size_t col, std::string_view letter) {
    const ScannedNumber n = detail::scan_number(c);
    if (n.status != NumberStatus::Ok) fail(col, detail::number_problem(n, letter, detail::word_text(line_, col - 1)));
    return n;
  }

  void read_value(Cursor& c, ValueWord& word, std::size_t col, const char* letter, LineWords* geometry) {
    const ScannedNumber n = scan_checked(c, col, letter);
    if (word.present) fail(col, std::string("word ") + letter + " appears twice on the line");
    word = {true, n.value, col};
    if (geometry != nullptr && geometry->first_geometry_column == 0) geometry->first_geometry_column = col;
  }

  /// Non-negative integer word (N, M).
  long read_integer(Cursor& c, std::size_t col, const char* letter, long max) {
    const ScannedNumber n = detail::scan_number(c);
    if (n.status == NumberStatus::Missing) fail(col, std::string("expected a number after '") + letter + "'");
    if (n.status == NumberStatus::Malformed || n.negative || n.has_point || n.digits.empty())
      fail(col, "'" + detail::word_text(line_, col - 1) + "': " + letter + " takes a non-negative whole number");
    long value = 0;
    const auto r = std::from_chars(n.digits.data(), n.digits.data() + n.digits.size(), value);
    if (r.ec != std::errc{} || value > max) fail(col, "number out of range in '" + detail::word_text(line_, col - 1) + "'");
    return value;
  }

  void read_g(Cursor& c, LineWords& w, std::size_t col) {
    const ScannedNumber n = detail::scan_number(c);
    const auto word = [&] { return detail::word_text(line_, col - 1); };
    if (n.status == NumberStatus::Missing) fail(col, "expected a number after 'G'");
    if (n.status == NumberStatus::Malformed || n.negative || n.digits.empty())
      fail(col, "'" + word() + "': G takes a non-negative number such as G01 or G90.1");
    std::string_view digits = n.digits;
    while (digits.size() > 1 && digits.front() == '0') digits.remove_prefix(1);
    int code = -1;
    if (digits.size() <= 3 && n.fraction.size() <= 1 && !(n.has_point && n.fraction.empty())) {
      int whole = 0;
      const auto parsed = std::from_chars(digits.data(), digits.data() + digits.size(), whole);
      if (parsed.ec != std::errc{}) whole = -1000;
      code = whole * 10 + (n.fraction.empty() ? 0 : n.fraction.front() - '0');
    }
    switch (code) {
      case 0: case 10: case 20: case 30: set_group(w.motion, code, col, "motion"); break;
      case 40: set_group(w.dwell, code, col, "dwell"); break;
      case 170: case 180: case 190: set_group(w.plane, code, col, "plane selection"); break;
      case 200: case 210: set_group(w.units, code, col, "units"); break;
      case 900: case 910: set_group(w.distance, code, col, "distance mode"); break;
      case 901: case 911: set_group(w.arc_distance, code, col, "arc distance mode"); break;
      case 940: set_group(w.feed_mode, code, col, "feed mode"); break;
      case 930: case 950:
        report_.unsupported(line_no_, col, "'" + word() + "': only feed per minute (G94) is supported");
        break;
      case 400: set_group(w.compensation, code, col, "cutter compensation"); break;
      case 610: case 640: set_group(w.control, code, col, "path control"); break;
      case 611:
        if (linuxcnc_) {
          set_group(w.control, code, col, "path control");
        } else {
          report_.unsupported(line_no_, col, "'" + word() + "' is LinuxCNC's exact stop: read the program with --dialect linuxcnc "
                                             "(ISO's exact stop is G61)");
        }
        break;
      case 410: case 420:
        report_.unsupported(line_no_, col, "'" + word() + "': cutter radius compensation is not supported");
        break;
      default: report_.unsupported(line_no_, col, "unknown word '" + word() + "'"); break;
    }
  }

  void set_group(GroupWord& group, int code, std::size_t col, const char* name) {
    if (group.code >= 0)
      fail(col, g_name(group.code) + " and " + g_name(code) + " on one line are in the same modal group (" + name + ")");
    group = {code, col};
  }

  void apply(const LineWords& w, Block& block) {
    if (w.plane.code >= 0) state_.plane = w.plane.code == 170 ? Plane::XY : w.plane.code == 180 ? Plane::ZX : Plane::YZ;
    if (w.units.code >= 0) state_.inch = w.units.code == 200;
    if (w.distance.code >= 0) state_.incremental = w.distance.code == 910;
    if (w.arc_distance.code >= 0) state_.arc_absolute = w.arc_distance.code == 901;
    const double unit = state_.inch ? detail::kMmPerInch : 1.0;
    if (w.control.code >= 0) apply_control(w, unit);
    if (w.q.present && w.control.code != 640) fail(w.q.column, "Q is only used with G64 (naive-CAM tolerance)");
    block.path_control = state_.control;
    block.blend_tolerance_mm = state_.blend_tolerance;
    block.cam_tolerance_mm = state_.cam_tolerance;
    if (w.feed.present) {
      const double f = w.feed.value * unit;
      if (!(f > 0.0)) fail(w.feed.column, "feed F must be > 0 (got " + detail::format_number(w.feed.value) + ")");
      if (f > detail::kMaxMagnitude) fail(w.feed.column, "feed F out of range (at most 1e9 mm/min)");
      state_.feed = f;
    }
    block.plane = state_.plane;
    block.start = state_.position;
    block.end = state_.position;
    block.center = state_.position;
    if (w.dwell.code >= 0) {
      apply_dwell(w, block);
      return;
    }
    if (w.motion.code >= 0) state_.motion = w.motion.code;
    if (w.p.present && !(linuxcnc_ && w.control.code == 640))
      fail(w.p.column, linuxcnc_ ? "P is only used with G04 (dwell time in seconds) and G64 (blend tolerance)"
                                 : "P is only used with G04 (dwell time in seconds)");
    const bool has_axes = w.axis[0].present || w.axis[1].present || w.axis[2].present;
    const bool has_offsets = w.offset[0].present || w.offset[1].present || w.offset[2].present;
    if (!has_axes && !has_offsets && !w.radius.present) return;  // modal words only: a None block
    if (state_.motion < 0)
      fail(w.first_geometry_column, "axis words without a motion mode: program G00, G01, G02 or G03 first");
    const int motion = state_.motion;
    const std::size_t motion_column = w.motion.code >= 0 ? w.motion.column : w.first_geometry_column;
    if (motion <= 10 && (has_offsets || w.radius.present)) {
      const std::size_t col = w.radius.present ? w.radius.column : first_present(w.offset);
      fail(col, "I/J/K and R are only used with arcs (G02/G03), not with " + g_name(motion));
    }
    for (std::size_t a = 0; a < kAxisCount; ++a) {
      if (!w.axis[a].present) continue;
      const double v = w.axis[a].value * unit;
      const double target = state_.incremental ? state_.position[a] + v : v;
      if (!(std::fabs(target) <= detail::kMaxMagnitude))
        fail(w.axis[a].column, "coordinate out of range (|value| must be <= 1e9 mm)");
      block.end[a] = detail::positive_zero(target);
      block.axes = static_cast<std::uint8_t>(block.axes | axis_bit(static_cast<Axis>(a)));
    }
    block.feed_mm_min = state_.feed;
    if (motion == 0) {
      block.type = BlockType::Rapid;
    } else {
      if (!(state_.feed > 0.0))
        fail(motion_column, "no feed programmed: " + g_name(motion) + " needs F > 0 on this line or before");
      if (motion == 10) {
        block.type = BlockType::Linear;
      } else {
        block.type = motion == 20 ? BlockType::ArcCw : BlockType::ArcCcw;
        build_arc(w, block, unit, motion_column);
      }
    }
    state_.position = block.end;
  }

  /// G61 / G61.1 / G64 [P [Q]]. ISO (Fanuc) G64 takes no tolerance; LinuxCNC's P and Q are in
  /// program units, P0 means the same as G64 alone (LinuxCNC G-code reference, G64).
  void apply_control(const LineWords& w, double unit) {
    state_.blend_tolerance = 0.0;
    state_.cam_tolerance = -1.0;
    switch (w.control.code) {
      case 610: state_.control = linuxcnc_ ? PathControl::ExactPath : PathControl::ExactStop; return;
      case 611: state_.control = PathControl::ExactStop; return;
      default: break;
    }
    state_.control = PathControl::Blend;
    if (w.p.present) {
      if (!linuxcnc_)
        fail(w.p.column, "G64 P<tolerance> is LinuxCNC syntax: read the program with --dialect linuxcnc "
                         "(ISO's G64 takes no tolerance)");
      if (w.dwell.code >= 0) fail(w.p.column, "P of G64 and of G04 on one line: write the dwell on a line of its own");
      if (!(w.p.value >= 0.0 && w.p.value * unit <= detail::kMaxMagnitude))
        fail(w.p.column, "blend tolerance P must be >= 0 (got " + detail::format_number(w.p.value) + ")");
      state_.blend_tolerance = w.p.value * unit;
    }
    if (w.q.present) {
      if (!(w.q.value >= 0.0 && w.q.value * unit <= detail::kMaxMagnitude))
        fail(w.q.column, "naive-CAM tolerance Q must be >= 0 (got " + detail::format_number(w.q.value) + ")");
      if (!w.p.present) fail(w.q.column, "G64 Q needs P before it (G64 P<blend tolerance> Q<naive-CAM tolerance>)");
      state_.cam_tolerance = w.q.value * unit;
    }
  }

  static std::size_t first_present(const std::array<ValueWord, kAxisCount>& words) {
    for (const ValueWord& v : words)
      if (v.present) return v.column;
    return 0;
  }

  void apply_dwell(const LineWords& w, Block& block) {
    if (w.motion.code >= 0)
      fail(w.motion.column, "G04 and " + g_name(w.motion.code) + " on one line: a line carries at most one motion or dwell");
    for (const ValueWord* v : {&w.axis[1], &w.axis[2], &w.offset[0], &w.offset[1], &w.offset[2], &w.radius})
      if (v->present) fail(v->column, "'" + detail::word_text(line_, v->column - 1) + "' is not allowed with G04 (dwell time: P or X in seconds)");
    if (w.p.present && w.axis[0].present) fail(w.axis[0].column, "G04 takes its time from P or X, not both");
    const ValueWord& t = w.p.present ? w.p : w.axis[0];
    if (!t.present) fail(w.dwell.column, "G04 needs the dwell time P or X in seconds");
    if (t.value < 0.0) fail(t.column, "dwell time must be >= 0 s");
    block.type = BlockType::Dwell;
    block.dwell_s = t.value;
  }

  void build_arc(const LineWords& w, Block& block, double unit, std::size_t motion_column) {
    const detail::PlaneAxes pa = detail::plane_axes(block.plane);
    const char* plane_word = detail::plane_gcode(block.plane);
    if (w.offset[pa.n].present)
      fail(w.offset[pa.n].column, std::string("'") + detail::word_text(line_, w.offset[pa.n].column - 1) +
                                      "' is not in the " + detail::plane_name(block.plane) + " plane (" + plane_word +
                                      "); select the plane of the arc with G17, G18 or G19");
    const bool has_center = w.offset[pa.u].present || w.offset[pa.v].present;
    if (w.radius.present && has_center)
      fail(w.radius.column, "an arc takes either R or its centre (I/J/K), not both");
    std::string problem;
    if (w.radius.present) {
      problem = detail::center_from_radius(block, w.radius.value * unit, tolerance_);
      if (!problem.empty()) fail(w.radius.column, problem);
    } else {
      if (!has_center)
        fail(motion_column, std::string("arc needs its centre (") + static_cast<char>('I' + pa.u) +
                                static_cast<char>('I' + pa.v) + " in " + plane_word + ") or a radius R");
      block.center = block.start;
      for (const std::size_t a : {pa.u, pa.v}) {
        const ValueWord& o = w.offset[a];
        double c = 0.0;
        if (state_.arc_absolute) {
          if (!o.present)
            fail(motion_column, std::string("G90.1 (absolute arc centre) needs both ") + static_cast<char>('I' + pa.u) +
                                    " and " + static_cast<char>('I' + pa.v));
          c = o.value * unit;
        } else {
          c = o.present ? block.start[a] + o.value * unit : block.start[a];
        }
        if (!(std::fabs(c) <= detail::kMaxMagnitude))
          fail(o.present ? o.column : motion_column, "arc centre out of range (|value| must be <= 1e9 mm)");
        block.center[a] = detail::positive_zero(c);
      }
      problem = detail::check_arc_radius(block, tolerance_);
      if (!problem.empty()) fail(motion_column, problem);
    }
    if (!detail::within_limits(block.center)) fail(motion_column, "arc centre out of range (|value| must be <= 1e9 mm)");
  }
};

}  // namespace

namespace {

Program parse_iso_dialect(std::string_view text, std::string_view source_name, const ParseOptions& options,
                          Dialect dialect) {
  detail::check_tolerances(options);
  Program program;
  program.name = std::string(source_name);
  program.dialect = dialect;
  program.start = options.start;
  program.blocks.reserve(detail::reserve_hint(text));
  IsoReader reader(source_name, options, program);
  reader.read(text);
  return program;
}

}  // namespace

Program parse_iso(std::string_view text, std::string_view source_name, const ParseOptions& options) {
  return parse_iso_dialect(text, source_name, options, Dialect::Iso);
}

Program parse_linuxcnc(std::string_view text, std::string_view source_name, const ParseOptions& options) {
  return parse_iso_dialect(text, source_name, options, Dialect::LinuxCnc);
}

}  // namespace servotwin::motion
