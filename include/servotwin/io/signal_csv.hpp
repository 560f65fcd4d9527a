#pragma once
/// \file
/// Recorded time series: a CSV with a header row and one row per sample, any number of numeric
/// columns, uniformly sampled. `#` lines are comments. The sample period comes from a time column
/// or from an explicit sample rate:
/// * `t` or `time`: seconds;
/// * `t_<unit>` or `time_<unit>` with unit `s`, `ms`, `us` or `ns` (e.g. `time_us`): the unit is
///   taken from the name and the values converted to seconds.
/// Only the requested columns are stored, so long files are read with memory for those alone.

#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace servotwin::io {

/// How to read a signal CSV.
struct SignalReadOptions {
  /// Columns to read, by exact header name; empty = every column except the time column.
  std::vector<std::string> columns;
  /// Time column; empty = the first column named as in the file comment above (`t`, `time`,
  /// `t_s`, `time_ms`, `time_us`, ...). A named column must carry its unit the same way.
  std::string time_column;
  /// Sample rate [Hz]: required when the file has no time column; checked against it otherwise.
  std::optional<double> fs;
  /// Largest accepted deviation of a time stamp from the uniform grid, relative to the period.
  double max_jitter = 0.01;
};

/// Uniformly sampled columns read from a CSV.
struct SignalTable {
  std::string source;                        ///< file name as given, for messages
  double t0 = 0.0;                           ///< first time stamp [s] (0 without a time column)
  double ts = 0.0;                           ///< sample period [s]
  std::string time_column;                   ///< the column the period came from, empty for `fs`
  std::vector<std::string> names;            ///< the stored columns, in the order requested
  std::vector<std::vector<double>> columns;  ///< one vector per name, all of size()
  std::vector<std::string> header;           ///< every column of the file, for messages

  [[nodiscard]] std::size_t size() const noexcept { return columns.empty() ? 0 : columns.front().size(); }
  /// The column `name` (core::InputError naming the file and the available columns otherwise).
  [[nodiscard]] const std::vector<double>& column(std::string_view name) const;
};

/// Reads a signal CSV from a stream. Throws core::InputError naming `source_name`, line, column
/// and CSV column for: an empty file, a missing column (listing the available ones), a duplicate
/// column name, a row with the wrong number of fields, text/NaN/inf in a number, a time stamp that
/// does not increase or lies off the uniform grid (the line is named), a time column without a
/// unit, `fs` missing or disagreeing with the time column, fewer than 2 rows.
SignalTable read_signal_csv(std::istream& in, std::string_view source_name, const SignalReadOptions& options = {});

/// Opens `path` and reads it (core::InputError if it cannot be opened).
SignalTable read_signal_file(const std::string& path, const SignalReadOptions& options = {});

/// Throws core::InputError naming the file and column when every sample of `name` is the same:
/// such a column cannot be an excitation.
void require_varying(const SignalTable& table, std::string_view name);

/// Seconds per unit of a time column name (`t`, `time` -> 1, `time_ms` -> 1e-3, ...), or empty
/// when the name is not a time column.
std::optional<double> time_column_unit(std::string_view name);

}  // namespace servotwin::io
