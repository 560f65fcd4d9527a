#include "gcode_common.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

#include "servotwin/core/error.hpp"

namespace servotwin::motion::detail {

const char* plane_name(Plane p) noexcept {
  switch (p) {
    case Plane::XY: return "XY";
    case Plane::ZX: return "ZX";
    case Plane::YZ: return "YZ";
  }
  return "XY";
}

const char* plane_gcode(Plane p) noexcept {
  switch (p) {
    case Plane::XY: return "G17";
    case Plane::ZX: return "G18";
    case Plane::YZ: return "G19";
  }
  return "G17";
}

bool equals_upper(std::string_view text, std::string_view upper_literal) noexcept {
  if (text.size() != upper_literal.size()) return false;
  for (std::size_t i = 0; i < text.size(); ++i)
    if (to_upper(text[i]) != upper_literal[i]) return false;
  return true;
}

std::string_view trim(std::string_view text) noexcept {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

bool LineSplitter::next(std::string_view& line) noexcept {
  if (pos_ >= text_.size()) return false;
  const std::size_t newline = text_.find('\n', pos_);
  const std::size_t end = newline == std::string_view::npos ? text_.size() : newline;
  line = text_.substr(pos_, end - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = newline == std::string_view::npos ? text_.size() : newline + 1;
  ++number_;
  return true;
}

std::size_t reserve_hint(std::string_view text) noexcept {
  const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  return std::min(lines, text.size() / 3 + 1);
}

std::string format_number(double value) {
  std::array<char, 400> buf{};
  // Plain decimals for people unless the magnitude calls for an exponent.
  const double m = std::fabs(value);
  const bool plain = m == 0.0 || (m >= 1e-9 && m < 1e15);
  const auto r = plain ? std::to_chars(buf.data(), buf.data() + buf.size(), value, std::chars_format::fixed)
                       : std::to_chars(buf.data(), buf.data() + buf.size(), value);
  return r.ec == std::errc{} ? std::string(buf.data(), r.ptr) : std::string("?");
}

std::string format_computed(double value) {
  std::array<char, 64> buf{};
  const int n = std::snprintf(buf.data(), buf.size(), "%.6g", value);
  return n > 0 ? std::string(buf.data(), static_cast<std::size_t>(n)) : std::string("?");
}

void Reporter::error(std::size_t line, std::size_t column, const std::string& message) const {
  throw core::InputError(core::SourceLocation{std::string(source_), line, column, {}}, message);
}

void Reporter::unsupported(std::size_t line, std::size_t column, const std::string& message) {
  if (!lenient_) error(line, column, message);
  if (warnings_.size() < kMaxWarnings) {
    warnings_.push_back({line, column, message + " (ignored)"});
  } else if (warnings_.size() == kMaxWarnings) {
    warnings_.push_back({line, column, "more than " + std::to_string(kMaxWarnings) + " warnings; the rest are not listed"});
  }
}

std::string_view Cursor::take_letters() noexcept {
  const std::size_t begin = pos;
  while (pos < text.size() && is_alpha(text[pos])) ++pos;
  return text.substr(begin, pos - begin);
}

ScannedNumber scan_number(Cursor& cursor) noexcept {
  ScannedNumber n;
  cursor.skip_blanks();
  const std::string_view s = cursor.text;
  std::size_t pos = cursor.pos;
  const std::size_t begin = pos;
  if (pos < s.size() && (s[pos] == '+' || s[pos] == '-')) {
    n.negative = s[pos] == '-';
    ++pos;
  }
  const std::size_t int_begin = pos;
  while (pos < s.size() && is_digit(s[pos])) ++pos;
  n.digits = s.substr(int_begin, pos - int_begin);
  if (pos < s.size() && s[pos] == '.') {
    n.has_point = true;
    ++pos;
    const std::size_t frac_begin = pos;
    while (pos < s.size() && is_digit(s[pos])) ++pos;
    n.fraction = s.substr(frac_begin, pos - frac_begin);
  }
  // An exponent ("1e30") is not part of an RS274NGC or Heidenhain number; read as the number 1
  // followed by a word E30 it would silently turn F1e30 into F1 (issue 27 §3).
  const auto digit_at = [&](std::size_t i) { return i < s.size() && is_digit(s[i]); };
  const bool exponent = pos < s.size() && (s[pos] == 'e' || s[pos] == 'E') &&
                        (digit_at(pos + 1) || ((pos + 1 < s.size() && (s[pos + 1] == '+' || s[pos + 1] == '-')) && digit_at(pos + 2)));
  if (exponent && !(n.digits.empty() && n.fraction.empty())) {
    pos += 2;
    while (pos < s.size() && is_digit(s[pos])) ++pos;
    n.status = NumberStatus::Malformed;
    n.exponent = true;
    cursor.pos = pos;
    return n;
  }
  const bool continues = pos < s.size() && (s[pos] == '.' || s[pos] == '+' || s[pos] == '-');
  if (n.digits.empty() && n.fraction.empty()) {
    n.status = pos == begin ? NumberStatus::Missing : NumberStatus::Malformed;
    cursor.pos = pos;
    return n;
  }
  if (continues) {
    // "1.2.3", "5-3": skip the whole run so the caller can point at it.
    while (pos < s.size() && (is_digit(s[pos]) || s[pos] == '.' || s[pos] == '+' || s[pos] == '-')) ++pos;
    n.status = NumberStatus::Malformed;
    cursor.pos = pos;
    return n;
  }
  cursor.pos = pos;
  // from_chars takes no '+'; the '-' stays in the text.
  const char* first = s.data() + (n.negative ? int_begin - 1 : int_begin);
  const char* last = s.data() + pos;
  double value = 0.0;
  const auto r = std::from_chars(first, last, value, std::chars_format::fixed);
  if (r.ec == std::errc::result_out_of_range) {
    // Too large, or so small it underflows: only the first is an error.
    const bool nonzero_integer_part = n.digits.find_first_not_of('0') != std::string_view::npos;
    if (nonzero_integer_part) {
      n.status = NumberStatus::OutOfRange;
      return n;
    }
    value = 0.0;
  } else if (r.ec != std::errc{} || r.ptr != last) {
    n.status = NumberStatus::Malformed;
    return n;
  }
  if (!std::isfinite(value) || std::fabs(value) > kMaxMagnitude) {
    n.status = NumberStatus::OutOfRange;
    return n;
  }
  n.value = positive_zero(value);
  n.status = NumberStatus::Ok;
  return n;
}

std::string word_text(std::string_view line, std::size_t start) {
  std::size_t pos = std::min(start, line.size());
  while (pos < line.size() && is_alpha(line[pos])) ++pos;
  const auto in_number = [&](std::size_t i) {
    if (!is_alpha(line[i])) return true;
    // An exponent after digits ("F1e30") belongs to the (malformed) number it follows.
    const bool e = (line[i] == 'e' || line[i] == 'E') && i > start && is_digit(line[i - 1]);
    const std::size_t d = i + 1 < line.size() && (line[i + 1] == '+' || line[i + 1] == '-') ? i + 2 : i + 1;
    return e && d < line.size() && is_digit(line[d]);
  };
  while (pos < line.size() && !is_blank(line[pos]) && in_number(pos) && line[pos] != ';' && line[pos] != '(') ++pos;
  if (pos == start && pos < line.size()) ++pos;
  return printable(line.substr(start, pos - start));
}

std::string number_problem(const ScannedNumber& number, std::string_view what, std::string_view word) {
  switch (number.status) {
    case NumberStatus::Missing: return "expected a number after '" + std::string(what) + "'";
    case NumberStatus::OutOfRange:
      return "number out of range in '" + std::string(word) + "' (magnitude must be <= 1e9)";
    case NumberStatus::Malformed:
    case NumberStatus::Ok: break;
  }
  if (number.exponent)
    return "malformed number in '" + std::string(word) +
           "': G-code numbers have no exponent (write the plain decimal, e.g. 0.001 for 1e-3)";
  return "malformed number in '" + std::string(word) + "' (expected a plain decimal such as 12, -0.5 or +3.25)";
}

void check_tolerances(const ParseOptions& options) {
  const auto bad = [](double v) { return !std::isfinite(v) || v < 0.0 || v > kMaxMagnitude; };
  if (bad(options.arc_tolerance_abs_mm))
    throw core::InputError(core::SourceLocation{{}, 0, 0, "arc_tolerance_abs_mm"},
                           "arc tolerance must be finite and in [0, 1e9] mm, got " + format_number(options.arc_tolerance_abs_mm));
  if (bad(options.arc_tolerance_rel))
    throw core::InputError(core::SourceLocation{{}, 0, 0, "arc_tolerance_rel"},
                           "relative arc tolerance must be finite and >= 0, got " + format_number(options.arc_tolerance_rel));
  if (!within_limits(options.start))
    throw core::InputError(core::SourceLocation{{}, 0, 0, "start"}, "start position must be finite and within +-1e9 mm");
}

double rounding_slack(const Point& a, const Point& b, const Point& c) noexcept {
  double m = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) m = std::max({m, std::fabs(a[i]), std::fabs(b[i]), std::fabs(c[i])});
  return 32.0 * std::numeric_limits<double>::epsilon() * m;
}

bool within_limits(const Point& p) noexcept {
  return std::all_of(p.begin(), p.end(), [](double v) { return std::isfinite(v) && std::fabs(v) <= kMaxMagnitude; });
}

std::string center_from_radius(Block& block, double signed_radius, const ArcTolerance& tolerance) {
  const PlaneAxes pa = plane_axes(block.plane);
  const double du = block.end[pa.u] - block.start[pa.u];
  const double dv = block.end[pa.v] - block.start[pa.v];
  const double chord = std::hypot(du, dv);
  if (chord == 0.0)
    return "an arc by radius R needs an end point different from the start point in the " +
           std::string(plane_name(block.plane)) + " plane (program a full circle by its centre)";
  const double r = std::fabs(signed_radius);
  const double slack = rounding_slack(block.start, block.end, block.start);
  if (r <= slack) return "arc radius R must not be 0";
  const double half = 0.5 * chord;
  double h = 0.0;
  if (half > r) {
    const double tol = std::max(tolerance.abs_mm, tolerance.rel * r) + slack;
    if (half - r > tol)
      return "arc radius " + format_number(r) + " mm is smaller than half the distance to the end point (" +
             format_number(half) + " mm)";
  } else {
    h = std::sqrt((r - half) * (r + half));
  }
  const bool ccw = block.type == BlockType::ArcCcw;
  const double side = (ccw ? 1.0 : -1.0) * (signed_radius > 0.0 ? 1.0 : -1.0);
  block.center = block.start;
  block.center[pa.u] = block.start[pa.u] + 0.5 * du - side * h * dv / chord;
  block.center[pa.v] = block.start[pa.v] + 0.5 * dv + side * h * du / chord;
  return {};
}

std::string check_arc_radius(const Block& block, const ArcTolerance& tolerance) {
  const PlaneAxes pa = plane_axes(block.plane);
  const double rs = std::hypot(block.start[pa.u] - block.center[pa.u], block.start[pa.v] - block.center[pa.v]);
  const double re = std::hypot(block.end[pa.u] - block.center[pa.u], block.end[pa.v] - block.center[pa.v]);
  const double slack = rounding_slack(block.start, block.end, block.center);
  if (rs <= slack) return "arc centre coincides with the start point (radius 0)";
  const double tol = std::max(tolerance.abs_mm, tolerance.rel * std::max(rs, re)) + slack;
  if (std::fabs(rs - re) > tol)
    return "arc does not close: radius " + format_computed(rs) + " mm at the start, " + format_computed(re) +
           " mm at the end (difference above the tolerance of " + format_computed(tol) + " mm)";
  return {};
}

namespace {
constexpr std::size_t kNumberBuffer = 512;  // fixed text of any double fits (largest ~330 characters)

void append_signed(std::string& out, const char* first, const char* last, char sign) {
  if (*first != '-' && sign != '\0') out += sign;
  out.append(first, last);
}
}  // namespace

void append_number(std::string& out, double value, int decimals, char sign) {
  value = positive_zero(value);
  std::array<char, kNumberBuffer> buf{};
  const auto fixed = std::to_chars(buf.data(), buf.data() + buf.size(), value, std::chars_format::fixed, decimals);
  if (fixed.ec == std::errc{}) {
    double back = 0.0;
    const auto r = std::from_chars(buf.data(), fixed.ptr, back, std::chars_format::fixed);
    if (r.ec == std::errc{} && back == value) {
      append_signed(out, buf.data(), fixed.ptr, sign);
      return;
    }
  }
  const auto shortest = std::to_chars(buf.data(), buf.data() + buf.size(), value, std::chars_format::fixed);
  if (shortest.ec != std::errc{}) {  // cannot happen for finite values and this buffer
    out += "0";
    return;
  }
  append_signed(out, buf.data(), shortest.ptr, sign);
  // Pad to the minimum number of decimals (the same number, so still exact).
  const std::string_view text(buf.data(), static_cast<std::size_t>(shortest.ptr - buf.data()));
  const std::size_t point = text.find('.');
  const std::size_t have = point == std::string_view::npos ? 0 : text.size() - point - 1;
  if (decimals > 0 && have < static_cast<std::size_t>(decimals)) {
    if (point == std::string_view::npos) out += '.';
    out.append(static_cast<std::size_t>(decimals) - have, '0');
  }
}

void append_shortest(std::string& out, double value) {
  value = positive_zero(value);
  std::array<char, kNumberBuffer> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), value, std::chars_format::fixed);
  if (r.ec != std::errc{}) {
    out += "0";
    return;
  }
  out.append(buf.data(), r.ptr);
}

void state_path_control(Program& program, std::optional<PathControl> mode, double blend_tolerance_mm) {
  const auto fail = [](const std::string& message) {
    throw core::InputError(core::SourceLocation{{}, 0, 0, "path_control"}, message);
  };
  if (!(blend_tolerance_mm >= 0.0 && blend_tolerance_mm <= kMaxMagnitude))
    fail("blend tolerance must be in [0, 1e9] mm, got " + format_number(blend_tolerance_mm));
  const PathControl m = mode.value_or(program.dialect == Dialect::Heidenhain ? PathControl::Unstated : PathControl::ExactStop);
  if (m != PathControl::Blend && blend_tolerance_mm > 0.0) fail("a blend tolerance needs the blend mode");
  if (!can_state(program.dialect, m, blend_tolerance_mm)) {
    if (program.dialect == Dialect::Heidenhain)
      fail("Heidenhain Klartext cannot state " + describe_path_control(m, blend_tolerance_mm) +
           ": it has Cycle 32 TOLERANCE (blend with a tolerance) or the machine's own setting");
    fail("ISO G64 takes no tolerance: write the program in the LinuxCNC dialect for G64 P<tolerance>");
  }
  for (Block& b : program.blocks) {
    b.path_control = m;
    b.blend_tolerance_mm = m == PathControl::Blend ? blend_tolerance_mm : 0.0;
  }
}

}  // namespace servotwin::motion::detail
