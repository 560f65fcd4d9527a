#pragma once
// Shared pieces of the report tests: render a document, pull the embedded chart data out of the
// HTML, and a real identification to report on.

#include <nlohmann/json.hpp>

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "servotwin/machine/presets.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/report/document.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/vcnc/machine_run.hpp"

namespace servotwin::report::testing {

inline std::string render(const Document& doc, const HtmlOptions& options = {}) {
  std::ostringstream out;
  write_html(out, doc, options);
  return out.str();
}

/// Occurrences of `needle` in `text`.
inline std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++n;
  return n;
}

/// The text of <script type="application/json" id="report-data">, as the browser's HTML parser
/// sees it: everything up to the first "</script".
inline std::string data_text(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"report-data\">";
  const std::size_t begin = html.find(open);
  if (begin == std::string::npos) throw std::runtime_error("no report-data script element");
  const std::size_t content = begin + open.size();
  const std::size_t end = html.find("</script", content);
  if (end == std::string::npos) throw std::runtime_error("report-data is not closed");
  return html.substr(content, end - content);
}

inline nlohmann::json chart_data(const std::string& html) { return nlohmann::json::parse(data_text(html)); }

/// Capture of a thesis Table 3.2-style X program (200 random moves within +-10 mm at F12000) on a
/// virtual machine preset, as tests/validation does.
inline vcnc::NamedCapture thesis_capture(const std::string& machine_name, std::uint64_t seed, std::size_t moves = 200) {
  const machine::MachineConfig machine = machine::preset(machine_name);
  motion::IdentificationOptions o = motion::identification_defaults(motion::IdentificationSet::Standard);
  o.axes = {motion::Axis::X};
  o.seed = seed;
  o.moves = moves;
  const motion::Program program = motion::make_identification_program(o);
  return {machine_name + " seed " + std::to_string(seed), vcnc::run_program(machine, program)};
}

}  // namespace servotwin::report::testing
