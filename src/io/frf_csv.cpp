#include "servotwin/io/frf_csv.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <istream>
#include <numbers>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "csv_lines.hpp"
#include "number_format.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::io {

namespace {

using detail::Field;

constexpr std::string_view kFormat = "servotwin.frf/1";

using detail::trim_blanks;

/// Settings found in `# key: value` comments before the header.
struct Preamble {
  std::optional<core::QualityKind> quality;
  std::optional<double> duration_s;
  std::vector<std::pair<double, std::string>> invalid_notes;  // "# invalid F Hz: why"
};

void parse_comment(std::string_view line, std::size_t line_number, const std::string& source, Preamble& preamble) {
  std::string_view body = trim_blanks(line);
  if (body.empty() || body.front() != '#') return;
  body = trim_blanks(body.substr(1));
  const std::size_t colon = body.find(':');
  if (colon == std::string_view::npos) return;
  const std::string_view key = trim_blanks(body.substr(0, colon));
  const std::string_view value = trim_blanks(body.substr(colon + 1));
  const std::size_t value_column = static_cast<std::size_t>(value.data() - line.data()) + 1;
  if (key == "format") {
    const std::size_t slash = value.rfind('/');
    if (value.substr(0, slash) != "servotwin.frf" || slash == std::string_view::npos)
      throw core::InputError({source, line_number, value_column, "format"},
                             "not a frequency-response file: format '" + std::string(value) + "', expected '" +
                                 std::string(kFormat) + "'");
    const std::string_view major = value.substr(slash + 1, value.find('.', slash) - slash - 1);
    if (major != "1")
      throw core::InputError({source, line_number, value_column, "format"},
                             "unsupported version '" + std::string(value) + "'; this reader knows " + std::string(kFormat));
  } else if (key == "quality") {
    if (value == "coherence") preamble.quality = core::QualityKind::kCoherence;
    else if (value == "thd") preamble.quality = core::QualityKind::kThd;
    else
      throw core::InputError({source, line_number, value_column, "quality"},
                             "unknown quality kind '" + std::string(value) + "', expected coherence or thd");
  } else if (key.rfind("invalid ", 0) == 0 && key.size() > 11 && key.substr(key.size() - 3) == " Hz") {
    // "# invalid 1.5 Hz: THD 0.39 above 0.07": the reason of an invalid point, matched by frequency.
    const std::string_view freq = trim_blanks(key.substr(8, key.size() - 11));
    const double f = detail::parse_number(Field{freq, static_cast<std::size_t>(freq.data() - line.data()) + 1},
                                          {source, line_number, 0, "invalid"}, "invalid");
    // The note is written back on one comment line, so a line break inside it cannot be kept.
    if (const std::size_t cr = value.find('\r'); cr != std::string_view::npos)
      throw core::InputError({source, line_number, value_column + cr, "invalid"},
                             "a carriage return inside the note of an invalid point; end lines with LF or CR LF");
    preamble.invalid_notes.emplace_back(f, std::string(value));
  } else if (key == "duration_s") {
    const double d = detail::parse_number(Field{value, value_column}, {source, line_number, 0, ""}, "duration_s");
    if (!(d > 0.0))
      throw core::InputError({source, line_number, value_column, "duration_s"}, "duration must be > 0 s");
    preamble.duration_s = d;
  }
}

std::size_t index_of(const std::vector<std::string>& header, std::string_view name) {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? std::string::npos : static_cast<std::size_t>(it - header.begin());
}

std::string column_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

/// Column positions of the header; npos = absent.
struct Columns {
  std::size_t freq, re, im, mag_db, phase_deg, quality, snr, amplitude, std_dev, valid;
  std::string quality_name;
  bool polar = false;
};

Columns resolve_columns(const std::vector<std::string>& header, const std::string& source, std::size_t line,
                        Preamble& preamble) {
  Columns c{};
  c.freq = index_of(header, "freq_hz");
  if (c.freq == std::string::npos)
    throw core::InputError({source, line, 0, "freq_hz"},
                           "missing column 'freq_hz' (columns: " + column_list(header) + ")");
  c.re = index_of(header, "re");
  c.im = index_of(header, "im");
  c.mag_db = index_of(header, "mag_db");
  c.phase_deg = index_of(header, "phase_deg");
  if (c.re == std::string::npos || c.im == std::string::npos) {
    if (c.mag_db == std::string::npos || c.phase_deg == std::string::npos)
      throw core::InputError({source, line, 0, "re"},
                             "expected the columns 're, im' or 'mag_db, phase_deg' (columns: " + column_list(header) + ")");
    c.polar = true;
  }
  c.quality = index_of(header, "coherence_or_thd");
  c.quality_name = "coherence_or_thd";
  for (auto [name, kind] : {std::pair{"coherence", core::QualityKind::kCoherence}, std::pair{"thd", core::QualityKind::kThd}}) {
    if (c.quality != std::string::npos) break;
    c.quality = index_of(header, name);
    if (c.quality == std::string::npos) continue;
    c.quality_name = name;
    if (preamble.quality && *preamble.quality != kind)
      throw core::InputError({source, line, 0, name},
                             std::string("column '") + name + "' contradicts the '# quality:' comment");
    preamble.quality = kind;
  }
  c.snr = index_of(header, "snr");
  c.amplitude = index_of(header, "amplitude");
  c.std_dev = index_of(header, "std");
  c.valid = index_of(header, "valid");
  return c;
}

double optional_field(const std::vector<Field>& fields, std::size_t index, const core::SourceLocation& where,
                      std::string_view name) {
  if (index == std::string::npos) return 0.0;
  const double v = detail::parse_number(fields[index], where, name);
  if (v < 0.0)
    throw core::InputError({where.file, where.line, fields[index].column, std::string(name)},
                           fmt::format("column '{}' must be >= 0, got {}", name, v));
  return v;
}

}  // namespace

core::FrequencyResponse read_frf_csv(std::istream& in, std::string_view source_name, const FrfReadOptions& options) {
  const std::string source(source_name);
  std::string line;
  std::size_t line_number = 0;
  Preamble preamble;
  line_number = detail::read_header_line(in, source, line, "a header row such as 'freq_hz,re,im'",
                                         [&](const std::string& skipped, std::size_t number) {
                                           parse_comment(skipped, number, source, preamble);
                                         });
  const std::size_t header_line = line_number;
  std::vector<Field> fields;
  detail::split_csv_line(line, fields);
  std::vector<std::string> header;
  for (const Field& f : fields) header.emplace_back(f.text);
  const Columns c = resolve_columns(header, source, header_line, preamble);

  core::FrequencyResponse response;
  response.quality_kind = preamble.quality.value_or(core::QualityKind::kCoherence);
  response.duration_s = preamble.duration_s;
  while (std::getline(in, line)) {
    ++line_number;
    if (detail::is_skippable_line(line)) continue;
    detail::split_csv_line(line, fields);
    if (fields.size() != header.size())
      throw core::InputError({source, line_number, 0, ""},
                             fmt::format("expected {} fields as in the header, found {}", header.size(), fields.size()));
    const core::SourceLocation where{source, line_number, 0, ""};
    core::FrequencyPoint p;
    p.freq_hz = detail::parse_number(fields[c.freq], where, "freq_hz");
    if (!(p.freq_hz > 0.0))
      throw core::InputError({source, line_number, fields[c.freq].column, "freq_hz"},
                             fmt::format("frequency must be > 0 Hz, got {}", p.freq_hz));
    if (!response.points.empty() && !(p.freq_hz > response.points.back().freq_hz))
      throw core::InputError({source, line_number, fields[c.freq].column, "freq_hz"},
                             fmt::format("frequencies must increase: {} Hz after {} Hz", p.freq_hz,
                                         response.points.back().freq_hz));
    if (c.polar) {
      const double mag_db = detail::parse_number(fields[c.mag_db], where, "mag_db");
      const double phase_deg = detail::parse_number(fields[c.phase_deg], where, "phase_deg");
      // Divided first: phase_deg * π overflows for |phase_deg| above 5.7e307.
      p.value = std::polar(std::pow(10.0, mag_db / 20.0), phase_deg / 180.0 * std::numbers::pi);
    } else {
      p.value = {detail::parse_number(fields[c.re], where, "re"), detail::parse_number(fields[c.im], where, "im")};
    }
    // A magnitude beyond a double (mag_db 1e12, or re and im near 1e308) could not be written back.
    if (!std::isfinite(std::abs(p.value)))
      throw core::InputError({source, line_number, 0, c.polar ? "mag_db" : "re"},
                             c.polar ? "the magnitude overflows a double: mag_db must be below 6165 dB"
                                     : "the magnitude |re + j im| overflows a double");
    p.quality = optional_field(fields, c.quality, where, c.quality_name);
    p.snr = optional_field(fields, c.snr, where, "snr");
    p.amplitude = optional_field(fields, c.amplitude, where, "amplitude");
    p.std_dev = optional_field(fields, c.std_dev, where, "std");
    if (c.valid != std::string::npos) {
      const double v = detail::parse_number(fields[c.valid], where, "valid");
      if (v != 0.0 && v != 1.0)
        throw core::InputError({source, line_number, fields[c.valid].column, "valid"},
                               fmt::format("column 'valid' must be 0 or 1, got {}", v));
      p.valid = v == 1.0;
    }
    response.points.push_back(p);
  }
  if (in.bad()) throw core::InputError({source, line_number, 0, ""}, "read error");
  for (const auto& [freq, note] : preamble.invalid_notes)
    for (core::FrequencyPoint& p : response.points)
      if (p.freq_hz == freq && !p.valid) p.note = note;
  if (response.points.size() < options.min_points)
    throw core::InputError({source, line_number, 0, ""},
                           fmt::format("{} frequency point{}: at least {} are needed", response.points.size(),
                                       response.points.size() == 1 ? "" : "s", options.min_points));
  return response;
}

core::FrequencyResponse read_frf_file(const std::string& path, const FrfReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the file for reading");
  return read_frf_csv(in, path, options);
}

void write_frf_csv(std::ostream& out, const core::FrequencyResponse& response, const std::vector<std::string>& comments) {
  for (std::size_t i = 0; i < response.points.size(); ++i) {
    const core::FrequencyPoint& p = response.points[i];
    if (!(std::isfinite(p.freq_hz) && p.freq_hz > 0.0) || (i > 0 && !(p.freq_hz > response.points[i - 1].freq_hz)))
      throw std::invalid_argument(fmt::format("write_frf_csv: point {} has frequency {} Hz (must be > 0 and increasing)",
                                              i, p.freq_hz));
    if (!std::isfinite(p.value.real()) || !std::isfinite(p.value.imag()) || !std::isfinite(p.quality) ||
        !std::isfinite(p.snr) || !std::isfinite(p.amplitude) || !std::isfinite(p.std_dev))
      throw std::invalid_argument(fmt::format("write_frf_csv: point {} at {} Hz has a non-finite value", i, p.freq_hz));
  }
  for (const auto& comment : comments)
    if (comment.find_first_of("\r\n") != std::string::npos)
      throw std::invalid_argument("write_frf_csv: a comment must be a single line");
  for (const core::FrequencyPoint& p : response.points)
    if (p.note.find_first_of("\r\n") != std::string::npos)
      throw std::invalid_argument("write_frf_csv: a point's note must be a single line");
  fmt::memory_buffer buffer;
  auto to = std::back_inserter(buffer);
  fmt::format_to(to, "# format: {}\n# quality: {}\n", kFormat,
                 response.quality_kind == core::QualityKind::kThd ? "thd" : "coherence");
  if (response.duration_s) fmt::format_to(to, "# duration_s: {}\n", *response.duration_s);
  for (const auto& comment : comments) fmt::format_to(to, "# {}\n", comment);
  for (const core::FrequencyPoint& p : response.points)
    if (!p.valid) fmt::format_to(to, "# invalid {} Hz: {}\n", p.freq_hz, p.note.empty() ? "marked invalid" : p.note);
  fmt::format_to(to, "freq_hz,re,im,mag_db,phase_deg,coherence_or_thd,snr,amplitude,std,valid\n");
  for (const core::FrequencyPoint& p : response.points) {
    const double magnitude = std::abs(p.value);
    // A zero point has no finite dB value; its re/im columns still carry it exactly.
    fmt::format_to(to, "{},{},{},{},{},{},{},{},{},{}\n", p.freq_hz, p.value.real(), p.value.imag(),
                   20.0 * std::log10(magnitude), std::arg(p.value) * 180.0 / std::numbers::pi, p.quality, p.snr,
                   p.amplitude, p.std_dev, p.valid ? 1 : 0);
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
