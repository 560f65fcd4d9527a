#pragma once
/// \file
/// The dialect-independent program model: what the G-code readers produce, the identification
/// generator builds, the writers print and the interpolator consumes. All lengths are in mm
/// (inch programs are converted on reading), all positions absolute, feeds in mm/min.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace servotwin::motion {

/// Linear axes a program may move.
enum class Axis : std::uint8_t { X = 0, Y = 1, Z = 2 };
inline constexpr std::size_t kAxisCount = 3;
/// Position of all axes [mm].
using Point = std::array<double, kAxisCount>;
/// Upper-case letter of an axis ('X').
char axis_letter(Axis a) noexcept;
/// Lower-case name used in CSV columns ("x").
const char* axis_name(Axis a) noexcept;
/// Bit of an axis in an axis mask.
constexpr std::uint8_t axis_bit(Axis a) noexcept { return static_cast<std::uint8_t>(1U << static_cast<unsigned>(a)); }

enum class Dialect { Iso, Heidenhain };

enum class BlockType : std::uint8_t {
  Rapid,   ///< G00 / Heidenhain `F MAX`: straight line at the machine's rapid feed
  Linear,  ///< G01 / Heidenhain `L`
  ArcCw,   ///< G02 / Heidenhain `C ... DR-`
  ArcCcw,  ///< G03 / Heidenhain `C ... DR+`
  Dwell,   ///< G04: wait `dwell_s` seconds
  None     ///< no motion (M codes, BLK FORM, TOOL CALL, comments kept for rewriting)
};

/// Plane of circular interpolation (G17/G18/G19). Arcs turn about the third axis; in G18 the
/// ISO convention is used (the plane is Z-X, so clockwise is seen from +Y).
enum class Plane : std::uint8_t { XY, ZX, YZ };

/// One executable block (a line may hold at most one motion).
struct Block {
  BlockType type = BlockType::None;
  Point start{};               ///< position before the block [mm]
  Point end{};                 ///< position after the block [mm]
  Point center{};              ///< arc centre [mm]; along the plane normal it holds start's value
  /// Plane of arcs; for other blocks the active plane (ISO G17/G18/G19, Heidenhain TOOL CALL axis).
  Plane plane = Plane::XY;
  /// Programmed (modal) feed for Linear and arcs; for Rapid the modal feed at that point (ignored
  /// when moving); 0 for Dwell and None blocks.
  double feed_mm_min = 0.0;
  double dwell_s = 0.0;        ///< Dwell only
  std::uint8_t axes = 0;       ///< mask of axes written in this block (axis_bit)
  std::vector<int> m_codes;    ///< M codes of the line, kept, not interpreted
  std::size_t line = 0;        ///< 1-based source line (0 for generated blocks)
  long number = -1;            ///< N number / Heidenhain block number, -1 when absent
  std::string comment;         ///< comment text of the line, if any (without delimiters, trimmed)
  /// None blocks only: a dialect statement without motion, kept for rewriting in canonical form
  /// with lengths in mm (Heidenhain `BLK FORM 0.1 Z Y-50.000 Z-50.000`, `TOOL CALL 0 Z`).
  std::string statement;
};

/// A reader's warning (only in lenient mode), tied to a line and column.
struct Diagnostic {
  std::size_t line = 0;
  std::size_t column = 0;
  std::string message;
};

/// A parsed or generated program.
struct Program {
  std::string name;              ///< file name or program name (Heidenhain BEGIN PGM)
  Dialect dialect = Dialect::Iso;
  Point start{};                 ///< position before the first block [mm]
  std::vector<Block> blocks;
  std::vector<Diagnostic> warnings;
  /// Mask of axes that the program moves (any block whose end differs from its start in that axis)
  /// or writes.
  [[nodiscard]] std::uint8_t used_axes() const noexcept;
};

}  // namespace servotwin::motion
