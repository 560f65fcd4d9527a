// Identification-program generator (thesis Tables 3.2, 4.3, 4.4); the rules are documented in
// identification_program.hpp.
#include "servotwin/motion/identification_program.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>

#include "gcode_common.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::motion {

IdentificationOptions identification_defaults(IdentificationSet set) {
  IdentificationOptions o;
  o.set = set;
  switch (set) {
    case IdentificationSet::Standard:  // Table 3.2: 200 moves within +-10 mm, F12000 (200 mm/s)
      o.moves = 200;
      o.range_mm = 10.0;
      o.feed_mm_min = 12000.0;
      break;
    case IdentificationSet::Low:  // Table 4.3 / section 4.3.3: travel up to 30 um, F15000 (250 mm/s)
      o.moves = 200;
      o.range_mm = 0.03;
      o.feed_mm_min = 15000.0;
      break;
    case IdentificationSet::High:  // Table 4.4 / section 4.3.3: travel up to 10 mm, F15000
      o.moves = 100;
      o.range_mm = 10.0;
      o.feed_mm_min = 15000.0;
      break;
  }
  return o;
}

namespace {

using Offsets = std::array<long long, kAxisCount>;  // per axis, in output steps from the centre

[[noreturn]] void invalid(const char* field, const std::string& message) {
  throw core::InputError(core::SourceLocation{{}, 0, 0, field}, message);
}

const char* set_name(IdentificationSet s) {
  switch (s) {
    case IdentificationSet::Standard: return "standard";
    case IdentificationSet::Low: return "low-speed";
    case IdentificationSet::High: return "high-speed";
  }
  return "standard";
}

/// Validated options in integer output steps.
struct Grid {
  double scale = 1000.0;  ///< steps per mm
  long long range = 0;    ///< K: half-width in steps
  Offsets center{};       ///< centre in steps
  std::uint8_t mask = 0;  ///< selected axes
};

Grid validate(const IdentificationOptions& o) {
  if (o.axes.empty()) invalid("axes", "select at least one axis");
  Grid g;
  for (const Axis a : o.axes) {
    if (static_cast<std::size_t>(a) >= kAxisCount) invalid("axes", "unknown axis");
    if (g.mask & axis_bit(a)) invalid("axes", std::string("axis ") + axis_letter(a) + " selected twice");
    g.mask = static_cast<std::uint8_t>(g.mask | axis_bit(a));
  }
  if (o.moves == 0) invalid("moves", "the number of random moves must be at least 1");
  if (o.moves > 100'000'000) invalid("moves", "at most 1e8 random moves");
  if (o.decimals < 0 || o.decimals > 9) invalid("decimals", "decimals must be in 0..9, got " + std::to_string(o.decimals));
  if (!(o.feed_mm_min > 0.0 && o.feed_mm_min <= detail::kMaxMagnitude))
    invalid("feed_mm_min", "feed must be in (0, 1e9] mm/min, got " + detail::format_number(o.feed_mm_min));
  g.scale = std::pow(10.0, o.decimals);  // exact: 10^k for k <= 22 is a double
  const double step = 1.0 / g.scale;
  const double max_steps = std::min(detail::kMaxMagnitude * g.scale, 9007199254740992.0 /* 2^53 */);
  if (!(std::isfinite(o.range_mm) && o.range_mm >= step * (1.0 - 1e-9)))
    invalid("range_mm", "range must be at least one output step (" + detail::format_number(step) + " mm), got " +
                            detail::format_number(o.range_mm));
  const double k = o.range_mm * g.scale;
  if (k > max_steps) invalid("range_mm", "range too large (at most 1e9 mm and 2^53 output steps)");
  const double nearest = std::round(k);
  g.range = static_cast<long long>(std::fabs(k - nearest) <= 1e-9 * std::max(1.0, k) ? nearest : std::floor(k));
  for (std::size_t a = 0; a < kAxisCount; ++a) {
    const double c = o.center[a] * g.scale;
    if (!std::isfinite(c) || std::fabs(c) + static_cast<double>(g.range) > max_steps)
      invalid("center", std::string("centre ") + axis_letter(static_cast<Axis>(a)) + " with the range must stay within +-1e9 mm");
    const double rc = std::round(c);
    const bool selected = (g.mask & axis_bit(static_cast<Axis>(a))) != 0;  // others only size BLK FORM
    if (selected && std::fabs(c - rc) > 1e-6 + 4.0 * std::numeric_limits<double>::epsilon() * std::fabs(c))
      invalid("center", std::string("centre ") + axis_letter(static_cast<Axis>(a)) + " = " + detail::format_number(o.center[a]) +
                            " mm is not a multiple of the output step " + detail::format_number(step) + " mm");
    g.center[a] = static_cast<long long>(rc);
  }
  if (o.name.empty() || !std::all_of(o.name.begin(), o.name.end(), [](char ch) {
        return detail::is_alpha(ch) || detail::is_digit(ch) || ch == '_' || ch == '-';
      }))
    invalid("name", "program name must be non-empty and use only letters, digits, '_' and '-', got '" +
                        detail::printable(o.name) + "'");
  return g;
}

/// The random part: uniform offsets in [-K, K] from the top 53 bits of mt19937_64 outputs.
class Draw {
 public:
  Draw(std::uint64_t seed, long long range) : rng_(seed), range_(static_cast<double>(range)) {}

  /// One offset different from `previous` and from `other` (when given).
  long long next(long long previous, std::optional<long long> other) {
    while (true) {
      const double u = static_cast<double>(rng_() >> 11U) * 0x1.0p-53;  // [0, 1), 53 bits
      const double s = 2.0 * u - 1.0;                                      // exact
      const long long k = std::llround(range_ * s);                        // one rounding, then half away
      if (k != previous && (!other || k != *other)) return k;
    }
  }

 private:
  std::mt19937_64 rng_;
  double range_;
};

/// Offsets of every move after the positioning, per the set's shape.
std::vector<Offsets> move_offsets(const IdentificationOptions& o, const Grid& g) {
  const long long K = g.range;
  const std::size_t m = o.moves;
  std::vector<Offsets> moves;
  moves.reserve(m + 6);
  Offsets previous{};  // at the centre after positioning
  const auto push_all = [&](long long v) {
    Offsets t{};
    t.fill(v);
    moves.push_back(t);
    previous = t;
  };
  Draw draw(o.seed, K);
  const bool sweep = o.set != IdentificationSet::Standard;
  if (sweep) {
    push_all(-K);
    push_all(K);
  }
  const bool mirror = o.set == IdentificationSet::High;
  const std::size_t mirrored = mirror ? m / 2 : 0;
  const std::size_t drawn = m - mirrored;
  std::vector<Offsets> random(drawn);
  for (std::size_t i = 0; i < drawn; ++i) {
    for (std::size_t a = 0; a < kAxisCount; ++a) {
      if (!(g.mask & axis_bit(static_cast<Axis>(a)))) {
        random[i][a] = 0;
        continue;
      }
      // The move after this one must differ from it as well.
      std::optional<long long> next_target;
      if (i + 1 == drawn) {
        if (mirrored == 0) {
          next_target = mirror ? -K : 0;  // High: the closing sweep; otherwise back to the centre
        } else if (drawn == mirrored) {
          next_target = 0;  // followed by its own mirror image -k: k must not be 0
        } else {
          next_target = -random[mirrored - 1][a];  // followed by the mirror of element mirrored-1
        }
      }
      random[i][a] = draw.next(previous[a], next_target);
      previous[a] = random[i][a];
    }
  }
  for (const Offsets& r : random) moves.push_back(r);
  for (std::size_t j = 0; j < mirrored; ++j) {
    Offsets t = random[mirrored - 1 - j];
    for (long long& v : t) v = -v;
    moves.push_back(t);
  }
  if (mirror) {
    push_all(-K);
    push_all(K);
  }
  push_all(0);
  for (Offsets& t : moves)
    for (std::size_t a = 0; a < kAxisCount; ++a)
      if (!(g.mask & axis_bit(static_cast<Axis>(a)))) t[a] = 0;
  return moves;
}

std::string describe(const IdentificationOptions& o) {
  std::string axes;
  for (const Axis a : o.axes) axes += axis_letter(a);
  std::string s = "Rapid identification, " + std::string(set_name(o.set)) + " set: " + std::to_string(o.moves) +
                  " random moves of " + axes + " within +-";
  detail::append_number(s, o.range_mm, 3, '\0');
  s += " mm at F";
  detail::append_shortest(s, o.feed_mm_min);
  s += ", seed " + std::to_string(o.seed);
  return s;
}

}  // namespace

Program make_identification_program(const IdentificationOptions& o) {
  const Grid g = validate(o);
  const std::vector<Offsets> moves = move_offsets(o, g);
  const auto position = [&](const Offsets& off) {
    Point p{};  // axes not selected stay where the program starts
    for (std::size_t a = 0; a < kAxisCount; ++a)
      if (g.mask & axis_bit(static_cast<Axis>(a)))
        p[a] = detail::positive_zero(static_cast<double>(g.center[a] + off[a]) / g.scale);
    return p;
  };
  const Point centre = position(Offsets{});

  Program program;
  program.name = o.name;
  program.dialect = o.dialect;
  program.blocks.reserve(moves.size() + 8);
  Point at = program.start;
  const bool iso = o.dialect != Dialect::Heidenhain;
  long number = iso ? 0 : 1;
  const long step = iso ? 10 : 1;
  const auto add = [&](Block b) {
    b.start = at;
    if (b.type == BlockType::None) b.end = at;
    b.center = b.start;
    at = b.end;
    b.number = number;
    number += step;
    program.blocks.push_back(std::move(b));
  };
  const auto none_statement = [&](std::string statement) {
    Block b;
    b.statement = std::move(statement);
    add(std::move(b));
  };

  if (!iso) {
    Block comment;
    comment.comment = describe(o);
    comment.start = comment.end = comment.center = at;
    program.blocks.push_back(std::move(comment));  // unnumbered, as in Tables 4.3/4.4
    std::string lo = "BLK FORM 0.1 Z";
    std::string hi = "BLK FORM 0.2";
    for (std::size_t a = 0; a < kAxisCount; ++a) {
      const char letter = axis_letter(static_cast<Axis>(a));
      lo += std::string(" ") + letter;
      detail::append_number(lo, o.center[a] - o.range_mm, 3, '+');
      hi += std::string(" ") + letter;
      detail::append_number(hi, o.center[a] + o.range_mm, 3, '+');
    }
    none_statement(lo);
    none_statement(hi);
    none_statement("TOOL CALL 0 Z");
  }

  // Positioning at the rapid feed: ISO as in Table 3.2 (G00 carrying F), Heidenhain as in Tables
  // 4.3/4.4 (plane axes with R0 F MAX M3, then the tool axis when it is identified too).
  const std::uint8_t plane_mask = static_cast<std::uint8_t>(g.mask & (axis_bit(Axis::X) | axis_bit(Axis::Y)));
  const std::uint8_t z_mask = static_cast<std::uint8_t>(g.mask & axis_bit(Axis::Z));
  const auto rapid = [&](std::uint8_t mask, bool spindle) {
    Block b;
    b.type = BlockType::Rapid;
    b.axes = mask;
    b.end = at;
    for (std::size_t a = 0; a < kAxisCount; ++a)
      if (mask & axis_bit(static_cast<Axis>(a))) b.end[a] = centre[a];
    b.feed_mm_min = iso ? o.feed_mm_min : 0.0;
    if (spindle) b.m_codes.push_back(3);
    add(std::move(b));
  };
  if (iso) {
    rapid(g.mask, false);
  } else {
    if (plane_mask != 0) rapid(plane_mask, true);
    if (z_mask != 0) rapid(z_mask, plane_mask == 0);
  }

  for (const Offsets& off : moves) {
    Block b;
    b.type = BlockType::Linear;
    b.axes = g.mask;
    b.end = position(off);
    b.feed_mm_min = o.feed_mm_min;
    add(std::move(b));
  }
  Block end;
  end.m_codes.push_back(30);
  add(std::move(end));
  detail::state_path_control(program, o.path_control, o.blend_tolerance_mm);
  return program;
}

}  // namespace servotwin::motion
