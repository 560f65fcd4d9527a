#pragma once
// The web assets every report embeds: the charting library (installed from npm at configure time)
// and servotwin's glue, compiled in as byte arrays by cmake/EmbedWebAssets.cmake.

#include <cstddef>
#include <string_view>

namespace servotwin::report::detail {

struct WebAssets {
  std::string_view chart_library_name;
  std::string_view chart_library_version;
  std::string_view chart_library_js;       ///< minified, inlined in a <script> element
  std::string_view chart_library_css;
  std::string_view chart_library_license;  ///< MIT text, kept with the copy in every report
  std::string_view glue_js;                ///< web/src/report.js: embedded JSON -> charts
  std::string_view glue_css;               ///< web/src/report.css
};

/// Defined in the generated web_assets.cpp.
WebAssets web_assets();

}  // namespace servotwin::report::detail
