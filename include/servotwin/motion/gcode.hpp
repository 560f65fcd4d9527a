#pragma once
/// \file
/// Readers and writers for ISO G-code (RS-274 / DIN 66025 subset) and the Heidenhain
/// conversational subset used in the rapid-identification thesis (Tables 4.3/4.4).
///
/// Readers take the text, not a file: file access lives in `io`. Errors are thrown as
/// core::InputError naming `source_name:line:column` and the offending word.

#include <optional>
#include <string>
#include <string_view>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

struct ParseOptions {
  /// Unknown words and unsupported features become warnings in Program::warnings instead of
  /// errors; the word is ignored.
  bool lenient = false;
  /// Position of the machine before the program starts [mm].
  Point start{};
  /// Arcs given by centre (I/J/K, Heidenhain CC) must have start and end radius equal within
  /// max(arc_tolerance_abs_mm, arc_tolerance_rel * radius).
  double arc_tolerance_abs_mm = 0.002;
  double arc_tolerance_rel = 0.001;
};

/// Parses ISO G-code. Supported: N numbers, G00 G01 G02 G03 (I/J/K or R) G04 (P or X seconds)
/// G17 G18 G19 G20 G21 G90 G91 G94, F per minute, M codes (kept), comments in parentheses and
/// after ';', `%` tape marks, case-insensitive words, optional spaces between letter and number.
Program parse_iso(std::string_view text, std::string_view source_name, const ParseOptions& options = {});

/// Parses the Heidenhain conversational subset: BEGIN PGM / END PGM (MM or INCH), BLK FORM,
/// TOOL CALL, `L` lines with X/Y/Z (absolute or I-incremental), R0, `F`, `F MAX`, M codes,
/// `CC` (circle centre), `C` arcs with DR+/DR-, `CR` arcs with R and DR, `;` comments.
Program parse_heidenhain(std::string_view text, std::string_view source_name,
                         const ParseOptions& options = {});

/// Detects the dialect (a Heidenhain program starts with `[n] BEGIN PGM`) and parses.
Program parse_program(std::string_view text, std::string_view source_name,
                      const ParseOptions& options = {}, std::optional<Dialect> dialect = std::nullopt);

/// Guesses the dialect from the text (ignores leading blank and comment lines).
Dialect detect_dialect(std::string_view text) noexcept;

/// Writes a program in ISO G-code (mm, absolute, N numbers as stored or every 10).
std::string write_iso(const Program& program);
/// Writes a program in the Heidenhain conversational dialect (numbered blocks, BEGIN/END PGM).
std::string write_heidenhain(const Program& program);

}  // namespace servotwin::motion
