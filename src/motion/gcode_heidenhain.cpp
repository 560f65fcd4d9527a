// Heidenhain conversational reader (the subset documented in gcode.hpp).
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <string>

#include "gcode_common.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion {

namespace {

using detail::Cursor;
using detail::equals_upper;
using detail::NumberStatus;
using detail::Reporter;
using detail::ScannedNumber;
using detail::ValueWord;

/// Coordinates of a block: absolute (X) or incremental (IX) per axis.
struct AxisWords {
  std::array<ValueWord, kAxisCount> absolute{};
  std::array<ValueWord, kAxisCount> incremental{};
  [[nodiscard]] bool given(std::size_t a) const noexcept { return absolute[a].present || incremental[a].present; }
  [[nodiscard]] std::size_t count() const noexcept {
    std::size_t n = 0;
    for (std::size_t a = 0; a < kAxisCount; ++a) n += given(a) ? 1 : 0;
    return n;
  }
};

/// Words of the path blocks L, C, CC and CR.
struct PathWords {
  AxisWords coords;
  ValueWord radius;  ///< CR: signed radius
  bool r0 = false;
  int direction = 0;  ///< DR+ = +1, DR- = -1
  std::size_t direction_column = 0;
  bool fmax = false;
  std::size_t fmax_column = 0;
  ValueWord feed;
};

enum class PathKind { L, C, CC, CR };

const char* kind_name(PathKind k) {
  switch (k) {
    case PathKind::L: return "L";
    case PathKind::C: return "C";
    case PathKind::CC: return "CC";
    case PathKind::CR: return "CR";
  }
  return "L";
}

/// Heidenhain statements this reader knows but does not support.
bool known_unsupported(std::string_view kw) {
  static constexpr std::array<std::string_view, 22> kNames{
      "CT", "CP", "LP", "CTP", "RND", "CHF", "APPR", "DEP", "LBL", "CALL", "FN", "Q",
      "STOP", "PLANE", "FL", "FLT", "FC", "FCT", "FPOL", "FSELECT", "SPL", "TCH"};
  for (std::string_view n : kNames)
    if (equals_upper(kw, n)) return true;
  return false;
}

Plane working_plane_of(std::size_t tool_axis) {
  return tool_axis == 2 ? Plane::XY : tool_axis == 1 ? Plane::ZX : Plane::YZ;
}

class HeidenhainReader {
 public:
  HeidenhainReader(std::string_view source, const ParseOptions& options, Program& program)
      : program_(program), report_(source, options.lenient, program.warnings),
        tolerance_{options.arc_tolerance_abs_mm, options.arc_tolerance_rel}, position_(options.start) {}

  void read(std::string_view text) {
    detail::LineSplitter lines(text);
    std::string_view line;
    while (lines.next(line)) read_line(line, lines.line_number());
    const std::size_t last = lines.line_number() == 0 ? 1 : lines.line_number();
    if (!begun_) report_.error(last, 1, "no 'BEGIN PGM name MM' found: not a Heidenhain conversational program");
    no_pending_dwell();
    no_pending_tolerance();
    if (!ended_) report_.unsupported(last, 1, "missing 'END PGM " + program_.name + (inch_ ? " INCH'" : " MM'") + " at the end");
  }

 private:
  Program& program_;
  Reporter report_;
  detail::ArcTolerance tolerance_;
  Point position_;
  double feed_ = 0.0;  ///< modal numeric feed [mm/min], 0 = none yet
  Plane working_ = Plane::XY;
  bool has_center_ = false;
  Point center_{};
  Plane center_plane_ = Plane::XY;
  bool begun_ = false;
  bool ended_ = false;
  bool inch_ = false;
  bool dwell_pending_ = false;
  std::size_t dwell_line_ = 0;
  bool tolerance_pending_ = false;  ///< CYCL DEF 32.0 read, 32.1 expected
  std::size_t tolerance_line_ = 0;
  PathControl control_ = PathControl::Unstated;
  double tolerance_mm_ = 0.0;
  std::size_t line_no_ = 0;
  std::string_view line_;

  [[nodiscard]] double unit() const noexcept { return inch_ ? detail::kMmPerInch : 1.0; }
  /// A two-line cycle (9 DWELL TIME, 32 TOLERANCE) must be finished before anything else.
  void no_pending_dwell() const {
    if (dwell_pending_) report_.error(dwell_line_, 1, "CYCL DEF 9.0 must be followed by CYCL DEF 9.1 DWELL <seconds>");
  }
  void no_pending_tolerance() const {
    if (tolerance_pending_)
      report_.error(tolerance_line_, 1, "CYCL DEF 32.0 TOLERANCE must be followed by CYCL DEF 32.1 [T<tolerance>]");
  }
  [[noreturn]] void fail(std::size_t column, const std::string& message) const { report_.error(line_no_, column, message); }
  std::string word_at(std::size_t column) const { return detail::word_text(line_, column - 1); }

  void read_line(std::string_view line, std::size_t line_no) {
    line_ = line;
    line_no_ = line_no;
    Cursor c{line, 0};
    c.skip_blanks();
    if (c.at_end()) return;
    if (ended_) {
      report_.unsupported(line_no, c.column(), "text after END PGM");
      return;
    }
    Block block;
    block.line = line_no;
    block.plane = working_;
    block.start = position_;
    block.end = position_;
    block.center = position_;
    block.path_control = control_;
    block.blend_tolerance_mm = tolerance_mm_;
    if (detail::is_digit(c.peek())) block.number = read_block_number(c);
    c.skip_blanks();
    if (c.at_end() || c.peek() == ';') {  // number only, or a comment line
      if (!c.at_end()) block.comment = std::string(detail::trim(line.substr(c.pos + 1)));
      if (c.at_end() && !begun_) fail(1, "expected 'BEGIN PGM name MM' as the first block");
      program_.blocks.push_back(std::move(block));
      return;
    }
    const std::size_t kw_column = c.column();
    const std::string_view kw = c.take_letters();
    if (kw.empty()) {
      report_.unsupported(line_no, kw_column, "unexpected character '" + detail::printable(line.substr(kw_column - 1, 1)) + "'");
      return;
    }
    if (!begun_ && !equals_upper(kw, "BEGIN"))
      fail(kw_column, "expected 'BEGIN PGM name MM' as the first block, found '" + detail::printable(kw) + "'");
    if (!equals_upper(kw, "CYCL")) {
      no_pending_dwell();
      no_pending_tolerance();
    }
    if (equals_upper(kw, "BEGIN")) {
      read_begin(c, kw_column);
    } else if (equals_upper(kw, "END")) {
      read_end(c, kw_column);
    } else if (equals_upper(kw, "L")) {
      read_l(c, block, kw_column);
    } else if (equals_upper(kw, "C")) {
      read_c(c, block, kw_column);
    } else if (equals_upper(kw, "CR")) {
      read_cr(c, block, kw_column);
    } else if (equals_upper(kw, "CC")) {
      read_cc(c, kw_column);
    } else if (equals_upper(kw, "M")) {
      c.pos = kw_column - 1;
      read_m_line(c, block);
    } else if (equals_upper(kw, "BLK")) {
      read_blk_form(c, block, kw_column);
    } else if (equals_upper(kw, "TOOL")) {
      read_tool_call(c, block);
    } else if (equals_upper(kw, "CYCL")) {
      read_cycle(c, block, kw_column);
    } else if (known_unsupported(kw)) {
      report_.unsupported(line_no, kw_column, "'" + detail::printable(kw) + "' is not supported");
    } else {
      report_.unsupported(line_no, kw_column, "unknown word '" + word_at(kw_column) + "'");
    }
  }

  long read_block_number(Cursor& c) {
    const std::size_t col = c.column();
    const std::size_t begin = c.pos;
    while (!c.at_end() && detail::is_digit(c.peek())) ++c.pos;
    long value = 0;
    const auto r = std::from_chars(line_.data() + begin, line_.data() + c.pos, value);
    if (r.ec != std::errc{}) fail(col, "block number out of range in '" + word_at(col) + "'");
    if (!c.at_end() && !detail::is_blank(c.peek()) && c.peek() != ';')
      fail(col, "block number must be followed by a blank, found '" + word_at(col) + "'");
    return value;
  }

  /// Expects the keyword `word` (e.g. PGM after BEGIN).
  void expect_word(Cursor& c, std::string_view word, std::string_view after) {
    c.skip_blanks();
    const std::size_t col = c.column();
    const std::string_view got = c.take_letters();
    if (!equals_upper(got, word))
      fail(col, "expected '" + std::string(word) + "' after '" + std::string(after) + "'");
  }

  /// Only blanks or a comment may follow.
  void expect_end(Cursor& c, Block* block, std::string_view what) {
    c.skip_blanks();
    if (c.at_end()) return;
    if (c.peek() == ';') {
      if (block != nullptr) block->comment = std::string(detail::trim(line_.substr(c.pos + 1)));
      return;
    }
    report_.unsupported(line_no_, c.column(), "unexpected '" + word_at(c.column()) + "' after " + std::string(what));
  }

  ScannedNumber scan_checked(Cursor& c, std::size_t col, std::string_view what) {
    const ScannedNumber n = detail::scan_number(c);
    if (n.status != NumberStatus::Ok) fail(col, detail::number_problem(n, what, word_at(col)));
    return n;
  }

  std::pair<std::string_view, bool> read_name_and_unit(Cursor& c, std::string_view statement) {
    c.skip_blanks();
    const std::size_t begin = c.pos;
    while (!c.at_end() && !detail::is_blank(c.peek()) && c.peek() != ';') ++c.pos;
    const std::string_view name = line_.substr(begin, c.pos - begin);
    if (name.empty()) fail(c.column(), "expected the program name after '" + std::string(statement) + "'");
    c.skip_blanks();
    const std::size_t unit_col = c.column();
    const std::string_view unit = c.take_letters();
    bool inch = false;
    if (equals_upper(unit, "INCH")) {
      inch = true;
    } else if (!equals_upper(unit, "MM")) {
      fail(unit_col, "expected MM or INCH after the program name");
    }
    return {name, inch};
  }

  void read_begin(Cursor& c, std::size_t kw_column) {
    if (begun_) fail(kw_column, "second BEGIN PGM");
    expect_word(c, "PGM", "BEGIN");
    const auto [name, inch] = read_name_and_unit(c, "BEGIN PGM");
    begun_ = true;
    inch_ = inch;
    program_.name = std::string(name);
    expect_end(c, nullptr, "BEGIN PGM");
  }

  void read_end(Cursor& c, std::size_t kw_column) {
    expect_word(c, "PGM", "END");
    const auto [name, inch] = read_name_and_unit(c, "END PGM");
    if (name != program_.name || inch != inch_)
      fail(kw_column, "'END PGM " + detail::printable(name) + (inch ? " INCH" : " MM") + "' does not match 'BEGIN PGM " +
                          detail::printable(program_.name) + (inch_ ? " INCH'" : " MM'"));
    ended_ = true;
    expect_end(c, nullptr, "END PGM");
  }

  void set_axis_word(AxisWords& words, std::size_t axis, bool incremental, double value, std::size_t col) {
    if (words.given(axis)) fail(col, std::string("axis ") + axis_letter(static_cast<Axis>(axis)) + " given twice");
    (incremental ? words.incremental : words.absolute)[axis] = {true, value, col};
  }

  /// X/Y/Z/IX/IY/IZ: axis index and incremental flag; false when `letters` is no axis word.
  static bool axis_word(std::string_view letters, std::size_t& axis, bool& incremental) {
    incremental = letters.size() == 2 && detail::to_upper(letters[0]) == 'I';
    const std::string_view a = incremental ? letters.substr(1) : letters;
    if (a.size() != 1) return false;
    const char up = detail::to_upper(a[0]);
    if (up < 'X' || up > 'Z') return false;
    axis = static_cast<std::size_t>(up - 'X');
    return true;
  }

  /// A `;` comment runs to the end of the line: stores it in the block and says whether one was there.
  bool take_comment(const Cursor& c, Block& block) const {
    if (c.peek() != ';') return false;
    block.comment = std::string(detail::trim(line_.substr(c.pos + 1)));
    return true;
  }

  void read_path_words(Cursor& c, PathWords& w, Block& block, PathKind kind) {
    while (true) {
      c.skip_blanks();
      if (c.at_end()) return;
      if (take_comment(c, block)) return;
      const std::size_t col = c.column();
      const std::string_view letters = c.take_letters();
      if (letters.empty()) {
        report_.unsupported(line_no_, col, "unexpected character '" + detail::printable(line_.substr(col - 1, 1)) + "'");
        ++c.pos;
        continue;
      }
      std::size_t axis = 0;
      bool incremental = false;
      if (axis_word(letters, axis, incremental)) {
        const ScannedNumber n = scan_checked(c, col, letters);
        set_axis_word(w.coords, axis, incremental, n.value, col);
      } else if (equals_upper(letters, "R")) {
        const ScannedNumber n = scan_checked(c, col, "R");
        if (kind == PathKind::CR && !w.radius.present) {
          w.radius = {true, n.value, col};
        } else if (n.value == 0.0 && !w.r0) {
          w.r0 = true;
        } else {
          fail(col, "'" + word_at(col) + "': only R0 (no radius compensation) is allowed here" +
                        (kind == PathKind::CR ? " besides the radius" : ""));
        }
      } else if (equals_upper(letters, "RL") || equals_upper(letters, "RR")) {
        report_.unsupported(line_no_, col, "radius compensation '" + detail::printable(letters) + "' is not supported");
      } else if (equals_upper(letters, "DR")) {
        read_direction(c, w, kind, col);
      } else if (equals_upper(letters, "F")) {
        c.skip_blanks();
        if (detail::is_alpha(c.peek())) {
          const std::size_t sub_col = c.column();
          const std::string_view sub = c.take_letters();
          if (equals_upper(sub, "MAX")) {
            set_fmax(w, col);
          } else if (equals_upper(sub, "AUTO")) {
            report_.unsupported(line_no_, col, "'F AUTO' is not supported");
          } else {
            fail(sub_col, "F takes a feed in mm/min or MAX, found '" + word_at(sub_col) + "'");
          }
        } else {
          read_feed(c, w, col);
        }
      } else if (equals_upper(letters, "FMAX")) {
        set_fmax(w, col);
      } else if (equals_upper(letters, "M")) {
        block.m_codes.push_back(read_m_code(c, col));
      } else {
        report_.unsupported(line_no_, col, "unknown word '" + word_at(col) + "'");
        while (!c.at_end() && !detail::is_blank(c.peek()) && c.peek() != ';') ++c.pos;
      }
    }
  }

  void read_direction(Cursor& c, PathWords& w, PathKind kind, std::size_t col) {
    c.skip_blanks();
    const char sign = c.peek();
    if (sign != '+' && sign != '-') fail(col, "DR needs a direction: DR+ (counterclockwise) or DR- (clockwise)");
    ++c.pos;
    if (!c.at_end() && (detail::is_digit(c.peek()) || c.peek() == '.'))
      fail(col, "'" + word_at(col) + "': DR takes only a sign (DR+ or DR-)");
    if (kind != PathKind::C && kind != PathKind::CR)
      fail(col, std::string("'DR") + sign + "' is only used with C and CR, not with " + kind_name(kind));
    if (w.direction != 0) fail(col, "direction DR given twice");
    w.direction = sign == '+' ? 1 : -1;
    w.direction_column = col;
  }

  void set_fmax(PathWords& w, std::size_t col) {
    if (w.fmax || w.feed.present) fail(col, "feed given twice");
    w.fmax = true;
    w.fmax_column = col;
  }

  void read_feed(Cursor& c, PathWords& w, std::size_t col) {
    const ScannedNumber n = scan_checked(c, col, "F");
    if (w.fmax || w.feed.present) fail(col, "feed given twice");
    const double f = n.value * unit();
    if (!(f > 0.0)) fail(col, "feed F must be > 0 (got " + detail::format_number(n.value) + ")");
    if (f > detail::kMaxMagnitude) fail(col, "feed F out of range (at most 1e9 mm/min)");
    w.feed = {true, f, col};
  }

  int read_m_code(Cursor& c, std::size_t col) {
    const ScannedNumber n = detail::scan_number(c);
    if (n.status == NumberStatus::Missing) fail(col, "expected a number after 'M'");
    if (n.status == NumberStatus::Malformed || n.negative || n.has_point || n.digits.empty())
      fail(col, "'" + word_at(col) + "': M takes a non-negative whole number");
    int value = 0;
    const auto r = std::from_chars(n.digits.data(), n.digits.data() + n.digits.size(), value);
    if (r.ec != std::errc{}) fail(col, "number out of range in '" + word_at(col) + "'");
    return value;
  }

  /// Resolves the coordinates of a block against `from`; fills `mask` with the axes given.
  Point resolve(const AxisWords& words, const Point& from, std::uint8_t* mask) {
    Point p = from;
    for (std::size_t a = 0; a < kAxisCount; ++a) {
      const ValueWord& abs = words.absolute[a];
      const ValueWord& inc = words.incremental[a];
      if (!abs.present && !inc.present) continue;
      const double v = (abs.present ? abs.value : inc.value) * unit();
      const double target = abs.present ? v : from[a] + v;
      if (!(std::fabs(target) <= detail::kMaxMagnitude))
        fail(abs.present ? abs.column : inc.column, "coordinate out of range (|value| must be <= 1e9 mm)");
      p[a] = detail::positive_zero(target);
      if (mask != nullptr) *mask = static_cast<std::uint8_t>(*mask | axis_bit(static_cast<Axis>(a)));
    }
    return p;
  }

  void take_feed(const PathWords& w, std::size_t kw_column, const char* what) {
    if (w.feed.present) feed_ = w.feed.value;
    if (!(feed_ > 0.0))
      fail(kw_column, std::string("no feed programmed: ") + what + " needs F on this block or before");
  }

  void read_l(Cursor& c, Block& block, std::size_t kw_column) {
    PathWords w;
    read_path_words(c, w, block, PathKind::L);
    if (w.coords.count() == 0) {  // L with only F/R0/M: no motion
      if (w.feed.present) feed_ = w.feed.value;
      program_.blocks.push_back(std::move(block));
      return;
    }
    block.end = resolve(w.coords, position_, &block.axes);
    if (w.fmax) {
      block.type = BlockType::Rapid;
    } else {
      take_feed(w, kw_column, "L");
      block.type = BlockType::Linear;
    }
    block.feed_mm_min = feed_;
    position_ = block.end;
    program_.blocks.push_back(std::move(block));
  }

  void check_arc_words(const PathWords& w, std::size_t kw_column, const char* what) {
    if (w.direction == 0) fail(kw_column, std::string(what) + " needs the direction DR+ (counterclockwise) or DR- (clockwise)");
    if (w.coords.count() == 0) fail(kw_column, std::string(what) + " needs an end point");
    if (w.fmax) fail(w.fmax_column, "F MAX is only allowed on straight lines (L)");
  }

  void read_c(Cursor& c, Block& block, std::size_t kw_column) {
    PathWords w;
    read_path_words(c, w, block, PathKind::C);
    if (!has_center_) fail(kw_column, "C needs a circle centre: program CC first");
    check_arc_words(w, kw_column, "C");
    take_feed(w, kw_column, "C");
    block.plane = center_plane_;
    block.type = w.direction > 0 ? BlockType::ArcCcw : BlockType::ArcCw;
    block.end = resolve(w.coords, position_, &block.axes);
    block.feed_mm_min = feed_;
    const detail::PlaneAxes pa = detail::plane_axes(block.plane);
    block.center = block.start;
    block.center[pa.u] = center_[pa.u];
    block.center[pa.v] = center_[pa.v];
    const std::string problem = detail::check_arc_radius(block, tolerance_);
    if (!problem.empty()) fail(kw_column, problem);
    position_ = block.end;
    program_.blocks.push_back(std::move(block));
  }

  void read_cr(Cursor& c, Block& block, std::size_t kw_column) {
    PathWords w;
    read_path_words(c, w, block, PathKind::CR);
    if (!w.radius.present) fail(kw_column, "CR needs the radius R (R+ for arcs up to 180 degrees, R- above)");
    check_arc_words(w, kw_column, "CR");
    take_feed(w, kw_column, "CR");
    block.plane = working_;
    block.type = w.direction > 0 ? BlockType::ArcCcw : BlockType::ArcCw;
    block.end = resolve(w.coords, position_, &block.axes);
    block.feed_mm_min = feed_;
    const std::string problem = detail::center_from_radius(block, w.radius.value * unit(), tolerance_);
    if (!problem.empty()) fail(w.radius.column, problem);
    if (!detail::within_limits(block.center)) fail(w.radius.column, "arc centre out of range (|value| must be <= 1e9 mm)");
    position_ = block.end;
    program_.blocks.push_back(std::move(block));
  }

  void read_cc(Cursor& c, std::size_t kw_column) {
    Block scratch;  // CC has no block of its own; words other than coordinates are refused below
    PathWords w;
    read_path_words(c, w, scratch, PathKind::CC);
    if (w.feed.present || w.fmax || w.r0 || !scratch.m_codes.empty())
      fail(kw_column, "CC takes only the coordinates of the circle centre");
    const std::size_t n = w.coords.count();
    const detail::PlaneAxes working = detail::plane_axes(working_);
    Plane plane = working_;
    if (n == 1) {
      std::size_t a = 0;
      while (!w.coords.given(a)) ++a;
      if (a == working.n)
        fail(kw_column, std::string("CC ") + axis_letter(static_cast<Axis>(a)) + " is not in the working plane " +
                            detail::plane_name(working_) + "; give two coordinates to choose the plane of the arc");
    } else if (n == 2) {
      plane = !w.coords.given(2) ? Plane::XY : !w.coords.given(1) ? Plane::ZX : Plane::YZ;
    } else if (n == 3) {
      fail(kw_column, "CC takes at most two coordinates (the centre in the plane of the arc)");
    }
    center_ = resolve(w.coords, position_, nullptr);
    center_plane_ = plane;
    has_center_ = true;
  }

  void read_m_line(Cursor& c, Block& block) {
    while (true) {
      c.skip_blanks();
      if (c.at_end()) break;
      if (take_comment(c, block)) break;
      const std::size_t col = c.column();
      const std::string_view letters = c.take_letters();
      if (equals_upper(letters, "M")) {
        block.m_codes.push_back(read_m_code(c, col));
        continue;
      }
      report_.unsupported(line_no_, col, "unknown word '" + word_at(col) + "'");
      if (letters.empty()) ++c.pos;
      while (!c.at_end() && !detail::is_blank(c.peek()) && c.peek() != ';') ++c.pos;
    }
    program_.blocks.push_back(std::move(block));
  }

  /// "0.1" / "9.0" style numbers of BLK FORM and CYCL DEF: returns the text, "" when malformed.
  std::string read_dotted(Cursor& c) {
    const ScannedNumber n = detail::scan_number(c);
    if (n.status != NumberStatus::Ok || n.negative || !n.has_point) return {};
    return std::string(n.digits) + "." + std::string(n.fraction);
  }

  void read_blk_form(Cursor& c, Block& block, std::size_t kw_column) {
    expect_word(c, "FORM", "BLK");
    c.skip_blanks();
    const std::size_t kind_col = c.column();
    const std::string kind = read_dotted(c);
    if (kind != "0.1" && kind != "0.2") fail(kind_col, "expected 0.1 or 0.2 after BLK FORM");
    block.statement = "BLK FORM " + kind;
    if (kind == "0.1") {
      c.skip_blanks();
      const std::size_t axis_col = c.column();
      const std::string_view axis = c.take_letters();
      std::size_t a = 0;
      bool inc = false;
      if (!axis_word(axis, a, inc) || inc) fail(axis_col, "expected the tool axis X, Y or Z after BLK FORM 0.1");
      block.statement += ' ';
      block.statement += axis_letter(static_cast<Axis>(a));
    }
    AxisWords coords;
    while (true) {
      c.skip_blanks();
      if (c.at_end()) break;
      if (take_comment(c, block)) break;
      const std::size_t col = c.column();
      const std::string_view letters = c.take_letters();
      std::size_t a = 0;
      bool inc = false;
      if (!axis_word(letters, a, inc) || (inc && kind == "0.1")) {
        report_.unsupported(line_no_, col, "unknown word '" + word_at(col) + "' in BLK FORM");
        if (letters.empty()) ++c.pos;
        while (!c.at_end() && !detail::is_blank(c.peek()) && c.peek() != ';') ++c.pos;
        continue;
      }
      const ScannedNumber n = scan_checked(c, col, letters);
      set_axis_word(coords, a, inc, n.value, col);
    }
    if (coords.count() == 0) fail(kw_column, "BLK FORM " + kind + " needs coordinates");
    for (std::size_t a = 0; a < kAxisCount; ++a) {
      if (!coords.given(a)) continue;
      const bool inc = coords.incremental[a].present;
      const double v = (inc ? coords.incremental[a].value : coords.absolute[a].value) * unit();
      block.statement += inc ? " I" : " ";
      block.statement += axis_letter(static_cast<Axis>(a));
      detail::append_number(block.statement, v, 3, '+');
    }
    program_.blocks.push_back(std::move(block));
  }

  void read_tool_call(Cursor& c, Block& block) {
    expect_word(c, "CALL", "TOOL");
    c.skip_blanks();
    const std::size_t tool_col = c.column();
    std::string tool;
    if (c.peek() == '"') {
      const std::size_t close = line_.find('"', c.pos + 1);
      if (close == std::string_view::npos) fail(tool_col, "tool name: closing '\"' missing");
      tool = std::string(line_.substr(c.pos, close - c.pos + 1));
      c.pos = close + 1;
    } else {
      const ScannedNumber n = detail::scan_number(c);
      if (n.status != NumberStatus::Ok || n.negative || n.digits.empty())
        fail(tool_col, "expected a tool number or a \"name\" after TOOL CALL");
      tool = std::string(n.digits) + (n.has_point ? "." + std::string(n.fraction) : "");
    }
    c.skip_blanks();
    const std::size_t axis_col = c.column();
    const std::string_view axis = c.take_letters();
    std::size_t a = 0;
    bool inc = false;
    if (!axis_word(axis, a, inc) || inc) fail(axis_col, "expected the tool axis X, Y or Z after the tool");
    working_ = working_plane_of(a);
    block.plane = working_;
    block.statement = "TOOL CALL " + tool + " " + axis_letter(static_cast<Axis>(a));
    bool has_speed = false;
    while (true) {
      c.skip_blanks();
      if (c.at_end()) break;
      if (take_comment(c, block)) break;
      const std::size_t col = c.column();
      const std::string_view letters = c.take_letters();
      if (equals_upper(letters, "S") && !has_speed) {
        const ScannedNumber n = scan_checked(c, col, "S");
        if (n.value < 0.0) fail(col, "spindle speed S must be >= 0");
        block.statement += " S";
        detail::append_shortest(block.statement, n.value);
        has_speed = true;
        continue;
      }
      report_.unsupported(line_no_, col, "unknown word '" + word_at(col) + "' in TOOL CALL");
      if (letters.empty()) ++c.pos;
      while (!c.at_end() && !detail::is_blank(c.peek()) && c.peek() != ';') ++c.pos;
    }
    program_.blocks.push_back(std::move(block));
  }

  void read_cycle(Cursor& c, Block& block, std::size_t kw_column) {
    expect_word(c, "DEF", "CYCL");
    c.skip_blanks();
    const std::size_t number_col = c.column();
    const std::string cycle = read_dotted(c);
    if (cycle == "9.0") {
      no_pending_dwell();
      c.skip_blanks();
      if (!c.at_end() && c.peek() != ';') {
        expect_word(c, "DWELL", "CYCL DEF 9.0");
        expect_word(c, "TIME", "DWELL");
      }
      expect_end(c, nullptr, "CYCL DEF 9.0 DWELL TIME");
      dwell_pending_ = true;
      dwell_line_ = line_no_;
      return;
    }
    if (cycle == "9.1") {
      if (!dwell_pending_) fail(kw_column, "CYCL DEF 9.1 without CYCL DEF 9.0 DWELL TIME before it");
      expect_word(c, "DWELL", "CYCL DEF 9.1");
      const std::size_t col = c.column();
      const ScannedNumber n = scan_checked(c, col, "DWELL");
      if (n.value < 0.0) fail(col, "dwell time must be >= 0 s");
      dwell_pending_ = false;
      block.type = BlockType::Dwell;
      block.dwell_s = n.value;
      expect_end(c, &block, "CYCL DEF 9.1 DWELL");
      program_.blocks.push_back(std::move(block));
      return;
    }
    no_pending_dwell();
    if (cycle == "32.0" || cycle == "32.1" || cycle == "32.2") {
      read_tolerance_cycle(c, block, cycle, kw_column);
      return;
    }
    no_pending_tolerance();
    report_.unsupported(line_no_, number_col,
                        "cycle '" + word_at(number_col) + "' is not supported (only cycle 9 DWELL TIME and 32 TOLERANCE)");
  }

  /// Cycle 32 TOLERANCE: `CYCL DEF 32.0 TOLERANCE`, then `CYCL DEF 32.1 T<tolerance>` (the contour
  /// deviation the control may take when it smooths corners) or a bare `CYCL DEF 32.1` (back to
  /// the machine manufacturer's value: the mode is no longer stated), then optionally
  /// `CYCL DEF 32.2 HSC-MODE:<0|1> [TA<angle>]` (machine filter settings: kept, not interpreted).
  void read_tolerance_cycle(Cursor& c, Block& block, const std::string& cycle, std::size_t kw_column) {
    if (cycle == "32.0") {
      no_pending_tolerance();
      expect_word(c, "TOLERANCE", "CYCL DEF 32.0");
      expect_end(c, nullptr, "CYCL DEF 32.0 TOLERANCE");
      tolerance_pending_ = true;
      tolerance_line_ = line_no_;
      return;
    }
    if (cycle == "32.1") {
      if (!tolerance_pending_) fail(kw_column, "CYCL DEF 32.1 without CYCL DEF 32.0 TOLERANCE before it");
      tolerance_pending_ = false;
      c.skip_blanks();
      if (c.at_end() || c.peek() == ';') {
        control_ = PathControl::Unstated;
        tolerance_mm_ = 0.0;
        return;
      }
      const std::size_t col = c.column();
      if (!equals_upper(c.take_letters(), "T")) fail(col, "expected T<tolerance> after CYCL DEF 32.1");
      const ScannedNumber n = scan_checked(c, col, "T");
      const double t = n.value * unit();
      if (!(t > 0.0 && t <= detail::kMaxMagnitude))
        fail(col, "tolerance T must be > 0 mm (a bare CYCL DEF 32.1 restores the machine's value)");
      expect_end(c, nullptr, "CYCL DEF 32.1 T");
      control_ = PathControl::Blend;
      tolerance_mm_ = t;
      return;
    }
    no_pending_tolerance();
    std::string_view rest = line_.substr(c.pos);
    const std::size_t semicolon = rest.find(';');
    if (semicolon != std::string_view::npos) {
      block.comment = std::string(detail::trim(rest.substr(semicolon + 1)));
      rest = rest.substr(0, semicolon);
    }
    block.statement = "CYCL DEF 32.2 " + std::string(detail::trim(rest));
    program_.blocks.push_back(std::move(block));
  }
};

}  // namespace

Program parse_heidenhain(std::string_view text, std::string_view source_name, const ParseOptions& options) {
  detail::check_tolerances(options);
  Program program;
  program.dialect = Dialect::Heidenhain;
  program.start = options.start;
  program.blocks.reserve(detail::reserve_hint(text));
  HeidenhainReader reader(source_name, options, program);
  reader.read(text);
  return program;
}

Dialect detect_dialect(std::string_view text) noexcept {
  detail::LineSplitter lines(text);
  std::string_view line;
  while (lines.next(line)) {
    Cursor c{line, 0};
    c.skip_blanks();
    if (c.at_end() || c.peek() == ';' || c.peek() == '(' || c.peek() == '%') continue;
    while (!c.at_end() && detail::is_digit(c.peek())) ++c.pos;
    c.skip_blanks();
    if (!equals_upper(c.take_letters(), "BEGIN")) return Dialect::Iso;
    c.skip_blanks();
    return equals_upper(c.take_letters(), "PGM") ? Dialect::Heidenhain : Dialect::Iso;
  }
  return Dialect::Iso;
}

Program parse_program(std::string_view text, std::string_view source_name, const ParseOptions& options,
                      std::optional<Dialect> dialect) {
  switch (dialect.value_or(detect_dialect(text))) {
    case Dialect::Heidenhain: return parse_heidenhain(text, source_name, options);
    case Dialect::LinuxCnc: return parse_linuxcnc(text, source_name, options);
    case Dialect::Iso: break;
  }
  return parse_iso(text, source_name, options);
}

}  // namespace servotwin::motion
