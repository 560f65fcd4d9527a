#include "servotwin/io/trace_profile.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "csv_lines.hpp"
#include "json_reader.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/program_file.hpp"

namespace servotwin::io {

namespace {

constexpr std::string_view kProfileFormat = "servotwin.trace-profile/1";
using detail::JsonObject;
using nlohmann::json;

TraceFormat format_of(const JsonObject& o) {
  const std::string f = o.string_or("trace_format", "csv");
  for (const TraceFormat t : {TraceFormat::Csv, TraceFormat::Halsampler, TraceFormat::Halscope})
    if (f == trace_format_name(t)) return t;
  o.fail("trace_format", "expected csv, halsampler or halscope, got '" + f + "'");
}

}  // namespace

std::optional<double> millimetres_per(std::string_view unit) noexcept {
  if (unit == "mm") return 1.0;
  if (unit == "m") return 1000.0;
  if (unit == "um") return 1e-3;
  if (unit == "nm") return 1e-6;
  if (unit == "inch" || unit == "in") return 25.4;
  return std::nullopt;
}

TraceProfile parse_trace_profile(std::string_view text, std::string_view source_name) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kProfileFormat, source_name);
  const JsonObject o(document, "", source_name);
  o.allow_only({"format", "description", "trace_format", "columns", "map", "units", "scale", "ts", "delimiter",
                "comment_prefix", "max_jitter"});
  TraceProfile p;
  p.description = o.string_or("description", "");
  CaptureReadOptions& r = p.reading;
  r.format = format_of(o);
  if (o.has("columns")) {
    for (const json& c : o.array("columns")) {
      if (!c.is_string() || c.get<std::string>().empty()) o.fail("columns", "expected a list of non-empty column names");
      r.columns.push_back(c.get<std::string>());
    }
  }
  if (const auto map = o.optional_object("map")) {
    for (const auto& [ours, theirs] : document["map"].items()) {
      if (!theirs.is_string() || theirs.get<std::string>().empty())
        map->fail(ours, "expected the file's column name for '" + ours + "'");
      r.map.emplace_back(detail::lower(ours), theirs.get<std::string>());
    }
  }
  p.units = o.string_or("units", "");
  if (!p.units.empty()) {
    const auto per = millimetres_per(p.units);
    if (!per) o.fail("units", "expected mm, m, um, nm or inch, got '" + p.units + "'");
    r.scale = o.number_or("scale", *per);
    if (std::abs(r.scale - *per) > 1e-12 * *per)
      o.fail("scale", "the scale " + json(r.scale).dump() + " disagrees with units '" + p.units + "' (" + json(*per).dump() +
                          " mm per unit)");
  } else {
    r.scale = o.number_or("scale", 1.0);
    if (r.scale == 0.0) o.fail("scale", "expected a non-zero factor to mm");
  }
  if (const auto ts = o.optional_number("ts")) {
    if (!(*ts > 0.0)) o.fail("ts", "expected a sample period > 0 s");
    r.ts = *ts;
  }
  const std::string delimiter = o.string_or("delimiter", ",");
  if (delimiter.size() != 1 || delimiter == "\"") o.fail("delimiter", "expected one character such as \",\", \";\" or \"\\t\"");
  r.delimiter = delimiter.front();
  r.comment_prefix = o.string_or("comment_prefix", "#");
  if (r.comment_prefix.empty()) o.fail("comment_prefix", "must not be empty");
  r.max_jitter = o.number_or("max_jitter", r.max_jitter);
  if (!(r.max_jitter >= 0.0 && r.max_jitter < 0.5)) o.fail("max_jitter", "expected a fraction of the period in [0, 0.5)");
  return p;
}

TraceProfile read_trace_profile(const std::string& path) {
  return parse_trace_profile(read_text_file(path, std::size_t{1} << 20), path);
}

void write_trace_profile(std::ostream& out, const TraceProfile& p) {
  const CaptureReadOptions& r = p.reading;
  nlohmann::ordered_json j;
  j["format"] = kProfileFormat;
  if (!p.description.empty()) j["description"] = p.description;
  j["trace_format"] = trace_format_name(r.format);
  if (!r.columns.empty()) j["columns"] = r.columns;
  if (!r.map.empty()) {
    nlohmann::ordered_json map = nlohmann::ordered_json::object();
    for (const auto& [ours, theirs] : r.map) map[ours] = theirs;
    j["map"] = map;
  }
  // The unit when the scale is one's, else the scale itself.
  std::string unit;
  for (const char* u : {"mm", "m", "um", "nm", "inch"})
    if (millimetres_per(u) == r.scale) unit = u;
  if (!unit.empty()) {
    j["units"] = unit;
  } else {
    j["scale"] = r.scale;
  }
  if (r.ts) j["ts"] = *r.ts;
  if (r.format == TraceFormat::Csv && r.delimiter != ',') j["delimiter"] = std::string(1, r.delimiter);
  if (r.comment_prefix != "#") j["comment_prefix"] = r.comment_prefix;
  if (r.max_jitter != CaptureReadOptions{}.max_jitter) j["max_jitter"] = r.max_jitter;
  out << j.dump(2) << '\n';
}

}  // namespace servotwin::io
