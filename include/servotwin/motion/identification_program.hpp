#pragma once
/// \file
/// Generator of rapid-identification programs (thesis section 3.4, Table 3.2, and section 4.3.3,
/// Tables 4.3/4.4): random straight moves uniformly distributed within +-range around a centre.
///
/// Random numbers: std::mt19937_64 seeded with `seed` (its output sequence is fixed by the C++
/// standard); each draw takes the top 53 bits of one output as u in [0, 1), so s = 2u - 1 lies in
/// [-1, 1). With K = range * 10^decimals grid steps, a target is centre + round(K * s) / 10^decimals
/// (round half away from zero): uniform within +-range, rounded to the output resolution, and the
/// same on every platform (only exact or correctly rounded IEEE operations are involved). Axes are
/// drawn in X, Y, Z order within a move. A draw equal to the axis's previous target is redrawn so
/// every move moves every selected axis.
///
/// Shapes (`moves` = number of random moves M):
/// * Standard (Table 3.2): rapid to the centre, M random moves, a move back to the centre.
/// * Low (Table 4.3): rapid to the centre, a move to centre - range and one to centre + range,
///   M random moves, a move back to the centre. (The printed table has `X-0.000`/`X+0.000` in the
///   sweep blocks 7/8, i.e. zero-length moves; here the sweep reaches the range so that it moves.)
/// * High (Table 4.4): rapid to the centre, sweep to centre - range and centre + range, M random
///   moves, sweep to centre - range and centre + range, back to the centre. As in Table 4.4 (blocks
///   9-11 vs 103-101) the last floor(M/2) random moves mirror the first ones about the centre in
///   reverse order, so the random part is balanced in direction.
///
/// Framing by dialect:
/// * Iso (Table 3.2): `N0000 G61 G00 X0.000 F12000` (the rapid carries the feed and the
///   path-control word, see `path_control`), `N0010 G01 ...`, N numbers in steps of 10, then `M30`.
///   LinuxCnc is framed the same way.
/// * Heidenhain (Tables 4.3/4.4): a comment block (unnumbered), `BLK FORM 0.1 Z` / `0.2` spanning
///   centre +- range on all three axes, `TOOL CALL 0 Z`, `L <selected X/Y axes> R0 F MAX M3`, then
///   `L Z.. F MAX` only if Z is selected, the moves with F on the first, `M30`. Write it with
///   write_program (or write_heidenhain) to get `BEGIN PGM name MM` ... `END PGM name MM`.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

/// Which of the thesis's programs to imitate.
enum class IdentificationSet {
  Standard,  ///< Table 3.2: G00 to the centre, then `moves` random G01 moves, back to the centre
  Low,       ///< Table 4.3: very short moves (tens of um) for the low-speed/friction regime
  High       ///< Table 4.4: a full-range sweep each way, random moves, a sweep, back to the centre
};

struct IdentificationOptions {
  std::vector<Axis> axes{Axis::X};  ///< axes moved together (each move draws every axis)
  IdentificationSet set = IdentificationSet::Standard;
  std::size_t moves = 200;          ///< number of random moves
  double range_mm = 10.0;           ///< targets are uniform in [centre - range, centre + range]
  double feed_mm_min = 12000.0;     ///< programmed feed
  Point center{};                   ///< centre of the motion range [mm]; on selected axes a multiple of 10^-decimals
  std::uint64_t seed = 1;           ///< same seed -> same program, on every platform
  std::string name = "RAPIDIDENT";  ///< program name (Heidenhain BEGIN PGM): letters, digits, _ or -
  int decimals = 3;                 ///< targets are rounded to this many decimals (1 um), 0..9
  Dialect dialect = Dialect::Iso;   ///< framing of the program (see the file comment)
  /// Path-control mode stated on every block; empty = the dialect's default: exact stop for ISO
  /// (G61) and LinuxCNC (G61.1), nothing for Heidenhain (the machine's setting; Klartext has no
  /// exact-stop word). A reversal stops anyway; the mode matters for moves that continue in the
  /// same direction, and it keeps the controller's default (LinuxCNC blends) from applying.
  std::optional<PathControl> path_control;
  double blend_tolerance_mm = 0.0;  ///< with PathControl::Blend: the stated tolerance, 0 = none
};

/// Defaults of each set as in the thesis: Standard 200 moves, +-10 mm, F12000 (Table 3.2);
/// Low 200 moves, +-0.03 mm, F15000 (Table 4.3); High 100 moves, +-10 mm, F15000 (Table 4.4).
IdentificationOptions identification_defaults(IdentificationSet set);

/// Builds the program. Throws core::InputError for no axes or a repeated axis, zero moves, range
/// not finite or below one output step (10^-decimals), feed <= 0 or above 1e9 mm/min, decimals
/// outside 0..9, a centre that is not finite or (on a selected axis) not on the 10^-decimals grid, targets beyond
/// +-1e9 mm, a name that BEGIN PGM cannot carry, or a path-control mode the dialect cannot state
/// (field "path_control").
Program make_identification_program(const IdentificationOptions& options);

}  // namespace servotwin::motion
