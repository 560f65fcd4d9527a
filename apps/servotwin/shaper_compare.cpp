// `servotwin shaper compare`: read every shaper file, compare them with
// report::shaper_comparison (shaping::compare_shapers plus Klipper's suggested max accel), print a
// table or a JSON array, and write the HTML report when asked.
#include "shaper_compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/report/shaper_report.hpp"

namespace servotwin::cli {

namespace {

struct CompareArgs {
  std::vector<std::string> paths;
  std::string report_path;
  bool json = false;
  report::ShaperReportOptions options;
  std::optional<double> freq_min_hz, freq_max_hz;
  std::string title;
};

/// A number for JSON: non-finite values (no band, no or unlimited max accel) are null.
nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json rows_json(const std::vector<report::ShaperComparison>& rows, const report::ShaperReportOptions& o) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows) {
    const bool band = r.row.band_width_normalized > 0.0;
    out.push_back({{"file", r.name},
                   {"type", r.row.type},
                   {"freq_hz", r.freq_hz},
                   {"zeta", r.zeta},
                   {"impulse_count", r.row.impulse_count},
                   {"duration_s", r.row.duration_s},
                   {"residual_at_design", r.row.residual_at_design},
                   {"band_level", o.comparison.level},
                   {"band_low_hz", band ? nlohmann::json(r.row.band_low_ratio * r.freq_hz) : nlohmann::json(nullptr)},
                   {"band_high_hz", band ? nlohmann::json(r.row.band_high_ratio * r.freq_hz) : nlohmann::json(nullptr)},
                   {"band_width_normalized", r.row.band_width_normalized},
                   {"smoothing", r.row.smoothing},
                   {"smoothing_accel", o.comparison.accel},
                   {"smoothing_scv", o.comparison.scv},
                   {"max_accel", number_or_null(r.max_accel)},
                   {"max_accel_unlimited", std::isinf(r.max_accel)},
                   {"max_accel_smoothing", o.max_smoothing}});
  }
  return out;
}

std::string rows_text(const std::vector<report::ShaperComparison>& rows, const report::ShaperReportOptions& o) {
  std::size_t name_width = 4;
  for (const auto& r : rows) name_width = std::max(name_width, r.name.size());
  const std::string band_header = fmt::format("band V<={:g}% [Hz]", 100.0 * o.comparison.level);
  std::string text = fmt::format("{:<{}}  {:<9} {:>10} {:>7} {:>3} {:>11} {:>8} {:>21} {:>7} {:>10} {:>10}\n", "file",
                                 name_width, "type", "f [Hz]", "zeta", "n", "duration[s]", "V [%]", band_header, "width",
                                 "smoothing", "max accel");
  for (const auto& r : rows) {
    const std::string band = r.row.band_width_normalized > 0.0
                                 ? fmt::format("{:.4g} - {:.4g}", r.row.band_low_ratio * r.freq_hz, r.row.band_high_ratio * r.freq_hz)
                                 : "empty";
    const std::string accel =
        std::isinf(r.max_accel) ? "unlimited" : (std::isnan(r.max_accel) ? "none" : fmt::format("{:.0f}", r.max_accel));
    text += fmt::format("{:<{}}  {:<9} {:>10.6g} {:>7.4g} {:>3} {:>11.5g} {:>8.3g} {:>21} {:>7.3g} {:>10.4g} {:>10}\n", r.name,
                        name_width, r.row.type, r.freq_hz, r.zeta, r.row.impulse_count, r.row.duration_s,
                        100.0 * r.row.residual_at_design, band, r.row.band_width_normalized, r.row.smoothing, accel);
  }
  text += fmt::format(
      "V: residual vibration at the design point; width: insensitivity band / design frequency; smoothing at accel {:g}, "
      "scv {:g}; max accel keeps smoothing <= {:g} (Klipper's measures, mm and mm/s^2 for Klipper's units)\n",
      o.comparison.accel, o.comparison.scv, o.max_smoothing);
  return text;
}

int run_compare(const CompareArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  report::ShaperReportOptions options = a.options;
  options.freq_min_hz = a.freq_min_hz;
  options.freq_max_hz = a.freq_max_hz;
  if (!a.title.empty()) options.title = a.title;
  // The report file is claimed before the work, so an existing file stops the command early.
  std::shared_ptr<io::OutputFile> report_file = open_report(a.report_path, global);

  std::vector<report::NamedShaper> shapers;
  shapers.reserve(a.paths.size());
  for (const std::string& path : a.paths) shapers.push_back({path, io::load_shaper(path).shaper});

  const auto rename = [](const core::InputError& e, const std::string& field) {
    core::SourceLocation where = e.where();
    where.field = field;
    return core::InputError(where, e.reason());
  };
  std::vector<report::ShaperComparison> rows;
  try {
    rows = report::shaper_comparison(shapers, options);
  } catch (const core::InputError& e) {
    // The library names its option fields; say them as the command-line options.
    const std::string& field = e.where().field;
    if (field == "level") throw rename(e, "--level");
    if (field == "accel") throw rename(e, "--accel");
    if (field == "scv") throw rename(e, "--scv");
    if (field == "max_smoothing") throw rename(e, "--max-smoothing");
    throw;
  }
  fmt::print("{}", a.json ? rows_json(rows, options).dump(2) + "\n" : rows_text(rows, options));

  if (report_file) {
    report::Document doc;
    try {
      doc = report::shaper_report(shapers, options);
    } catch (const core::InputError& e) {
      const std::string& field = e.where().field;
      if (field == "freq_min_hz") throw rename(e, "--freq-min-hz");
      if (field == "freq_max_hz") throw rename(e, "--freq-max-hz");
      throw;
    }
    write_report(doc, *report_file, global);
  }
  progress(global, "compared {} shaper{} in {:.1f} ms", shapers.size(), shapers.size() == 1 ? "" : "s", elapsed_ms(start));
  return kSuccess;
}

}  // namespace

void add_compare(CLI::App& shaper, Action& selected) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* cmd = shaper.add_subcommand(
      "compare", "Compare input shapers for one axis: delay, residual vibration, insensitivity band, smoothing");
  cmd->add_option("shapers", a->paths, "Shaper JSON files (servotwin.shaper/1), one or more")->required()->expected(1, -1);
  add_report_option(*cmd, a->report_path);
  cmd->add_flag("--json", a->json, "Print the comparison as a JSON array (one object per shaper)");
  cmd->add_option("--level", a->options.comparison.level, "Vibration level of the insensitivity band, (0, 1)")
      ->capture_default_str();
  cmd->add_option("--accel", a->options.comparison.accel, "Acceleration for the smoothing measure (Klipper: mm/s^2)")
      ->capture_default_str();
  cmd->add_option("--scv", a->options.comparison.scv, "Square-corner velocity for the smoothing measure (Klipper: mm/s)")
      ->capture_default_str();
  cmd->add_option("--max-smoothing", a->options.max_smoothing, "Smoothing limit of the suggested max accel (Klipper: 0.12 mm)")
      ->capture_default_str();
  cmd->add_option("--freq-min-hz", a->freq_min_hz, "Report: lower end of the frequency axis [Hz] (default 0)");
  cmd->add_option("--freq-max-hz", a->freq_max_hz,
                  "Report: upper end of the frequency axis [Hz] (default 2.5 x the highest design frequency)");
  cmd->add_option("--title", a->title, "Report: title");
  set_examples(*cmd,
               "  servotwin shaper compare zv.json mzv.json ei.json\n"
               "  servotwin shaper compare mzv.json zv4.json --report shapers.html --level 0.1\n"
               "  servotwin shaper compare *.json --json --accel 3000 --scv 5\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run_compare(*a, g); }; });
}

}  // namespace servotwin::cli
