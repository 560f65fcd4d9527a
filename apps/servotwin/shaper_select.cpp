// `servotwin shaper select resonances_x.csv|plant_model.json [--max-smoothing S] [--json]`:
// choose family and frequency from a Klipper PSD CSV (measured spectrum, damping unknown) or from
// a fitted plant model (modes with known damping); print a Klipper-like table and the reasons, or
// the recommended shaper as servotwin.shaper/1 JSON with `alternatives` and `reasons`.
#include "shaper_select.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/io/klipper_csv.hpp"
#include "servotwin/io/plant_model_json.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/shaping/firmware.hpp"
#include "servotwin/shaping/selection.hpp"
#include "shaper_export.hpp"

namespace servotwin::cli {

namespace {


struct SelectArgs {
  std::string input;
  std::optional<double> max_smoothing;
  std::optional<double> max_delay_ms;
  std::string axis = "xyz";
  std::string families;
  double accel = 5000.0;
  double scv = 5.0;
  double freq_uncertainty = 0.05;
  bool no_multi_mode = false;
  bool any_shaper = false;
  bool json = false;
  ShaperExport exported;
  std::string output;
};

bool is_json_path(const std::string& path) {
  return path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
}

std::vector<shaping::ShaperType> parse_families(const std::string& list) {
  std::vector<shaping::ShaperType> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = list.find(',', start);
    const std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!name.empty()) out.push_back(shaping::parse_shaper_type(name, "--families"));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.empty()) throw core::InputError(core::at_field("--families"), "expected a comma-separated list of families");
  return out;
}

/// Klipper's types among servotwin's families: what a Klipper printer can run.
std::vector<shaping::ShaperType> klipper_families() {
  std::vector<shaping::ShaperType> out;
  for (const std::string& name : shaping::klipper_shaper_types()) out.push_back(shaping::parse_shaper_type(name));
  return out;
}

std::string freq_text(const shaping::ShaperCandidate& c) {
  std::string out;
  for (std::size_t i = 0; i < c.freq_hz.size(); ++i) out += fmt::format("{}{:.1f}", i ? "+" : "", c.freq_hz[i]);
  return out;
}

nlohmann::json candidate_json(const shaping::ShaperCandidate& c) {
  nlohmann::json j = {{"name", c.name},           {"freq_hz", c.freq_hz},       {"vibrations", c.vibrations},
                      {"smoothing", c.smoothing}, {"max_accel", c.max_accel},   {"duration_s", c.duration_s},
                      {"times_s", c.shaper.times}, {"amplitudes", c.shaper.amplitudes}};
  if (!std::isnan(c.vibrations_assumed_damping)) j["vibrations_assumed_damping"] = c.vibrations_assumed_damping;
  return j;
}

std::string table_text(const shaping::ShaperSelection& sel, bool model, const std::string& what) {
  std::string t = what + "\n";
  t += fmt::format("  {:<14} {:>12} {:>11} {:>10} {:>10} {:>9}{}\n", "shaper", "freq [Hz]",
                   model ? "worst resid" : "vibrations", "smoothing", "max_accel", "delay ms",
                   model ? "  (if ζ=0.1 assumed)" : "");
  for (const shaping::ShaperCandidate& c : sel.alternatives) {
    t += fmt::format("  {:<14} {:>12} {:>10.1f}% {:>10.3f} {:>10.0f} {:>9.2f}", c.name, freq_text(c),
                     100.0 * c.vibrations, c.smoothing, std::round(c.max_accel / 100.0) * 100.0, 1e3 * c.duration_s);
    if (model && !std::isnan(c.vibrations_assumed_damping))
      t += fmt::format("  {:>8.1f}%", 100.0 * c.vibrations_assumed_damping);
    t += "\n";
  }
  t += fmt::format("Recommended shaper is {} @ {} Hz\n", sel.recommended.name, freq_text(sel.recommended));
  for (const std::string& r : sel.reasons) t += "  - " + r + "\n";
  return t;
}

int run_select(const SelectArgs& a, const GlobalOptions& global) {
  if (a.max_delay_ms && !(std::isfinite(*a.max_delay_ms) && *a.max_delay_ms > 0.0))
    throw core::InputError(core::at_field("--max-delay-ms"), fmt::format("expected a delay > 0 ms, got {}", *a.max_delay_ms));
  shaping::ShaperSelection sel;
  std::string what;
  const bool model = is_json_path(a.input);
  if (model) {
    const io::LoadedPlantModel loaded = io::load_plant_model(a.input);
    std::vector<shaping::KnownMode> modes;
    for (const fit::Mode& m : loaded.model.modes) modes.push_back({m.resonance.omega_rad_s / kTwoPi, m.resonance.zeta});
    if (modes.empty())
      throw core::InputError(core::SourceLocation{a.input, 0, 0, "modes"},
                             "the plant model has no flexible mode: there is nothing for a shaper to cancel");
    shaping::ModelSelectionOptions o;
    if (!a.families.empty()) o.families = parse_families(a.families);
    o.max_smoothing = a.max_smoothing;
    if (a.max_delay_ms) o.max_delay_s = *a.max_delay_ms * 1e-3;
    o.accel = a.accel;
    o.scv = a.scv;
    o.freq_uncertainty = a.freq_uncertainty;
    sel = shaping::select_shaper_from_model(modes, o);
    what = fmt::format("Shapers for the {} fitted {} of {} (damping known):", modes.size(),
                       plural(modes.size(), "mode", "modes"), a.input);
  } else {
    shaping::Spectrum spectrum = io::load_klipper_csv(a.input);
    shaping::SpectrumSelectionOptions o;
    o.axis = shaping::parse_spectrum_axis(a.axis, "--axis");
    o.max_smoothing = a.max_smoothing;
    if (a.max_delay_ms) o.max_delay_s = *a.max_delay_ms * 1e-3;
    o.accel = a.accel;
    o.scv = a.scv;
    // A Klipper spectrum comes from a Klipper printer: by default the shapers it can run.
    shaping::SpectrumSelectionOptions klipper = o;
    klipper.families = klipper_families();
    klipper.multi_mode = false;
    if (!a.families.empty()) o.families = parse_families(a.families);
    o.multi_mode = !a.no_multi_mode;
    const bool klipper_only = !a.any_shaper && a.families.empty();
    sel = shaping::select_shaper_from_spectrum(spectrum, klipper_only ? klipper : o);
    what = fmt::format("Shapers fitted to {} (psd_{}, {}; designed for ζ = 0.1{}):", a.input, a.axis,
                       spectrum.normalized ? "already normalized" : "normalized by (f + 0.1)",
                       klipper_only ? "; Klipper's types, --any-shaper for ZVDD, ZV4 and two-mode shapers" : "");
    if (!klipper_only && !shaping::klipper_has(sel.recommended.shaper.type)) {
      const shaping::ShaperSelection k = shaping::select_shaper_from_spectrum(spectrum, klipper);
      sel.reasons.push_back(fmt::format(
          "against the best shaper Klipper can run, {} @ {} Hz: remaining vibrations {:.1f} % -> {:.1f} %, smoothing "
          "{:.3f} -> {:.3f}",
          k.recommended.name, freq_text(k.recommended), 100.0 * k.recommended.vibrations, 100.0 * sel.recommended.vibrations,
          k.recommended.smoothing, sel.recommended.smoothing));
    }
  }

  io::ShaperFileExtras extras;
  extras.robustness = {{"smoothing", sel.recommended.smoothing},
                       {"smoothing_accel", a.accel},
                       {"smoothing_scv", a.scv},
                       {"max_accel", sel.recommended.max_accel},
                       {model ? "worst_residual" : "remaining_vibrations", sel.recommended.vibrations}};
  nlohmann::json document = io::shaper_to_json(sel.recommended.shaper, extras);
  document["alternatives"] = nlohmann::json::array();
  for (const shaping::ShaperCandidate& c : sel.alternatives) document["alternatives"].push_back(candidate_json(c));
  document["reasons"] = sel.reasons;

  const std::string text = table_text(sel, model, what);
  const std::string json_text = document.dump(2) + "\n";
  if (a.json && a.exported.requested())
    throw core::InputError(core::at_field("--export"), "give either --json or --export, not both");
  const std::string file_text = a.exported.requested() ? a.exported.text(sel.recommended.shaper) : json_text;
  if (a.output.empty()) {
    fmt::print("{}", a.json || a.exported.requested() ? file_text : text);
  } else {
    auto out = open_output(a.output, global);
    out->stream() << file_text;
    out->commit();
    progress(global, "wrote {} shaper to {}", sel.recommended.name, a.output);
    if (!a.json) fmt::print("{}", text);
  }
  return kSuccess;
}

}  // namespace

void add_select(CLI::App& shaper, Action& selected) {
  auto args = std::make_shared<SelectArgs>();
  auto* select = shaper.add_subcommand(
      "select", "Choose shaper family and frequency from a Klipper PSD CSV or a fitted plant model (.json)");
  select->add_option("input", args->input, "resonances_*.csv / calibration_data_*.csv, or plant_model.json")
      ->required()
      ->check(CLI::ExistingFile);
  select->add_option("--max-smoothing", args->max_smoothing,
                     "Limit on Klipper's smoothing at --accel/--scv (default: suggested max_accel >= 1500)");
  select->add_option("--max-delay-ms", args->max_delay_ms, "Limit on the shaper duration [ms]");
  select->add_option("--axis", args->axis, "PSD column of a CSV: x, y, z or xyz (default xyz, as Klipper)");
  select->add_option("--families", args->families,
                     "Comma-separated families to consider (default: Klipper's types for a CSV, all for a plant model)");
  select->add_option("--accel", args->accel, "Acceleration of the smoothing measure (default 5000, mm/s^2)");
  select->add_option("--scv", args->scv, "Square-corner velocity of the smoothing measure (default 5, mm/s)");
  select->add_option("--freq-uncertainty", args->freq_uncertainty,
                     "Plant model: relative frequency band each mode must be covered over (default 0.05)");
  select->add_flag("--no-multi-mode", args->no_multi_mode, "CSV: do not consider two-mode (convolved) shapers");
  select->add_flag("--any-shaper", args->any_shaper,
                   "CSV: consider every family and two-mode shapers, not only Klipper's types (the gain over the "
                   "Klipper pick is printed)");
  args->exported.add_to(*select);
  select->add_flag("--json", args->json, "Print the recommended shaper as servotwin.shaper/1 JSON");
  select->add_option("-o,--output", args->output, "Write the shaper JSON to this file ('-' = stdout)");
  set_examples(*select,
               "  servotwin shaper select resonances_x_20221231_212825.csv\n"
               "  servotwin shaper select resonances_y.csv --max-smoothing 0.1 --json -o shaper_y.json\n"
               "  servotwin shaper select plant_model.json --max-delay-ms 30\n"
               "  servotwin shaper select resonances_x.csv --export klipper\n"
               "  servotwin shaper select resonances_x.csv --any-shaper --export rrf");
  select->callback([args, &selected] { selected = [args](const GlobalOptions& g) { return run_select(*args, g); }; });
}

}  // namespace servotwin::cli
