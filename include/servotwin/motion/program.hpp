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

/// G-code dialect of a program. LinuxCnc is ISO with LinuxCNC's meaning of the path-control words
/// (G61 exact path, G61.1 exact stop, `G64 P<tol> Q<tol>`); see gcode.hpp and docs/gcode.md.
enum class Dialect { Iso, LinuxCnc, Heidenhain };

/// How the controller passes from one motion block to the next (ISO modal group 13; Heidenhain
/// Cycle 32). Which words express each mode depends on the dialect (docs/gcode.md).
enum class PathControl : std::uint8_t {
  Unstated,   ///< the program does not say: the controller's own setting applies
  ExactStop,  ///< stop at the end of every block (ISO/Fanuc G61, LinuxCNC G61.1)
  ExactPath,  ///< reach every programmed point: stop at corners, keep speed where moves continue
              ///< tangentially (LinuxCNC G61)
  Blend       ///< continuous feed, corners blended (G64), within Block::blend_tolerance_mm if > 0
};

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
  /// Path-control mode in effect for this block (modal); it governs the junction at the block's
  /// end, as in LinuxCNC, where a segment's termination is fixed when it is queued.
  PathControl path_control = PathControl::Unstated;
  /// Blend only: largest deviation from the programmed corner the controller may take [mm]
  /// (LinuxCNC `G64 P`, Heidenhain Cycle 32 `T`); 0 = none stated (plain G64).
  double blend_tolerance_mm = 0.0;
  /// Blend only, LinuxCNC: naive-CAM tolerance `G64 Q` [mm]; negative = not written (LinuxCNC then
  /// takes P's value).
  double cam_tolerance_mm = -1.0;
};

/// A path-control mode in words for messages, e.g. "exact stop at every block end", "corners
/// blended within 0.01 mm".
std::string describe_path_control(PathControl mode, double blend_tolerance_mm);

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
  /// True when some motion block has a stated path-control mode.
  [[nodiscard]] bool states_path_control() const noexcept;
  /// True when some motion block blends (PathControl::Blend).
  [[nodiscard]] bool blends() const noexcept;
};

}  // namespace servotwin::motion
