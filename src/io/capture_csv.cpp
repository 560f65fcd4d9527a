#include "servotwin/io/capture_csv.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <istream>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "csv_lines.hpp"
#include "servotwin/core/large_buffer.hpp"
#include "number_format.hpp"
#include "time_stamps.hpp"
#include "servotwin/io/linuxcnc_config.hpp"
#include "trace_table.hpp"

namespace servotwin::io {

namespace {

using detail::Field;

using detail::lower;

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() > suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

/// Maps our column names to the file's columns.
class ColumnResolver {
 public:
  ColumnResolver(const std::vector<Field>& header, const CaptureReadOptions& options, std::string_view source)
      : options_(options), source_(source) {
    for (const Field& f : header) names_.emplace_back(f.text);
    if (options.format == TraceFormat::Halscope) {
      for (const auto& n : names_)
        if (const auto ours = joint_pin_column(n, options.joint_axes)) aliases_.emplace_back(*ours, n);
    }
    for (const auto& [ours, theirs] : options.map) {
      if (std::find(names_.begin(), names_.end(), theirs) == names_.end())
        throw core::InputError({std::string(source), 1, 0, "--map " + ours + "=" + theirs},
                               "the file has no column '" + theirs + "' (columns: " + column_list() + ")");
    }
  }

  /// Index of our column `name` in the file, or npos.
  [[nodiscard]] std::size_t find(const std::string& name) const {
    std::string wanted = name;
    for (const auto& [ours, theirs] : aliases_)
      if (ours == name) wanted = theirs;
    for (const auto& [ours, theirs] : options_.map)
      if (lower(ours) == name) wanted = theirs;
    std::size_t found = std::string::npos;
    for (std::size_t i = 0; i < names_.size(); ++i) {
      if (names_[i] != wanted) continue;
      if (found != std::string::npos)
        throw core::InputError({std::string(source_), 1, 0, wanted}, "column '" + wanted + "' appears twice in the header");
      found = i;
    }
    return found;
  }

  [[nodiscard]] std::size_t require(const std::string& name) const {
    const std::size_t i = find(name);
    if (i == std::string::npos)
      throw core::InputError({std::string(source_), 1, 0, name},
                             "missing column '" + name + "' (columns: " + column_list() + "); map one with --map " +
                                 name + "=<column>");
    return i;
  }

  /// Axis names with a `_cmd` or `_act` column (our names, after mapping), in file order.
  [[nodiscard]] std::vector<std::string> discover_axes() const {
    std::vector<std::string> ours;
    for (const auto& n : names_) ours.push_back(lower(n));
    for (const auto& [our_name, theirs] : options_.map) ours.push_back(lower(our_name));
    for (const auto& [our_name, theirs] : aliases_) ours.push_back(our_name);
    std::vector<std::string> axes;
    for (const auto& n : ours) {
      for (std::string_view suffix : {"_cmd", "_act"}) {
        if (!ends_with(n, suffix)) continue;
        std::string axis = n.substr(0, n.size() - suffix.size());
        if (std::find(axes.begin(), axes.end(), axis) == axes.end()) axes.push_back(axis);
      }
    }
    return axes;
  }

  [[nodiscard]] std::string column_list() const {
    std::string out;
    for (const auto& n : names_) out += (out.empty() ? "" : ", ") + n;
    return out.empty() ? "none" : out;
  }

 private:
  const CaptureReadOptions& options_;
  std::string_view source_;
  std::vector<std::string> names_;
  std::vector<std::pair<std::string, std::string>> aliases_;  ///< our name -> a LinuxCNC joint pin's channel
};

/// Bytes left in a seekable stream (a file or a string), none for a pipe.
std::optional<std::size_t> remaining_bytes(std::istream& in) {
  const std::istream::pos_type here = in.tellg();
  if (here == std::istream::pos_type(-1)) {
    in.clear(in.rdstate() & ~std::ios::failbit);
    return std::nullopt;
  }
  in.seekg(0, std::ios::end);
  const std::istream::pos_type end = in.tellg();
  in.clear(in.rdstate() & ~(std::ios::failbit | std::ios::eofbit));
  in.seekg(here);
  if (end == std::istream::pos_type(-1) || !in || end < here) {
    in.clear(in.rdstate() & ~std::ios::failbit);
    in.seekg(here);
    return std::nullopt;
  }
  return static_cast<std::size_t>(end - here);
}

/// The columns are reserved from the rows' mean length so far, so that they do not grow by
/// copies (issue 26: the copies and their page faults were a third of reading a 1 M-row capture).
/// The estimate is renewed at 64, 128, 256, ... 262 144 rows: a capture's first rows (a machine at
/// rest, zeros) are shorter than the rest, and a column sized from them alone was three times too
/// long and copied to its size at the end, a column's worth of memory above the capture's own.
constexpr std::size_t kFirstRowsForEstimate = 64;
constexpr std::size_t kLastRowsForEstimate = 262144;

std::size_t estimated_rows(const detail::TraceTable& table, std::size_t rows, std::size_t input_bytes,
                           std::size_t first_row_end) {
  const std::size_t consumed = table.consumed_bytes();
  if (consumed <= first_row_end || input_bytes <= consumed) return rows;
  const double per_row = static_cast<double>(consumed - first_row_end) / static_cast<double>(rows - 1);
  return rows + static_cast<std::size_t>(1.02 * static_cast<double>(input_bytes - consumed) / per_row);
}

/// Where each data row came from, stored compactly: rows are consecutive lines except after
/// skipped (comment/blank) lines, so only the jumps are kept.
class RowLines {
 public:
  void add(std::size_t row, std::size_t line) {
    if (jumps_.empty() || line_of(row) != line) jumps_.emplace_back(row, line);
  }
  [[nodiscard]] std::size_t line_of(std::size_t row) const {
    if (jumps_.empty()) return 0;
    auto it = std::upper_bound(jumps_.begin(), jumps_.end(), row,
                               [](std::size_t r, const auto& jump) { return r < jump.first; });
    if (it == jumps_.begin()) return 0;
    --it;
    return it->second + (row - it->first);
  }

 private:
  std::vector<std::pair<std::size_t, std::size_t>> jumps_;
};

struct ColumnSink {
  std::size_t index;
  std::string name;      // our name, for messages
  std::vector<double>* target;
  double scale;
};

/// Sizes a column for `rows` rows while it is still short: a column reserved too long is
/// copied down now (cheap) rather than at the end.
void fit_capacity(std::vector<double>& column, std::size_t rows) {
  if (column.capacity() > rows + rows / 4) {
    std::vector<double> resized;
    core::reserve_large(resized, rows);
    resized.assign(column.begin(), column.end());
    column.swap(resized);
  } else if (column.capacity() < rows) {
    core::reserve_large(column, rows);
  }
}

/// The typical step of the time column: the median of its first steps (a gap further on does not
/// move it).
double typical_step(const detail::TimeStamps& t) {
  constexpr std::size_t kSteps = 1025;
  std::vector<double> steps;
  steps.reserve(std::min(t.size() - 1, kSteps));
  double previous = 0.0;
  t.for_each([&](std::size_t k, double tk) {
    if (k > 0 && steps.size() < kSteps) steps.push_back(tk - previous);
    previous = tk;
  });
  // The lower median: of two steps (three rows), the smaller is the one a gap did not widen.
  const auto middle = steps.begin() + static_cast<std::ptrdiff_t>((steps.size() - 1) / 2);
  std::nth_element(steps.begin(), middle, steps.end());
  return *middle;
}

/// The first step at least half a step from the typical one (a gap, or a clock that restarted or
/// stalled), if there is one; a jittered sample is not one.
std::optional<std::size_t> first_irregular_step(const detail::TimeStamps& t, double step) {
  std::optional<std::size_t> found;
  double previous = 0.0;
  const double tolerance = 0.5 * step;  // a jitter of a sample is not a gap
  t.for_each([&](std::size_t k, double tk) {
    if (!found && k > 0 && std::abs(tk - previous - step) > tolerance) found = k;
    previous = tk;
  });
  return found;
}

/// A sample off the uniform grid. A gap puts the first sample off the end-to-end grid well before
/// the gap (line 3 of a file whose gap was at line 700, issue 27 §4), so the message names the step
/// that breaks the grid when there is one, else the first sample off it (a drifting clock).
[[noreturn]] void throw_off_grid(const detail::TimeStamps& t, const RowLines& lines, double max_jitter,
                                 std::string_view source, const std::string& column, std::size_t k_off, double t_off,
                                 double deviation, double period) {
  const double step = typical_step(t);
  if (step > 0.0) {
    if (const auto k = first_irregular_step(t, step)) {
      double before = 0.0, at = 0.0;
      t.for_each([&](std::size_t i, double ti) {
        if (i + 1 == *k) before = ti;
        if (i == *k) at = ti;
      });
      throw core::InputError({std::string(source), lines.line_of(*k), 0, column},
                             fmt::format("time jumps from {} to {} s here, {:.4g} steps of the trace's typical {:.6g} s: "
                                         "the trace has a gap or its clock restarted (record it again, or cut the "
                                         "file at this line)",
                                         before, at, (at - before) / step, step));
    }
  }
  throw core::InputError({std::string(source), lines.line_of(k_off), 0, column},
                         fmt::format("time {} is {:.3g} % of the sample period ({} s) off the uniform grid; at "
                                     "most {:.3g} % jitter is accepted (resample the file first)",
                                     t_off, 100.0 * deviation / period, period, 100.0 * max_jitter));
}

void check_time_grid(const detail::TimeStamps& t, const RowLines& lines, double max_jitter, std::string_view source,
                     const std::string& column, double& t0, double& ts) {
  const std::size_t n = t.size();
  t0 = t.front();
  ts = (t.back() - t.front()) / static_cast<double>(n - 1);
  const double origin = t0, period = ts;
  std::optional<std::pair<std::size_t, double>> off;
  t.for_each([&](std::size_t k, double tk) {
    if (!off && std::abs(tk - (origin + static_cast<double>(k) * period)) > max_jitter * period) off = {k, tk};
  });
  if (off) {
    const double deviation = std::abs(off->second - (origin + static_cast<double>(off->first) * period));
    throw_off_grid(t, lines, max_jitter, source, column, off->first, off->second, deviation, period);
  }
}

void validate_options(const CaptureReadOptions& options, std::string_view source) {
  if (options.comment_prefix.empty())
    throw core::InputError({std::string(source), 0, 0, "comment_prefix"}, "the comment prefix must not be empty");
  if (options.format == TraceFormat::Csv && (options.delimiter == '"' || options.delimiter == '\n' || options.delimiter == '\0'))
    throw core::InputError({std::string(source), 0, 0, "delimiter"}, "the delimiter must be a character such as , ; or tab");
  if (!std::isfinite(options.scale) || options.scale == 0.0)
    throw core::InputError({std::string(source), 0, 0, "--scale"}, "scale must be a finite non-zero number");
  if (!(options.max_jitter >= 0.0 && options.max_jitter < 0.5))
    throw core::InputError({std::string(source), 0, 0, "max_jitter"}, "jitter tolerance must be in [0, 0.5)");
  if (options.ts && !(std::isfinite(*options.ts) && *options.ts > 0.0))
    throw core::InputError({std::string(source), 0, 0, "--ts"}, "sample period must be > 0");
}

}  // namespace

std::pair<std::string, std::string> parse_column_mapping(std::string_view text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
    throw core::InputError({"", 0, 0, "--map"}, "expected <name>=<column>, e.g. x_cmd=qg, got '" + std::string(text) + "'");
  return {lower(text.substr(0, eq)), std::string(text.substr(eq + 1))};
}

const char* trace_format_name(TraceFormat format) noexcept {
  switch (format) {
    case TraceFormat::Csv: return "csv";
    case TraceFormat::Halsampler: return "halsampler";
    case TraceFormat::Halscope: return "halscope";
  }
  return "?";
}

core::Capture read_capture_csv(std::istream& in, std::string_view source_name, const CaptureReadOptions& options) {
  validate_options(options, source_name);
  const std::string source(source_name);
  std::vector<Field> fields;
  const std::optional<std::size_t> input_bytes = remaining_bytes(in);
  detail::TraceTable table(in, source, options);
  const std::size_t header_line = table.header_line();
  const ColumnResolver columns(table.header(), options, source);

  core::Capture capture;
  std::vector<std::string> axes = options.axes;
  if (axes.empty()) axes = columns.discover_axes();
  if (axes.empty())
    throw core::InputError({source, header_line, 0, ""},
                           "no axis columns: expected <axis>_cmd and <axis>_act (columns: " + columns.column_list() +
                               "); map them with --map x_cmd=<column> --map x_act=<column>");
  capture.axes.reserve(axes.size());
  for (const auto& axis : axes) capture.axes.push_back(core::AxisTrace{lower(axis), {}, {}, {}});
  if (!options.axes.empty()) {
    for (const auto& trace : capture.axes) {
      if (columns.find(trace.name + "_cmd") != std::string::npos) continue;
      std::string present;
      for (const auto& a : columns.discover_axes()) present += (present.empty() ? "" : ", ") + a;
      throw core::InputError({source, header_line, 0, trace.name + "_cmd"},
                             "no axis '" + trace.name + "' in this capture (axes: " + (present.empty() ? "none" : present) +
                                 "; columns: " + columns.column_list() + "); map one with --map " + trace.name +
                                 "_cmd=<column>");
    }
  }

  std::vector<ColumnSink> sinks;
  detail::TimeStamps time;
  const std::size_t t_index = columns.find("t");
  if (t_index == std::string::npos && !options.ts && !table.period())
    throw core::InputError({source, header_line, 0, "t"},
                           "missing time column 't' (columns: " + columns.column_list() +
                               "); map one with --map t=<column> or give the sample period with --ts" +
                               (options.format == TraceFormat::Halsampler ? " or --ini" : ""));
  for (auto& trace : capture.axes) {
    sinks.push_back({columns.require(trace.name + "_cmd"), trace.name + "_cmd", &trace.cmd, options.scale});
    const std::size_t act = options.allow_missing_actual ? columns.find(trace.name + "_act") : columns.require(trace.name + "_act");
    if (act != std::string::npos) sinks.push_back({act, trace.name + "_act", &trace.act, options.scale});
    const std::size_t u = options.read_drive_output ? columns.find(trace.name + "_u") : std::string::npos;
    if (u != std::string::npos) sinks.push_back({u, trace.name + "_u", &trace.u, 1.0});
  }

  RowLines row_lines;
  std::size_t rows = 0, first_row_end = 0;
  core::SourceLocation where{source, 0, 0, ""};  // one string for the whole file, not one per row
  while (table.next(fields)) {
    const std::size_t line_number = table.line_number();
    where.line = line_number;
    if (t_index != std::string::npos) {
      const double t = detail::parse_number(fields[t_index], where, "t");
      if (!std::isfinite(t)) throw core::InputError({source, line_number, fields[t_index].column, "t"}, "time overflows");
      if (!time.empty() && !(t > time.back()))
        throw core::InputError({source, line_number, fields[t_index].column, "t"},
                               fmt::format("time does not increase: {} after {}", t, time.back()));
      time.push(t);
    }
    for (const ColumnSink& sink : sinks) {
      const double value = detail::parse_number(fields[sink.index], where, sink.name) * sink.scale;
      if (!std::isfinite(value))
        throw core::InputError({source, line_number, fields[sink.index].column, sink.name},
                               fmt::format("value times the scale {} overflows", sink.scale));
      sink.target->push_back(value);
    }
    row_lines.add(rows, line_number);
    ++rows;
    if (input_bytes && rows >= kFirstRowsForEstimate && rows <= kLastRowsForEstimate && std::has_single_bit(rows)) {
      const std::size_t estimate = estimated_rows(table, rows, *input_bytes, first_row_end);
      for (const ColumnSink& sink : sinks) fit_capacity(*sink.target, estimate);
      if (t_index != std::string::npos) time.reserve(estimate);
    }
    if (rows == 1) first_row_end = table.consumed_bytes();
  }
  if (in.bad()) throw core::InputError({source, table.line_number(), 0, ""}, "read error");
  if (rows < 2)
    throw core::InputError({source, table.line_number(), 0, ""},
                           fmt::format("{} data row{}: a capture needs at least 2 samples", rows, rows == 1 ? "" : "s"));

  if (!time.empty()) {
    check_time_grid(time, row_lines, options.max_jitter, source, "t", capture.t0, capture.ts);
    if (options.ts && std::abs(*options.ts - capture.ts) > options.max_jitter * capture.ts)
      throw core::InputError({source, 0, 0, "--ts"},
                             fmt::format("--ts {} disagrees with the file's time column (period {} s)", *options.ts,
                                         capture.ts));
  } else {
    capture.t0 = 0.0;
    if (options.ts && table.period() && std::abs(*options.ts - *table.period()) > 1e-9 * *table.period())
      throw core::InputError({source, 0, 0, "--ts"}, fmt::format("--ts {} disagrees with the file's sampling period {} s",
                                                                 *options.ts, *table.period()));
    capture.ts = options.ts ? *options.ts : *table.period();
  }
  // Only a clearly oversized vector is copied to its size: the copy of a long trace costs as much
  // as reading a tenth of it.
  for (auto& trace : capture.axes) {
    for (std::vector<double>* v : {&trace.cmd, &trace.act, &trace.u})
      if (v->capacity() > v->size() + v->size() / 8) v->shrink_to_fit();
  }
  return capture;
}

core::Capture read_capture_file(const std::string& path, const CaptureReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the file for reading");
  return read_capture_csv(in, path, options);
}

void write_capture_csv(std::ostream& out, const core::Capture& capture) {
  const std::size_t n = capture.size();
  for (const auto& axis : capture.axes)
    if (axis.cmd.size() != n || axis.act.size() != n || (!axis.u.empty() && axis.u.size() != n))
      throw std::invalid_argument("write_capture_csv: traces of axis '" + axis.name + "' differ in length");
  fmt::memory_buffer buffer;
  buffer.append(std::string_view("t"));
  for (const auto& axis : capture.axes) {
    fmt::format_to(std::back_inserter(buffer), ",{0}_cmd,{0}_act", axis.name);
    if (!axis.u.empty()) fmt::format_to(std::back_inserter(buffer), ",{}_u", axis.name);
  }
  buffer.push_back('\n');
  const int time_decimals = detail::time_decimals(capture.t0, capture.ts);
  for (std::size_t k = 0; k < n; ++k) {
    detail::append_time(buffer, capture.time(k), time_decimals);
    for (const auto& axis : capture.axes) {
      fmt::format_to(std::back_inserter(buffer), ",{},{}", axis.cmd[k], axis.act[k]);
      if (!axis.u.empty()) fmt::format_to(std::back_inserter(buffer), ",{}", axis.u[k]);
    }
    buffer.push_back('\n');
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
