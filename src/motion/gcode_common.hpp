#pragma once
// Pieces shared by the ISO and Heidenhain readers and the writers: line splitting, a cursor with a
// strict decimal-number scanner, diagnostics with source locations, and arc geometry. Private to
// the motion module.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::motion::detail {

/// Largest magnitude of a coordinate, offset or radius [mm], feed [mm/min] or dwell [s]: up to
/// here a double still resolves 1 um (2^53 um ~ 9e9 mm), and no sum or product of such values
/// can overflow.
inline constexpr double kMaxMagnitude = 1e9;
inline constexpr double kMmPerInch = 25.4;
inline constexpr std::size_t kMaxWarnings = 1000;

/// The two in-plane axes (u, v: counterclockwise from u to v seen from +n) and the normal n.
struct PlaneAxes {
  std::size_t u;
  std::size_t v;
  std::size_t n;
};
constexpr PlaneAxes plane_axes(Plane p) noexcept {
  switch (p) {
    case Plane::XY: return {0, 1, 2};
    case Plane::ZX: return {2, 0, 1};
    case Plane::YZ: return {1, 2, 0};
  }
  return {0, 1, 2};
}
const char* plane_name(Plane p) noexcept;
/// "G17", "G18", "G19".
const char* plane_gcode(Plane p) noexcept;

constexpr bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
constexpr bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }
constexpr bool is_alpha(char c) noexcept { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }
constexpr char to_upper(char c) noexcept { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c; }
/// Case-insensitive comparison with an upper-case literal.
bool equals_upper(std::string_view text, std::string_view upper_literal) noexcept;
std::string_view trim(std::string_view text) noexcept;

/// Splits text into lines at '\n' (a trailing '\r' is removed), numbering them from 1.
class LineSplitter {
 public:
  explicit LineSplitter(std::string_view text) noexcept : text_(text) {}
  bool next(std::string_view& line) noexcept;
  [[nodiscard]] std::size_t line_number() const noexcept { return number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

/// Blocks to reserve for a text: its line count, but no more than a program of 3-byte lines
/// ("M3\n") could hold, so blank-line padding cannot make a reader over-allocate.
std::size_t reserve_hint(std::string_view text) noexcept;

/// Text of a word for messages (core::printable), cut after a word's usual length.
inline std::string printable(std::string_view text, std::size_t max_chars = 24) { return core::printable(text, max_chars); }
/// Shortest round-trip decimal text of a number, for messages.
std::string format_number(double value);
/// A computed value (radius, tolerance) for a message: 6 significant digits.
std::string format_computed(double value);

/// A value word of a line (X, I, F, R, ...): raw value in program units and where it stood.
struct ValueWord {
  bool present = false;
  double value = 0.0;
  std::size_t column = 0;
};

/// Reports errors (core::InputError with file:line:column) and lenient-mode warnings.
class Reporter {
 public:
  Reporter(std::string_view source_name, bool lenient, std::vector<Diagnostic>& warnings) noexcept
      : source_(source_name), lenient_(lenient), warnings_(warnings) {}
  [[noreturn]] void error(std::size_t line, std::size_t column, const std::string& message) const;
  /// An unknown word or unsupported feature: an error, or in lenient mode a warning.
  void unsupported(std::size_t line, std::size_t column, const std::string& message);
  [[nodiscard]] bool lenient() const noexcept { return lenient_; }

 private:
  std::string_view source_;
  bool lenient_;
  std::vector<Diagnostic>& warnings_;
};

/// Position within one line; columns are 1-based byte offsets.
struct Cursor {
  std::string_view text;
  std::size_t pos = 0;
  [[nodiscard]] bool at_end() const noexcept { return pos >= text.size(); }
  [[nodiscard]] char peek() const noexcept { return pos < text.size() ? text[pos] : '\0'; }
  [[nodiscard]] std::size_t column() const noexcept { return pos + 1; }
  void skip_blanks() noexcept {
    while (pos < text.size() && is_blank(text[pos])) ++pos;
  }
  /// Letters from pos (ASCII), advancing past them.
  std::string_view take_letters() noexcept;
};

enum class NumberStatus : std::uint8_t { Ok, Missing, Malformed, OutOfRange };

/// A plain decimal number: optional blanks, optional sign, digits with at most one '.', at least
/// one digit, no exponent. Anything else (nan, inf, 1e5, 1.2.3, a sign alone) is not a number.
struct ScannedNumber {
  NumberStatus status = NumberStatus::Missing;
  double value = 0.0;
  bool negative = false;
  bool has_point = false;
  bool exponent = false;      ///< Malformed because an exponent (e30, E-3) follows the digits
  std::string_view digits;    ///< integer-part digits
  std::string_view fraction;  ///< digits after the point
};
/// Scans a number at the cursor and advances past it (also on error, past the offending text).
ScannedNumber scan_number(Cursor& cursor) noexcept;
/// The text of a word starting at `start` for messages: up to the next blank, ';' or '('.
std::string word_text(std::string_view line, std::size_t start);
/// Message for a number that failed to scan after `what` (e.g. "X").
std::string number_problem(const ScannedNumber& number, std::string_view what, std::string_view word);

/// Geometry of an arc being built: checks and centre computation shared by both dialects.
struct ArcTolerance {
  double abs_mm;
  double rel;
};
/// Validates ParseOptions' tolerances (finite, >= 0, abs <= 1e9).
void check_tolerances(const ParseOptions& options);
/// Slack for rounding errors in arc checks: a few ulps of the largest coordinate involved.
double rounding_slack(const Point& a, const Point& b, const Point& c) noexcept;
/// Centre of an arc by its signed radius (R > 0: at most 180 degrees, R < 0: more). Fills
/// block.center; returns an error message or an empty string.
std::string center_from_radius(Block& block, double signed_radius, const ArcTolerance& tolerance);
/// Checks an arc whose block.center is set: non-zero radius, start and end radius equal within the
/// tolerance. Returns an error message or an empty string.
std::string check_arc_radius(const Block& block, const ArcTolerance& tolerance);
/// True when every coordinate of a point is within +-kMaxMagnitude.
bool within_limits(const Point& p) noexcept;
/// Turns -0.0 into +0.0 (so writers never print "-0.000").
constexpr double positive_zero(double v) noexcept { return v + 0.0; }

/// Gives every block of a generated program the path-control mode `mode` (when empty: the dialect's
/// default, exact stop for ISO and LinuxCNC, the machine's setting for Heidenhain, which has no
/// exact-stop word). core::InputError (field "path_control") when the dialect cannot state it or
/// the tolerance is negative or not finite.
void state_path_control(Program& program, std::optional<PathControl> mode, double blend_tolerance_mm);

/// Appends a number by the writers' rule (see WriteOptions): `decimals` decimals when exact, the
/// shortest exact fixed text otherwise. sign: '\0' = only '-', '+' = always a sign, ' ' = a blank
/// for positive numbers.
void append_number(std::string& out, double value, int decimals, char sign);
/// Appends the shortest exact fixed-notation text of a number.
void append_shortest(std::string& out, double value);

}  // namespace servotwin::motion::detail
