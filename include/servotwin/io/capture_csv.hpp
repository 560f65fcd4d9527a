#pragma once
/// \file
/// Capture CSV files (design.md "capture CSV"): a header row, then one row per sample with `t`
/// and, per axis, `<axis>_cmd`, `<axis>_act` and optionally `<axis>_u`. Lines starting with `#`
/// are comments. Foreign files are read through a column map and a unit scale, e.g. the EMPS
/// benchmark with `x_cmd=qg, x_act=qm, scale 1000` (m -> mm).

#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "servotwin/core/capture.hpp"

namespace servotwin::io {

/// How to read a capture CSV.
struct CaptureReadOptions {
  /// Our column name -> the file's column name, e.g. {"x_cmd", "qg"}. Unmapped names are looked
  /// up as themselves.
  std::vector<std::pair<std::string, std::string>> map;
  /// Factor applied to positions (`_cmd`, `_act`), e.g. 1000 to read metres as mm. Not to t or u.
  double scale = 1.0;
  /// Largest accepted deviation of a time stamp from the uniform grid, relative to ts.
  double max_jitter = 0.01;
  /// Sample period for files without a time column.
  std::optional<double> ts;
  /// Axes to read (lower-case); empty = every axis that has both `_cmd` and `_act`.
  std::vector<std::string> axes;
  /// Axes may lack `_act` (a commanded trajectory only): AxisTrace::act is then empty.
  bool allow_missing_actual = false;
};

/// Reads a capture from a stream, line by line: memory holds only the columns used.
/// Throws core::InputError naming `source_name`, the line and column for: an empty file, a
/// missing column, a row with the wrong number of fields, text/NaN/inf in a number, a
/// non-increasing time, jitter above `max_jitter`, fewer than 2 rows.
core::Capture read_capture_csv(std::istream& in, std::string_view source_name,
                               const CaptureReadOptions& options = {});

/// Opens `path` and reads it (core::InputError if it cannot be opened).
core::Capture read_capture_file(const std::string& path, const CaptureReadOptions& options = {});

/// Parses "name=column" as given to `--map` (core::InputError naming the option otherwise).
std::pair<std::string, std::string> parse_column_mapping(std::string_view text);

/// Writes `t` then per axis `<axis>_cmd,<axis>_act[,<axis>_u]`; numbers round-trip exactly.
void write_capture_csv(std::ostream& out, const core::Capture& capture);

}  // namespace servotwin::io
