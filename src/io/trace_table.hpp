#pragma once
// The rows of a capture file in any of its layouts (io/capture_csv.hpp's TraceFormat): the
// column names (a header row, or the names given for a headerless halsampler file), then each
// data row's values, with the layout's own checks (halsampler sample numbers and overruns,
// halscope's sampling period). Private to io.

#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "csv_lines.hpp"
#include "servotwin/io/capture_csv.hpp"

namespace servotwin::io::detail {

class TraceTable {
 public:
  /// Reads up to the first data row's line (CSV and halscope: the header). core::InputError
  /// naming `source` for an empty file, a halsampler file without names, a halscope log without
  /// its period and no `ts` given.
  TraceTable(std::istream& in, const std::string& source, const CaptureReadOptions& options);

  /// Column names, with their columns in the header line (halsampler: their position).
  [[nodiscard]] const std::vector<Field>& header() const noexcept { return header_; }
  [[nodiscard]] std::size_t header_line() const noexcept { return header_line_; }
  /// Sample period the file states (halscope), if any [s].
  [[nodiscard]] std::optional<double> period() const noexcept { return period_; }
  /// The next data row's values, one per header name (valid until the next call); false at the
  /// end. core::InputError at the line for a wrong number of values, a gap in halsampler's sample
  /// numbers, an `overrun` between samples.
  bool next(std::vector<Field>& fields);
  [[nodiscard]] std::size_t line_number() const noexcept { return line_number_; }
  /// Bytes of the input consumed so far (up to the end of the line read last).
  [[nodiscard]] std::size_t consumed_bytes() const noexcept { return consumed_; }
  [[nodiscard]] const std::string& source() const noexcept { return source_; }

 private:
  bool read_line();
  void read_halscope_period(std::string_view line, std::size_t number);
  bool next_halsampler(std::vector<Field>& fields);
  void check_not_a_counter();

  std::istream& in_;
  std::string source_;
  const CaptureReadOptions& options_;
  // Lines are cut from a block buffer (one read of kBlock bytes instead of one getline per line:
  // issue 26, captures of hundreds of MB); line_ points into it until the next read_line.
  // The first read is smaller: most files a user hands over by mistake, the fuzzers' inputs and
  // short captures fit in it, and sizing 1 MiB for them was most of the time to read them.
  static constexpr std::size_t kBlock = std::size_t{1} << 20;
  static constexpr std::size_t kFirstBlock = std::size_t{1} << 16;
  std::string buffer_;
  std::size_t begin_ = 0, filled_ = 0;  ///< unread bytes are buffer_[begin_, filled_)
  bool end_of_input_ = false;
  std::size_t consumed_ = 0;
  std::string_view line_;
  std::size_t line_number_ = 0;
  bool line_complete_ = true;  ///< the line read last ended with a line break
  std::vector<std::string> names_;  ///< header names (the fields point into them)
  std::vector<Field> header_;
  std::size_t header_line_ = 0;
  std::optional<double> period_;
  char delimiter_ = ',';
  // halsampler: sample-number column (decided by the first row) and the last number
  std::optional<bool> numbered_;
  std::uint32_t last_number_ = 0;
  std::optional<bool> counting_;  ///< unnumbered: the first column still looks like a sample number
  long long counter_ = 0;
  std::size_t rows_ = 0;
  std::vector<Field> raw_;
};

}  // namespace servotwin::io::detail
