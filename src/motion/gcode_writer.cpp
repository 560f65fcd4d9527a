// ISO and Heidenhain writers (the output format is documented in gcode.hpp).
#include <cmath>
#include <string>

#include "gcode_common.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::motion {

namespace {

using detail::append_number;

[[noreturn]] void bad_block(std::size_t index, const std::string& message) {
  throw core::InputError(core::SourceLocation{{}, 0, 0, "blocks[" + std::to_string(index) + "]"},
                         "cannot write the program: " + message);
}

void check_options(const WriteOptions& o) {
  if (o.decimals < 0 || o.decimals > 9)
    throw core::InputError(core::SourceLocation{{}, 0, 0, "decimals"}, "decimals must be in 0..9, got " + std::to_string(o.decimals));
  if (o.iso_number_width < 0 || o.iso_number_width > 12)
    throw core::InputError(core::SourceLocation{{}, 0, 0, "iso_number_width"},
                           "N number width must be in 0..12, got " + std::to_string(o.iso_number_width));
}

bool is_arc(BlockType t) { return t == BlockType::ArcCw || t == BlockType::ArcCcw; }

/// What a writer can print must be what the readers accept.
void check_block(const Block& b, std::size_t index) {
  if (!detail::within_limits(b.start) || !detail::within_limits(b.end) ||
      (is_arc(b.type) && !detail::within_limits(b.center)))
    bad_block(index, "coordinates must be finite and within +-1e9 mm");
  if ((b.type == BlockType::Linear || is_arc(b.type)) &&
      !(b.feed_mm_min > 0.0 && b.feed_mm_min <= detail::kMaxMagnitude))
    bad_block(index, "feed must be in (0, 1e9] mm/min, got " + detail::format_number(b.feed_mm_min));
  if (b.type == BlockType::Rapid && !(b.feed_mm_min >= 0.0 && b.feed_mm_min <= detail::kMaxMagnitude))
    bad_block(index, "feed of a rapid must be in [0, 1e9] mm/min");
  if (b.type == BlockType::Dwell && !(b.dwell_s >= 0.0 && b.dwell_s <= detail::kMaxMagnitude))
    bad_block(index, "dwell time must be in [0, 1e9] s");
  for (const int m : b.m_codes)
    if (m < 0) bad_block(index, "M codes must be >= 0");
}

/// Axes to print for a block's end point: those written in the source and those that move.
std::uint8_t axes_to_write(const Block& b) {
  std::uint8_t mask = b.axes;
  for (std::size_t a = 0; a < kAxisCount; ++a)
    if (b.end[a] != b.start[a]) mask = static_cast<std::uint8_t>(mask | axis_bit(static_cast<Axis>(a)));
  return mask;
}

/// Comment text on one line: line breaks become blanks.
std::string one_line(const std::string& text) {
  std::string s = text;
  for (char& ch : s)
    if (ch == '\n' || ch == '\r') ch = ' ';
  return std::string(detail::trim(s));
}

/// Incremental arc offset I such that start + I reproduces the centre exactly when a nearby double
/// allows it (the reader computes the centre as start + I).
double exact_offset(double start, double center) {
  const double offset = center - start;
  if (start + offset == center) return offset;
  double down = offset;
  double up = offset;
  for (int k = 0; k < 8; ++k) {
    down = std::nextafter(down, -HUGE_VAL);
    up = std::nextafter(up, HUGE_VAL);
    if (start + down == center) return down;
    if (start + up == center) return up;
  }
  return offset;
}

void append_word(std::string& line, std::string_view word) {
  if (!line.empty()) line += ' ';
  line.append(word);
}

// ---------------------------------------------------------------------------------------------
// ISO

class IsoWriter {
 public:
  IsoWriter(const WriteOptions& o, Dialect dialect)
      : o_(o), sign_(o.sign_column ? ' ' : '\0'), linuxcnc_(dialect == Dialect::LinuxCnc) {}

  std::string write(const Program& program) {
    std::string out;
    out.reserve(program.blocks.size() * 24 + 64);
    for (std::size_t i = 0; i < program.blocks.size(); ++i) {
      const Block& b = program.blocks[i];
      check_block(b, i);
      if (b.type == BlockType::None && b.m_codes.empty() && b.comment.empty() && b.statement.empty()) continue;
      line_.clear();
      if (b.type == BlockType::Dwell && control_changes(b)) {
        // A dwell's P would clash with G64's P: the mode goes on a line of its own.
        write_control(b);
        out += line_;
        out += '\n';
        line_.clear();
      }
      write_block(b);
      out += line_;
      out += '\n';
    }
    return out;
  }

 private:
  const WriteOptions& o_;
  char sign_;
  bool linuxcnc_;
  std::string line_;
  Plane plane_ = Plane::XY;
  double feed_ = 0.0;
  bool first_ = true;
  std::string control_;  ///< the path-control words written last

  /// ISO (Fanuc): G61 exact stop, G64 cutting mode without a tolerance; ISO has no exact-path
  /// mode, so LinuxCNC's G61 becomes the stricter G61. LinuxCNC: G61.1, G61, G64 [P [Q]]. A return
  /// to "not stated" has no word.
  [[nodiscard]] std::string control_words(const Block& b) const {
    switch (b.path_control) {
      case PathControl::Unstated: return {};
      case PathControl::ExactStop: return linuxcnc_ ? "G61.1" : "G61";
      case PathControl::ExactPath: return "G61";
      case PathControl::Blend: break;
    }
    std::string words = "G64";
    // Q needs a P before it, even P0 (= no blend tolerance).
    if (!linuxcnc_ || (!(b.blend_tolerance_mm > 0.0) && b.cam_tolerance_mm < 0.0)) return words;
    words += " P";
    append_number(words, b.blend_tolerance_mm, o_.decimals, '\0');
    if (b.cam_tolerance_mm < 0.0) return words;
    words += " Q";
    append_number(words, b.cam_tolerance_mm, o_.decimals, '\0');
    return words;
  }

  [[nodiscard]] bool control_changes(const Block& b) const {
    const std::string words = control_words(b);
    return !words.empty() && words != control_;
  }

  void write_control(const Block& b) {
    if (!control_changes(b)) return;
    control_ = control_words(b);
    append_word(line_, control_);
  }

  void number_word(char letter, double value) {
    line_ += ' ';
    line_ += letter;
    append_number(line_, value, o_.decimals, sign_);
  }

  void write_block(const Block& b) {
    if (b.number >= 0) {
      std::string n = std::to_string(b.number);
      if (n.size() < static_cast<std::size_t>(o_.iso_number_width))
        n.insert(0, static_cast<std::size_t>(o_.iso_number_width) - n.size(), '0');
      line_ += 'N';
      line_ += n;
    }
    if (first_ && o_.iso_modal_preamble) {
      append_word(line_, "G17 G21 G90 G94");
      plane_ = Plane::XY;
    }
    first_ = false;
    if (b.plane != plane_) {
      append_word(line_, detail::plane_gcode(b.plane));
      plane_ = b.plane;
    }
    write_control(b);
    switch (b.type) {
      case BlockType::Rapid:
      case BlockType::Linear:
      case BlockType::ArcCw:
      case BlockType::ArcCcw: write_motion(b); break;
      case BlockType::Dwell:
        append_word(line_, "G04 P");
        append_number(line_, b.dwell_s, o_.decimals, '\0');
        break;
      case BlockType::None: break;
    }
    for (const int m : b.m_codes) append_word(line_, "M" + std::to_string(m));
    if (!b.statement.empty()) append_comment(one_line(b.statement));
    if (!b.comment.empty()) append_comment(one_line(b.comment));
  }

  void write_motion(const Block& b) {
    append_word(line_, b.type == BlockType::Rapid ? "G00" : b.type == BlockType::Linear ? "G01"
                       : b.type == BlockType::ArcCw ? "G02" : "G03");
    const std::uint8_t mask = axes_to_write(b);
    for (std::size_t a = 0; a < kAxisCount; ++a)
      if (mask & axis_bit(static_cast<Axis>(a))) number_word(axis_letter(static_cast<Axis>(a)), b.end[a]);
    if (is_arc(b.type)) {
      const detail::PlaneAxes pa = detail::plane_axes(b.plane);
      for (std::size_t a = 0; a < kAxisCount; ++a)
        if (a == pa.u || a == pa.v) number_word(static_cast<char>('I' + a), exact_offset(b.start[a], b.center[a]));
    }
    const bool feed_changed = b.feed_mm_min != feed_;
    if (feed_changed && (b.type != BlockType::Rapid || b.feed_mm_min > 0.0)) {
      line_ += " F";
      detail::append_shortest(line_, b.feed_mm_min);
      feed_ = b.feed_mm_min;
    }
  }

  void append_comment(const std::string& text) {
    if (text.empty()) return;
    if (text.find(')') == std::string::npos) {
      append_word(line_, "(" + text + ")");
    } else {
      append_word(line_, ";" + text);
    }
  }
};

// ---------------------------------------------------------------------------------------------
// Heidenhain

std::string heidenhain_name(const std::string& name) {
  std::string stem = name;
  const std::size_t slash = stem.find_last_of("/\\");
  if (slash != std::string::npos) stem.erase(0, slash + 1);
  const std::size_t dot = stem.rfind('.');
  if (dot != std::string::npos && dot > 0) stem.erase(dot);
  for (char& ch : stem)
    if (!detail::is_alpha(ch) && !detail::is_digit(ch) && ch != '_' && ch != '-') ch = '_';
  return stem.empty() ? std::string("PGM") : stem;
}

class HeidenhainWriter {
 public:
  explicit HeidenhainWriter(const WriteOptions& o) : o_(o) {}

  std::string write(const Program& program) {
    const std::string name = heidenhain_name(program.name);
    std::string out;
    out.reserve(program.blocks.size() * 24 + 64);
    out_ = &out;
    start_line();
    line_ += "BEGIN PGM " + name + " MM";
    end_line();
    for (std::size_t i = 0; i < program.blocks.size(); ++i) {
      check_block(program.blocks[i], i);
      write_block(program.blocks[i]);
    }
    start_line();
    line_ += "END PGM " + name + " MM";
    end_line();
    return out;
  }

 private:
  const WriteOptions& o_;
  std::string* out_ = nullptr;
  std::string line_;
  long next_ = 0;
  double feed_ = 0.0;
  bool r0_written_ = false;
  bool has_center_ = false;
  Point center_{};
  Plane center_plane_ = Plane::XY;
  PathControl control_ = PathControl::Unstated;
  double tolerance_ = 0.0;

  /// Cycle 32 TOLERANCE is the dialect's means (T: the contour deviation the control may take when
  /// it smooths corners; a bare 32.1 restores the machine's own value). Klartext has no exact-stop
  /// or tolerance-free blending word: such a mode is written as a comment, once.
  void path_control(const Block& b) {
    if (b.path_control == control_ && (b.path_control != PathControl::Blend || b.blend_tolerance_mm == tolerance_)) return;
    control_ = b.path_control;
    tolerance_ = b.blend_tolerance_mm;
    const bool cycle = control_ == PathControl::Unstated || (control_ == PathControl::Blend && tolerance_ > 0.0);
    if (!cycle) {
      start_line();
      line_ += ";path control: " + describe_path_control(control_, tolerance_) + " - not expressible in Klartext";
      end_line();
      return;
    }
    start_line();
    line_ += "CYCL DEF 32.0 TOLERANCE";
    end_line();
    start_line();
    line_ += "CYCL DEF 32.1";
    if (control_ == PathControl::Blend) {
      line_ += " T";
      append_number(line_, tolerance_, o_.decimals, '\0');
    }
    end_line();
  }

  void start_line() {
    line_.clear();
    line_ += std::to_string(next_++);
    line_ += ' ';
  }
  void end_line() {
    *out_ += line_;
    *out_ += '\n';
  }
  void coordinate(char letter, double value) {
    line_ += ' ';
    line_ += letter;
    append_number(line_, value, o_.decimals, '+');
  }
  void comment(const Block& b) {
    const std::string text = one_line(b.comment);
    if (!text.empty()) line_ += " ;" + text;
  }
  void m_codes(const Block& b) {
    for (const int m : b.m_codes) line_ += " M" + std::to_string(m);
  }
  void m_line(const Block& b) {
    if (b.m_codes.empty()) return;
    start_line();
    line_ += 'M' + std::to_string(b.m_codes.front());
    for (std::size_t i = 1; i < b.m_codes.size(); ++i) line_ += " M" + std::to_string(b.m_codes[i]);
    end_line();
  }
  /// R0 (no radius compensation) once, on the first block that moves in its plane: in Table 4.4
  /// the tool-axis move `4 L Z+200.000 F MAX` has none, `5 L X+0.000 Y+0.000 R0 F MAX M3` has it.
  void r0(const Block& b, std::uint8_t mask) {
    if (r0_written_) return;
    const detail::PlaneAxes pa = detail::plane_axes(b.plane);
    if ((mask & (axis_bit(static_cast<Axis>(pa.u)) | axis_bit(static_cast<Axis>(pa.v)))) == 0) return;
    line_ += " R0";
    r0_written_ = true;
  }
  void feed(const Block& b) {
    if (b.feed_mm_min == feed_) return;
    line_ += " F ";
    append_number(line_, b.feed_mm_min, o_.decimals, '\0');
    feed_ = b.feed_mm_min;
  }

  void write_block(const Block& b) {
    path_control(b);
    switch (b.type) {
      case BlockType::None: write_none(b); break;
      case BlockType::Rapid:
      case BlockType::Linear: write_line(b); break;
      case BlockType::ArcCw:
      case BlockType::ArcCcw: write_arc(b); break;
      case BlockType::Dwell:
        start_line();
        line_ += "CYCL DEF 9.0 DWELL TIME";
        end_line();
        start_line();
        line_ += "CYCL DEF 9.1 DWELL ";
        append_number(line_, b.dwell_s, o_.decimals, '\0');
        comment(b);
        end_line();
        m_line(b);
        break;
    }
  }

  void write_none(const Block& b) {
    const std::string text = one_line(b.comment);
    if (!b.statement.empty()) {
      start_line();
      line_ += one_line(b.statement);
      if (!text.empty()) line_ += " ;" + text;
      end_line();
      m_line(b);
    } else if (!b.m_codes.empty()) {
      start_line();
      line_ += 'M' + std::to_string(b.m_codes.front());
      for (std::size_t i = 1; i < b.m_codes.size(); ++i) line_ += " M" + std::to_string(b.m_codes[i]);
      if (!text.empty()) line_ += " ;" + text;
      end_line();
    } else if (!text.empty()) {
      if (b.number < 0) {
        line_ = ";" + text;  // unnumbered comment line, as in thesis Tables 4.3/4.4
      } else {
        start_line();
        line_ += ";" + text;
      }
      end_line();
    }
  }

  void write_line(const Block& b) {
    start_line();
    line_ += 'L';
    std::uint8_t mask = axes_to_write(b);
    if (mask == 0) mask = axis_bit(Axis::X);  // an L needs a coordinate; this one does not move
    for (std::size_t a = 0; a < kAxisCount; ++a)
      if (mask & axis_bit(static_cast<Axis>(a))) coordinate(axis_letter(static_cast<Axis>(a)), b.end[a]);
    r0(b, mask);
    if (b.type == BlockType::Rapid) {
      line_ += " F MAX";
    } else {
      feed(b);
    }
    m_codes(b);
    comment(b);
    end_line();
  }

  void write_arc(const Block& b) {
    const detail::PlaneAxes pa = detail::plane_axes(b.plane);
    if (!has_center_ || center_plane_ != b.plane || center_[pa.u] != b.center[pa.u] || center_[pa.v] != b.center[pa.v]) {
      start_line();
      line_ += "CC";
      coordinate(axis_letter(static_cast<Axis>(pa.u)), b.center[pa.u]);
      coordinate(axis_letter(static_cast<Axis>(pa.v)), b.center[pa.v]);
      end_line();
      has_center_ = true;
      center_plane_ = b.plane;
      center_ = b.center;
    }
    start_line();
    line_ += 'C';
    std::uint8_t mask = axes_to_write(b);
    if (mask == 0)
      mask = static_cast<std::uint8_t>(axis_bit(static_cast<Axis>(pa.u)) | axis_bit(static_cast<Axis>(pa.v)));
    for (std::size_t a = 0; a < kAxisCount; ++a)
      if (mask & axis_bit(static_cast<Axis>(a))) coordinate(axis_letter(static_cast<Axis>(a)), b.end[a]);
    line_ += b.type == BlockType::ArcCcw ? " DR+" : " DR-";
    r0(b, mask);
    feed(b);
    m_codes(b);
    comment(b);
    end_line();
  }
};

}  // namespace

std::string write_iso(const Program& program, const WriteOptions& options) {
  check_options(options);
  return IsoWriter(options, Dialect::Iso).write(program);
}

std::string write_linuxcnc(const Program& program, const WriteOptions& options) {
  check_options(options);
  return IsoWriter(options, Dialect::LinuxCnc).write(program);
}

std::string write_heidenhain(const Program& program, const WriteOptions& options) {
  check_options(options);
  return HeidenhainWriter(options).write(program);
}

std::string write_program(const Program& program, const WriteOptions& options) {
  switch (program.dialect) {
    case Dialect::Heidenhain: return write_heidenhain(program, options);
    case Dialect::LinuxCnc: return write_linuxcnc(program, options);
    case Dialect::Iso: break;
  }
  return write_iso(program, options);
}

bool can_state(Dialect dialect, PathControl mode, double blend_tolerance_mm) noexcept {
  switch (dialect) {
    case Dialect::LinuxCnc: return true;
    case Dialect::Iso: return mode != PathControl::Blend || !(blend_tolerance_mm > 0.0);
    case Dialect::Heidenhain: return mode == PathControl::Unstated || (mode == PathControl::Blend && blend_tolerance_mm > 0.0);
  }
  return false;
}

}  // namespace servotwin::motion
