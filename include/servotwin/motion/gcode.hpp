#pragma once
/// \file
/// Readers and writers for ISO G-code (RS-274 / DIN 66025 subset) and the Heidenhain
/// conversational subset used in the rapid-identification thesis (Tables 4.3/4.4).
///
/// Readers take the text, not a file: file access lives in `io`. Errors are thrown as
/// core::InputError naming `source_name:line:column` and the offending word, e.g.
/// `id.nc:12:9: unknown word 'Q5'`. Readers never crash or hang on any byte sequence.
///
/// Limits shared by both readers: every coordinate, offset and radius must satisfy |value| <= 1e9 mm
/// (up to there a double still resolves 1 um, 2^53 um ~ 9e9 mm), feeds 0 < F <= 1e9 mm/min, dwell
/// times 0 <= t <= 1e9 s. Numbers are plain decimals (`12`, `-0.5`, `.5`, `+3.`); exponents, `nan`
/// and `inf` are rejected as malformed.
///
/// ISO dialect, in detail:
/// * Words: `N` (once per line), `G`, `M` (several; kept in Block::m_codes, not interpreted), `F`,
///   `X Y Z`, `I J K`, `R`, `P`. Letters are case-insensitive, blanks may separate a letter from
///   its number (`N0010 G01 X 0.258`, thesis Table 3.2). Comments: `( ... )` and `;` to the end of
///   the line. Lines starting with `%` are tape marks and ignored.
/// * G words: G00 G01 G02 G03 (motion), G04 (dwell), G17 G18 G19 (plane), G20 G21 (inch/mm),
///   G90 G91 (absolute/incremental), G90.1 G91.1 (arc centre absolute/incremental, default G91.1),
///   G94 (feed per minute, the only feed mode), G40 (cutter compensation off, accepted as a no-op),
///   G61 (exact stop mode) and G64 (continuous path mode, no tolerance word), kept per block as
///   Block::path_control.
///   Several G words of different modal groups may share a line; two of the same group are an error.
///   A line carries at most one motion (or one dwell).
/// * Modal state at the start: no motion mode (axis words before the first G00..G03 are an error),
///   G17, G21, G90, G91.1, no feed. G20 converts every length and feed of the line it is active on
///   to mm (mm/min).
/// * Arcs: the centre by I/J/K (offsets from the start point in G91.1) or by R (R > 0: the arc of
///   at most 180 degrees, R < 0: the one above 180). I/J/K must belong to the active plane. A full
///   circle is given by I/J/K with end point == start point; an R arc with end == start is an error.
///   A coordinate along the plane normal makes a helix (linear in that axis).
/// * G04 takes its time in seconds from `P` or `X` (P in seconds as in LinuxCNC and Siemens, not
///   Fanuc's integer milliseconds).
/// * Feeds: F > 0 per minute, modal. G01/G02/G03 without any feed programmed before is an error.
///
/// LinuxCNC dialect: the ISO subset above, but with LinuxCNC's path-control words (LinuxCNC G-code
/// reference, G61/G61.1/G64): G61 is *exact path* (stops where the direction changes, runs on
/// through tangent and collinear joins), G61.1 exact stop, `G64 P<p> [Q<q>]` blending within p
/// (program units; P0 = plain G64), q the naive-CAM tolerance. P and Q belong to G64 there;
/// in ISO, `G64 P..` and G61.1 are errors that point to `--dialect linuxcnc`.
///
/// Heidenhain dialect, in detail (block numbers at the start of a line are optional):
/// * `BEGIN PGM name MM|INCH` first, `END PGM name MM|INCH` last (same name and unit); INCH
///   programs are converted to mm and mm/min (feeds are taken as inch/min).
/// * `BLK FORM 0.1 <tool axis> X.. Y.. Z..`, `BLK FORM 0.2 X.. Y.. Z..` and `TOOL CALL n|"name" X|Y|Z
///   [S..]` are checked and kept as None blocks with a canonical Block::statement (lengths in mm);
///   TOOL CALL sets the working plane (tool axis Z: XY, Y: ZX, X: YZ).
/// * `L` with `X Y Z` (absolute) or `IX IY IZ` (incremental), `R0`, `F <value>` (modal), `F MAX` /
///   `FMAX` (rapid, this block only), M codes. `L` without coordinates moves nothing (None block).
/// * `CC` sets the circle centre: two coordinates choose the arc plane (X Y, Z X or Y Z), one
///   coordinate must lie in the working plane, missing coordinates are taken from the current
///   position. `C <end> DR+|DR-` turns about CC (DR+ counterclockwise); end == start is a full
///   circle. `CR <end> R<radius> DR+|DR-` is an arc of the given radius in the working plane
///   (R+ at most 180 degrees, R- above). A coordinate along the plane normal makes a helix (an
///   extension: the TNC itself programs helices with CP).
/// * `CYCL DEF 9.0 DWELL TIME` followed by `CYCL DEF 9.1 DWELL <seconds>` is a dwell.
/// * `CYCL DEF 32.0 TOLERANCE` followed by `CYCL DEF 32.1 T<tolerance>` sets PathControl::Blend
///   with that tolerance (the TNC smooths corners within it); a bare `CYCL DEF 32.1` returns to
///   the machine's value (PathControl::Unstated). `CYCL DEF 32.2 HSC-MODE:.. TA..` is kept as a
///   statement, not interpreted. Klartext has no exact-stop word.
/// * `;` starts a comment. RL/RR radius compensation and other path functions (CT, CP, LP, RND,
///   CHF, APPR, DEP, ...) are unsupported: errors, or warnings (word or block ignored) in lenient
///   mode.

#include <optional>
#include <string>
#include <string_view>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

struct ParseOptions {
  /// Unknown words and unsupported features become warnings in Program::warnings instead of
  /// errors; the word (or, for an unsupported Heidenhain statement, the block) is ignored.
  /// Malformed numbers and geometric errors stay errors. At most 1000 warnings are listed.
  bool lenient = false;
  /// Position of the machine before the program starts [mm].
  Point start{};
  /// Arcs given by centre (I/J/K, Heidenhain CC) must have start and end radius equal within
  /// max(arc_tolerance_abs_mm, arc_tolerance_rel * radius); R arcs whose chord exceeds the
  /// diameter by no more than this are taken as half circles.
  double arc_tolerance_abs_mm = 0.002;
  double arc_tolerance_rel = 0.001;
};

/// Parses ISO G-code (see the file comment for the exact subset).
Program parse_iso(std::string_view text, std::string_view source_name, const ParseOptions& options = {});

/// Parses ISO G-code with LinuxCNC's path-control words (see the file comment): G61 is exact
/// path, G61.1 exact stop, `G64 [P<tolerance> [Q<naive-CAM tolerance>]]` blending.
Program parse_linuxcnc(std::string_view text, std::string_view source_name, const ParseOptions& options = {});

/// Parses the Heidenhain conversational subset (see the file comment).
Program parse_heidenhain(std::string_view text, std::string_view source_name,
                         const ParseOptions& options = {});

/// Detects the dialect (a Heidenhain program starts with `[n] BEGIN PGM`) and parses.
Program parse_program(std::string_view text, std::string_view source_name,
                      const ParseOptions& options = {}, std::optional<Dialect> dialect = std::nullopt);

/// Guesses the dialect from the text (ignores leading blank, comment and `%` lines): Heidenhain or
/// ISO (a LinuxCNC program is read as ISO unless the dialect is given).
Dialect detect_dialect(std::string_view text) noexcept;

/// How the writers print a program.
///
/// Number rule: lengths, offsets and times are printed in fixed notation with `decimals` decimals
/// (3 = 1 um by default) when that text reads back to exactly the same double; otherwise with the
/// shortest fixed-notation text that does (std::to_chars), so that reading a written program gives
/// back the same coordinates bit for bit. ISO feeds are printed in the shortest exact form
/// (`F12000`, thesis Table 3.2), Heidenhain feeds like lengths (`F 15000.000`, Tables 4.3/4.4).
struct WriteOptions {
  int decimals = 3;               ///< minimum decimals of lengths and times, 0..9
  /// ISO: a blank in place of the `+` of positive numbers, as in thesis Table 3.2 (`X 0.258`,
  /// `X-0.790`). Off by default: `X0.258`.
  bool sign_column = false;
  /// ISO: put `G17 G21 G90 G94` on the first block so the program does not rely on the
  /// controller's power-on modes (the readers assume exactly these).
  bool iso_modal_preamble = false;
  /// ISO: width to which N numbers are zero-padded (`N0010`).
  int iso_number_width = 4;
};

/// Writes a program in ISO G-code: mm, absolute coordinates, arcs by I/J/K (incremental), the
/// motion G word on every motion line, F when the feed changes, a plane word (G17/G18/G19) when
/// the plane changes, the path-control word (G61 / G64) when a stated mode changes (on a line of
/// its own before a dwell). Blocks keep their stored N numbers (none when Block::number < 0). Heidenhain
/// statements (BLK FORM, TOOL CALL) are written as comments. None blocks without M codes, comment
/// and statement are not written. The start position (ParseOptions::start) is not part of the text.
std::string write_iso(const Program& program, const WriteOptions& options = {});

/// Writes a program in the Heidenhain conversational dialect: `0 BEGIN PGM name MM`, blocks
/// numbered consecutively (a comment-only block with Block::number < 0 is written without a
/// number, as in the thesis tables), R0 on the first block moving in its plane, `F MAX` for rapids, F when the
/// feed changes, arcs as `CC` (when the centre or plane changes) + `C ... DR+/DR-`, dwells as
/// cycle 9, Cycle 32 TOLERANCE (`CYCL DEF 32.0 TOLERANCE`, `CYCL DEF 32.1 T<tol>`; a bare 32.1 to
/// return to the machine's value) when the path-control mode changes, a `;path control: ...`
/// comment for modes Klartext cannot state, `END PGM name MM`. The name is the stem of Program::name with characters other than
/// letters, digits, `_` and `-` replaced by `_` ("PGM" when empty).
std::string write_heidenhain(const Program& program, const WriteOptions& options = {});

/// Writes a program in ISO G-code like write_iso, with LinuxCNC's path-control words: G61.1 for
/// exact stop, G61 for exact path, `G64 [P<tolerance> [Q<naive-CAM tolerance>]]` for blending.
std::string write_linuxcnc(const Program& program, const WriteOptions& options = {});

/// Writes a program in its own dialect (Program::dialect).
std::string write_program(const Program& program, const WriteOptions& options = {});

/// Whether a dialect has words for a path-control mode: ISO G61 and G64 without a tolerance (and
/// LinuxCNC's exact path only as the stricter G61); LinuxCNC every mode; Heidenhain Klartext only
/// Cycle 32 TOLERANCE (Blend with a tolerance) and its reset (Unstated).
bool can_state(Dialect dialect, PathControl mode, double blend_tolerance_mm) noexcept;

}  // namespace servotwin::motion
