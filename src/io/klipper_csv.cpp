#include "servotwin/io/klipper_csv.hpp"

#include <array>
#include <fmt/format.h>
#include <fstream>
#include <istream>
#include <optional>

#include "csv_lines.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::io {

namespace {

using detail::Field;

constexpr std::array<std::string_view, 5> kColumns = {"freq", "psd_x", "psd_y", "psd_z", "psd_xyz"};
constexpr std::string_view kExpectedHeader = "header freq,psd_x,psd_y,psd_z,psd_xyz[,shapers:][,zv(21.0),...]";

/// Where each needed column sits, and whether the file carries fitted-shaper columns.
struct Layout {
  std::array<std::size_t, 5> index{};
  std::size_t field_count = 0;
  std::optional<std::size_t> marker;  ///< the `shapers:` column (empty on data rows)
  bool has_shaper_columns = false;
};

/// A fitted-shaper column name: letters/digits/underscore followed by "(number)".
bool is_shaper_column(std::string_view name) {
  const auto open = name.find('(');
  return open != std::string_view::npos && open > 0 && name.size() > open + 2 && name.back() == ')';
}

Layout parse_header(const std::string& line, std::size_t line_number, const std::string& source) {
  std::vector<Field> fields;
  detail::split_csv_line(line, fields);
  Layout layout;
  layout.field_count = fields.size();
  std::array<bool, 5> found{};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string name = detail::lower(fields[i].text);
    bool known = false;
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      if (name != kColumns[c]) continue;
      if (found[c])
        throw core::InputError({source, line_number, fields[i].column, ""},
                               fmt::format("column '{}' appears twice in the header", name));
      found[c] = true;
      layout.index[c] = i;
      known = true;
    }
    if (known) continue;
    if (name == "shapers:") {
      layout.marker = i;
    } else if (is_shaper_column(name)) {
      layout.has_shaper_columns = true;
    } else {
      throw core::InputError({source, line_number, fields[i].column, ""},
                             fmt::format("unknown column '{}': expected {}", name, kExpectedHeader));
    }
  }
  for (std::size_t c = 0; c < kColumns.size(); ++c)
    if (!found[c])
      throw core::InputError({source, line_number, 0, ""},
                             fmt::format("missing column '{}': expected {}", kColumns[c], kExpectedHeader));
  return layout;
}

}  // namespace

shaping::Spectrum read_klipper_csv(std::istream& in, const std::string& source) {
  std::string line;
  std::size_t line_number = detail::read_header_line(in, source, line, kExpectedHeader);
  const Layout layout = parse_header(line, line_number, source);

  shaping::Spectrum spectrum;
  spectrum.source = source;
  spectrum.normalized = layout.marker.has_value() || layout.has_shaper_columns;
  std::array<std::vector<double>*, 5> columns = {&spectrum.freq_hz, &spectrum.psd_x, &spectrum.psd_y,
                                                 &spectrum.psd_z, &spectrum.psd_sum};
  std::vector<Field> fields;
  while (detail::next_data_row(in, source, line, line_number, fields, layout.field_count)) {
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      const Field& field = fields[layout.index[c]];
      const double value = detail::parse_number(field, {source, line_number, 0, std::string(kColumns[c])}, kColumns[c]);
      const core::SourceLocation where{source, line_number, field.column, std::string(kColumns[c])};
      if (c == 0) {
        if (value < 0.0)
          throw core::InputError(where, fmt::format("frequency {} Hz is negative: expected ≥ 0", value));
        if (!spectrum.freq_hz.empty() && value <= spectrum.freq_hz.back())
          throw core::InputError(where, fmt::format("frequency {} Hz does not increase (previous row {} Hz): "
                                                    "expected strictly increasing frequencies",
                                                    value, spectrum.freq_hz.back()));
      } else if (value < 0.0) {
        throw core::InputError(where, fmt::format("power {} is negative: a PSD is ≥ 0", value));
      }
      columns[c]->push_back(value);
    }
    // Fitted-shaper columns are Klipper's own output, not needed here; the marker must stay empty.
    if (layout.marker && !fields[*layout.marker].text.empty())
      throw core::InputError({source, line_number, fields[*layout.marker].column, "shapers:"},
                             fmt::format("expected an empty field under the 'shapers:' marker, found '{}'",
                                         fields[*layout.marker].text));
  }
  if (spectrum.freq_hz.size() < kMinSpectrumRows)
    throw core::InputError({source, line_number, 0, ""},
                           fmt::format("{} frequency rows: expected at least {}", spectrum.freq_hz.size(),
                                       kMinSpectrumRows));
  return spectrum;
}

shaping::Spectrum load_klipper_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the spectrum file");
  return read_klipper_csv(in, path);
}

}  // namespace servotwin::io
