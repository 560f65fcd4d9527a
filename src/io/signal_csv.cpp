#include "servotwin/io/signal_csv.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <istream>

#include "csv_lines.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::io {

namespace {

using detail::Field;

using detail::lower;

std::string column_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

void validate_options(const SignalReadOptions& o, const std::string& source) {
  if (o.fs && !(std::isfinite(*o.fs) && *o.fs > 0.0))
    throw core::InputError({source, 0, 0, "--fs"}, "sample rate must be > 0 Hz");
  if (!(o.max_jitter >= 0.0 && o.max_jitter < 0.5))
    throw core::InputError({source, 0, 0, "max_jitter"}, "jitter tolerance must be in [0, 0.5)");
}

/// Time stamps per second of a time column name (1, 1e3, 1e6, 1e9), or 0 when the name is not
/// one. Stamps are divided by it (rather than multiplied by 1e-6, ...) so that a period of 400 µs
/// becomes exactly the double nearest 0.0004 s.
double ticks_per_second(std::string_view name) {
  const std::string n = lower(name);
  if (n == "t" || n == "time") return 1.0;
  for (std::string_view prefix : {"t_", "time_"}) {
    if (n.size() <= prefix.size() || n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string_view unit = std::string_view(n).substr(prefix.size());
    if (unit == "s") return 1.0;
    if (unit == "ms") return 1e3;
    if (unit == "us") return 1e6;
    if (unit == "ns") return 1e9;
  }
  return 0.0;
}

struct TimeColumn {
  std::size_t index = std::string::npos;
  double ticks = 1.0;  ///< per second
  std::string name;
};

TimeColumn find_time_column(const std::vector<std::string>& header, const SignalReadOptions& o, const std::string& source,
                            std::size_t header_line) {
  TimeColumn time;
  if (!o.time_column.empty()) {
    const auto it = std::find(header.begin(), header.end(), o.time_column);
    if (it == header.end())
      throw core::InputError({source, header_line, 0, o.time_column},
                             "missing time column '" + o.time_column + "' (columns: " + column_list(header) + ")");
    const double ticks = ticks_per_second(o.time_column);
    if (ticks == 0.0)
      throw core::InputError({source, header_line, 0, o.time_column},
                             "the time column's unit must be in its name: t or time (s), or t_/time_ followed by s, ms, "
                             "us or ns, e.g. time_us");
    time.index = static_cast<std::size_t>(it - header.begin());
    time.ticks = ticks;
    time.name = o.time_column;
    return time;
  }
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (const double ticks = ticks_per_second(header[i]); ticks != 0.0) {
      time.index = i;
      time.ticks = ticks;
      time.name = header[i];
      return time;
    }
  }
  return time;
}

/// `t` in the column's own unit, `ticks` of it per second.
void check_uniform(const std::vector<double>& t, double ticks, const std::vector<std::size_t>& lines,
                   const SignalReadOptions& o, const std::string& source, const std::string& column,
                   SignalTable& table) {
  const std::size_t n = t.size();
  const double t0 = t.front();
  const double ts = (t.back() - t.front()) / static_cast<double>(n - 1);
  for (std::size_t k = 1; k < n; ++k) {
    const double deviation = std::abs(t[k] - (t0 + static_cast<double>(k) * ts));
    if (deviation > o.max_jitter * ts)
      throw core::InputError({source, lines[k], 0, column},
                             fmt::format("non-uniform sampling: time {} is {:.3g} % of the mean sample period ({}) off "
                                         "the uniform grid (step from the previous row {}); at most {:.3g} % is "
                                         "accepted, resample the file first",
                                         t[k], 100.0 * deviation / ts, ts, t[k] - t[k - 1], 100.0 * o.max_jitter));
  }
  table.t0 = t0 / ticks;
  table.ts = ts / ticks;
  if (o.fs && std::abs(1.0 / *o.fs - table.ts) > o.max_jitter * table.ts)
    throw core::InputError({source, 0, 0, "--fs"}, fmt::format("--fs {} Hz disagrees with the time column '{}' ({} Hz)",
                                                               *o.fs, column, 1.0 / table.ts));
}

}  // namespace

std::optional<double> time_column_unit(std::string_view name) {
  const double ticks = ticks_per_second(name);
  if (ticks == 0.0) return std::nullopt;
  return 1.0 / ticks;
}

const std::vector<double>& SignalTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return columns[i];
  throw core::InputError({source, 0, 0, std::string(name)},
                         "missing column '" + std::string(name) + "' (columns: " + column_list(header) + ")");
}

SignalTable read_signal_csv(std::istream& in, std::string_view source_name, const SignalReadOptions& options) {
  const std::string source(source_name);
  validate_options(options, source);
  std::string line;
  std::size_t line_number = 0;
  std::vector<Field> fields;
  line_number = detail::read_header_line(in, source, line, "a header row with column names");
  const std::size_t header_line = line_number;
  detail::split_csv_line(line, fields);
  detail::check_header_delimiter(fields, ',', {source, header_line, 0, ""}, "");

  SignalTable table;
  table.source = source;
  for (const Field& f : fields) {
    const std::string name(f.text);
    if (name.empty())
      throw core::InputError({source, header_line, f.column, ""}, "empty column name in the header");
    if (std::find(table.header.begin(), table.header.end(), name) != table.header.end())
      throw core::InputError({source, header_line, f.column, name}, "column '" + name + "' appears twice in the header");
    table.header.push_back(name);
  }
  const std::size_t field_count = table.header.size();
  const TimeColumn time = find_time_column(table.header, options, source, header_line);
  if (time.index == std::string::npos && !options.fs)
    throw core::InputError({source, header_line, 0, "t"},
                           "no time column (t, time, or t_/time_ with the unit s, ms, us or ns, e.g. time_us; columns: " +
                               column_list(table.header) + "); name one or give the sample rate with --fs");
  table.time_column = time.name;

  std::vector<std::size_t> indices;
  if (options.columns.empty()) {
    for (std::size_t i = 0; i < field_count; ++i)
      if (i != time.index) {
        indices.push_back(i);
        table.names.push_back(table.header[i]);
      }
  } else {
    for (const auto& name : options.columns) {
      const auto it = std::find(table.header.begin(), table.header.end(), name);
      if (it == table.header.end())
        throw core::InputError({source, header_line, 0, name},
                               "missing column '" + name + "' (columns: " + column_list(table.header) + ")");
      indices.push_back(static_cast<std::size_t>(it - table.header.begin()));
      table.names.push_back(name);
    }
  }
  table.columns.resize(indices.size());

  std::vector<double> t;
  std::vector<std::size_t> lines;
  while (detail::next_data_row(in, source, line, line_number, fields, field_count)) {
    const core::SourceLocation where{source, line_number, 0, ""};
    for (std::size_t c = 0; c < indices.size(); ++c)
      table.columns[c].push_back(detail::parse_number(fields[indices[c]], where, table.names[c]));
    if (time.index != std::string::npos) {
      const double value = detail::parse_number(fields[time.index], where, time.name);
      if (!t.empty() && !(value > t.back()))
        throw core::InputError({source, line_number, fields[time.index].column, time.name},
                               fmt::format("time does not increase: {} after {}", fields[time.index].text, t.back()));
      t.push_back(value);
      lines.push_back(line_number);
    }
  }
  if (in.bad()) throw core::InputError({source, line_number, 0, ""}, "read error");
  const std::size_t rows = table.columns.empty() ? t.size() : table.columns.front().size();
  if (rows < 2)
    throw core::InputError({source, line_number, 0, ""},
                           fmt::format("{} data row{}: a time series needs at least 2 samples", rows, rows == 1 ? "" : "s"));
  if (time.index != std::string::npos) {
    check_uniform(t, time.ticks, lines, options, source, time.name, table);
  } else {
    table.ts = 1.0 / *options.fs;
  }
  return table;
}

SignalTable read_signal_file(const std::string& path, const SignalReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the file for reading");
  return read_signal_csv(in, path, options);
}

void require_varying(const SignalTable& table, std::string_view name) {
  const std::vector<double>& v = table.column(name);
  for (double s : v)
    if (s != v.front()) return;
  throw core::InputError({table.source, 0, 0, std::string(name)},
                         fmt::format("column '{}' is constant ({} in all {} rows): it cannot be the excitation", name,
                                     v.empty() ? 0.0 : v.front(), v.size()));
}

}  // namespace servotwin::io
