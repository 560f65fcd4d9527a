// The HTML writer of document.hpp: one self-contained file with the chart library, the glue and
// the chart data (embedded JSON) inlined.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>

#include "servotwin/core/error.hpp"
#include "servotwin/report/document.hpp"
#include "web_assets.hpp"

namespace servotwin::report {

namespace {

constexpr std::string_view kReplacement = "\xEF\xBF\xBD";  // U+FFFD

/// Decodes the UTF-8 code point at s[i]; returns its length in bytes, 0 when the bytes there are
/// not valid UTF-8 (overlong forms, surrogates and values above U+10FFFF included).
std::size_t utf8_length(std::string_view s, std::size_t i, std::uint32_t& code) {
  const auto byte = [&](std::size_t k) { return static_cast<std::uint8_t>(s[k]); };
  const std::uint8_t b0 = byte(i);
  std::size_t length = 0;
  std::uint32_t min = 0;
  if (b0 < 0x80) {
    code = b0;
    return 1;
  }
  if ((b0 & 0xE0) == 0xC0) {
    length = 2, code = b0 & 0x1Fu, min = 0x80;
  } else if ((b0 & 0xF0) == 0xE0) {
    length = 3, code = b0 & 0x0Fu, min = 0x800;
  } else if ((b0 & 0xF8) == 0xF0) {
    length = 4, code = b0 & 0x07u, min = 0x10000;
  } else {
    return 0;
  }
  if (i + length > s.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(i + k) & 0x3Fu);
  }
  if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return length;
}

/// Calls `emit(code, bytes)` for every code point of `s`, appending U+FFFD to `out` for invalid
/// UTF-8 instead.
template <typename Emit>
void for_each_code_point(std::string& out, std::string_view s, Emit emit) {
  for (std::size_t i = 0; i < s.size();) {
    std::uint32_t code = 0;
    const std::size_t length = utf8_length(s, i, code);
    if (length == 0) {
      out += kReplacement;
      ++i;
      continue;
    }
    emit(code, s.substr(i, length));
    i += length;
  }
}

/// Text for HTML element content and attribute values: markup characters as entities, control
/// characters other than tab and line breaks and invalid UTF-8 as U+FFFD.
void append_html(std::string& out, std::string_view s) {
  for_each_code_point(out, s, [&](std::uint32_t code, std::string_view bytes) {
    switch (code) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default:
        if ((code < 0x20 && code != '\t' && code != '\n' && code != '\r') || code == 0x7F) out += kReplacement;
        else out.append(bytes);
    }
  });
}

/// A JSON string literal that is also safe inside <script type="application/json">: '<', '>'
/// and '&' are \u escapes, so neither "</script" nor "<!--" can occur.
void append_json_string(std::string& out, std::string_view s) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += '"';
  for_each_code_point(out, s, [&](std::uint32_t code, std::string_view bytes) {
    switch (code) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (code < 0x20 || code == '<' || code == '>' || code == '&' || code == 0x2028 || code == 0x2029) {
          out += "\\u";
          for (int shift = 12; shift >= 0; shift -= 4) out += kHex[(code >> shift) & 0xFu];
        } else {
          out.append(bytes);
        }
    }
  });
  out += '"';
}

/// A JSON number with 9 significant digits, or null.
void append_number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::general, 9);
  out.append(buffer, result.ptr);
}

/// "600 000" for people.
std::string grouped(std::size_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += "\u202F";  // narrow no-break space
    out += digits[i];
  }
  return out;
}

std::string series_where(std::size_t s, std::size_t c, std::size_t k) {
  return "sections[" + std::to_string(s) + "].charts[" + std::to_string(c) + "].series[" + std::to_string(k) + "]";
}

/// Points of a line-chart series that can be placed on its x axis (finite x, positive on a log
/// axis), decimated for display. Returns the number of points shown.
std::size_t append_line_series_data(std::string& out, const Series& series, const Chart& chart,
                                     std::size_t max_points) {
  const bool log_x = chart.x_scale == Scale::Log, log_y = chart.y_scale == Scale::Log;
  const auto placeable = [&](double x) { return std::isfinite(x) && (!log_x || x > 0.0); };
  std::vector<double> x_kept, y_kept;
  std::span<const double> x = series.x, y = series.y;
  bool all_placeable = true;
  for (double v : series.x) all_placeable = all_placeable && placeable(v);
  if (!all_placeable) {
    for (std::size_t k = 0; k < series.x.size(); ++k) {
      if (!placeable(series.x[k])) continue;
      x_kept.push_back(series.x[k]);
      y_kept.push_back(series.y[k]);
    }
    x = x_kept;
    y = y_kept;
  }
  const std::vector<std::size_t> shown = display_indices(y, max_points);
  out += ",\"x\":[";
  for (std::size_t i = 0; i < shown.size(); ++i) {
    if (i > 0) out += ',';
    append_number(out, x[shown[i]]);
  }
  out += "],\"y\":[";
  for (std::size_t i = 0; i < shown.size(); ++i) {
    if (i > 0) out += ',';
    const double v = y[shown[i]];
    append_number(out, log_y && !(v > 0.0) ? std::nan("") : v);
  }
  out += ']';
  return shown.size();
}

/// Path points decimated for display; a point with a non-finite coordinate is null in both.
std::size_t append_path_series_data(std::string& out, const Series& series, std::size_t max_points) {
  const std::vector<std::size_t> shown = display_path_indices(series.x, series.y, max_points);
  for (const auto* values : {&series.x, &series.y}) {
    out += values == &series.x ? ",\"x\":[" : ",\"y\":[";
    for (std::size_t i = 0; i < shown.size(); ++i) {
      if (i > 0) out += ',';
      const std::size_t k = shown[i];
      const bool finite = std::isfinite(series.x[k]) && std::isfinite(series.y[k]);
      append_number(out, finite ? (*values)[k] : std::nan(""));
    }
    out += ']';
  }
  return shown.size();
}

struct ChartStats {
  std::size_t samples = 0;  ///< longest series
  std::size_t shown = 0;    ///< most points shown of a series
  bool decimated = false;
};

ChartStats append_chart_json(std::string& out, const Chart& chart, const HtmlOptions& options) {
  ChartStats stats;
  out += "{\"title\":";
  append_json_string(out, chart.title);
  out += ",\"x_label\":";
  append_json_string(out, chart.x_label);
  out += ",\"y_label\":";
  append_json_string(out, chart.y_label);
  out += chart.equal_axes ? ",\"path\":true" : ",\"path\":false";
  out += !chart.equal_axes && chart.x_scale == Scale::Log ? ",\"x_log\":true" : ",\"x_log\":false";
  out += !chart.equal_axes && chart.y_scale == Scale::Log ? ",\"y_log\":true" : ",\"y_log\":false";
  out += ",\"series\":[";
  for (std::size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    if (k > 0) out += ',';
    out += "{\"label\":";
    append_json_string(out, s.label);
    out += ",\"samples\":" + std::to_string(s.x.size());
    const std::size_t shown = chart.equal_axes ? append_path_series_data(out, s, options.max_path_points)
                                               : append_line_series_data(out, s, chart, options.max_points);
    out += '}';
    stats.samples = std::max(stats.samples, s.x.size());
    stats.shown = std::max(stats.shown, shown);
    stats.decimated = stats.decimated || shown < s.x.size();
  }
  out += "]}";
  return stats;
}

void append_paragraphs(std::string& out, std::string_view text) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find("\n\n", start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view paragraph = text.substr(start, end - start);
    while (!paragraph.empty() && paragraph.front() == '\n') paragraph.remove_prefix(1);
    if (!paragraph.empty()) {
      out += "<p>";
      for (std::size_t i = 0; i < paragraph.size();) {
        const std::size_t line_end = std::min(paragraph.find('\n', i), paragraph.size());
        if (i > 0) out += "<br>";
        append_html(out, paragraph.substr(i, line_end - i));
        i = line_end + 1;
      }
      out += "</p>\n";
    }
    start = end + 2;
  }
}

void append_table(std::string& out, const Table& table) {
  out += "<div class=\"table-wrap\"><table>";
  if (!table.title.empty()) {
    out += "<caption>";
    append_html(out, table.title);
    out += "</caption>";
  }
  if (!table.header.empty()) {
    out += "<thead><tr>";
    for (const auto& cell : table.header) {
      out += "<th scope=\"col\">";
      append_html(out, cell);
      out += "</th>";
    }
    out += "</tr></thead>";
  }
  out += "<tbody>\n";
  for (const auto& row : table.rows) {
    out += "<tr>";
    for (const auto& cell : row) {
      out += "<td>";
      append_html(out, cell);
      out += "</td>";
    }
    out += "</tr>\n";
  }
  out += "</tbody></table></div>\n";
}

void validate(const Document& doc, const HtmlOptions& options) {
  if (options.max_points < kMinDisplayPoints) {
    throw core::InputError({"", 0, 0, "max_points"}, "need at least " + std::to_string(kMinDisplayPoints) +
                                                         " display points per series, got " +
                                                         std::to_string(options.max_points));
  }
  if (options.max_path_points < kMinDisplayPoints || options.max_path_points > kMaxPathPoints) {
    throw core::InputError({"", 0, 0, "max_path_points"}, "need " + std::to_string(kMinDisplayPoints) + " to " +
                                                              std::to_string(kMaxPathPoints) +
                                                              " display points per path series, got " +
                                                              std::to_string(options.max_path_points));
  }
  for (std::size_t s = 0; s < doc.sections.size(); ++s) {
    const auto& charts = doc.sections[s].charts;
    for (std::size_t c = 0; c < charts.size(); ++c) {
      for (std::size_t k = 0; k < charts[c].series.size(); ++k) {
        const Series& series = charts[c].series[k];
        if (series.x.size() != series.y.size()) {
          throw core::InputError({"", 0, 0, series_where(s, c, k)},
                                 "series '" + series.label + "' of chart '" + charts[c].title + "' has " +
                                     std::to_string(series.x.size()) + " x but " + std::to_string(series.y.size()) +
                                     " y values");
        }
      }
    }
  }
}

}  // namespace

std::size_t chart_count(const Document& doc) {
  std::size_t n = 0;
  for (const auto& s : doc.sections) n += s.charts.size();
  return n;
}

void write_html(std::ostream& stream, const Document& doc, const HtmlOptions& options) {
  validate(doc, options);
  const detail::WebAssets assets = detail::web_assets();

  // Chart data first: the figures' captions say how much of each chart is shown.
  std::string data = "{\"format\":\"servotwin.report-data/1\",\"charts\":[";
  std::vector<ChartStats> stats;
  for (const auto& section : doc.sections) {
    for (const auto& chart : section.charts) {
      if (!stats.empty()) data += ",\n";
      stats.push_back(append_chart_json(data, chart, options));
    }
  }
  data += "]}";

  std::string out;
  out.reserve(data.size() + assets.chart_library_js.size() + assets.chart_library_css.size() +
              assets.glue_js.size() + assets.glue_css.size() + assets.chart_library_license.size() + 65536);
  out += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         "<meta name=\"generator\" content=\"servotwin\">\n<title>";
  append_html(out, doc.title);
  out += "</title>\n<style>\n";
  out += assets.chart_library_css;
  out += "\n</style>\n<style>\n";
  out += assets.glue_css;
  out += "\n</style>\n</head>\n<body>\n<header>\n<h1>";
  append_html(out, doc.title);
  out += "</h1>\n";
  if (!doc.subtitle.empty()) {
    out += "<p class=\"subtitle\">";
    append_html(out, doc.subtitle);
    out += "</p>\n";
  }
  out += "</header>\n";
  if (doc.sections.size() > 1) {
    out += "<nav class=\"toc\"><ol>\n";
    for (std::size_t s = 0; s < doc.sections.size(); ++s) {
      out += "<li><a href=\"#section-" + std::to_string(s + 1) + "\">";
      append_html(out, doc.sections[s].title);
      out += "</a></li>\n";
    }
    out += "</ol></nav>\n";
  }
  out += "<main>\n";
  std::size_t chart_index = 0;
  for (std::size_t s = 0; s < doc.sections.size(); ++s) {
    const Section& section = doc.sections[s];
    out += "<section id=\"section-" + std::to_string(s + 1) + "\">\n<h2>";
    append_html(out, section.title);
    out += "</h2>\n";
    append_paragraphs(out, section.text);
    for (const auto& table : section.tables) append_table(out, table);
    for (const auto& chart : section.charts) {
      const ChartStats& st = stats[chart_index];
      out += "<figure class=\"chart" + std::string(chart.equal_axes ? " path-chart" : "") + "\" id=\"chart-" +
             std::to_string(chart_index) + "\" data-chart=\"" + std::to_string(chart_index) + "\">\n<figcaption>";
      append_html(out, chart.title);
      if (st.decimated) {
        out += " <span class=\"note\">(" + grouped(st.shown) + " of " + grouped(st.samples) + " points drawn";
        out += chart.equal_axes ? ", path simplified for display)" : ", minimum and maximum per bucket)";
        out += "</span>";
      }
      out += "</figcaption>\n<div class=\"plot\"></div>\n"
             "<noscript><p class=\"no-script\">This chart is drawn by JavaScript, which is disabled.</p></noscript>\n"
             "</figure>\n";
      ++chart_index;
    }
    out += "</section>\n";
  }
  out += "</main>\n<footer><p>Made with servotwin. Drag across a chart to zoom (double-click to reset), hover for "
         "values, click a legend entry to hide its curve. Charts are drawn by ";
  out += assets.chart_library_name;
  out += ' ';
  out += assets.chart_library_version;
  out += " (MIT license, embedded in this file).</p></footer>\n"
         "<pre id=\"report-errors\" hidden></pre>\n<script>\n";
  out += assets.glue_js;
  out += "\n</script>\n<script>\n/*\n";
  out += assets.chart_library_name;
  out += ' ';
  out += assets.chart_library_version;
  out += "\n\n";
  out += assets.chart_library_license;
  out += "\n*/\n";
  out += assets.chart_library_js;
  out += "\n</script>\n<script type=\"application/json\" id=\"report-data\">\n";
  out += data;
  out += "\n</script>\n</body>\n</html>\n";
  stream.write(out.data(), static_cast<std::streamsize>(out.size()));
}

}  // namespace servotwin::report
