// `servotwin shaper design`: input shapers for a mode of known frequency and damping.
#include <cmath>
#include <filesystem>
#include <numbers>

#include "command.hpp"
#include "shaper_apply.hpp"
#include "shaper_compare.hpp"
#include "shaper_export.hpp"
#include "shaper_multimode.hpp"
#include "shaper_select.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/shaping/discretization.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/smoothing.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::cli {

namespace {


struct DesignArgs {
  std::string type;
  double freq_hz = 0.0;
  double zeta = 0.0;
  double p1 = 0.0, p2 = 0.5, p3 = 0.0;
  std::string preset;
  double v_tol = shaping::kDefaultVibrationTolerance;
  double ts = 0.0;
  double level = 0.05;
  double accel = 5000.0;
  double scv = 5.0;
  bool json = false;
  std::string method = "exact";
  ShaperExport exported;
  std::string output;
  CLI::Option* p_options[4] = {};
  CLI::Option* method_option = nullptr;
  CLI::Option* v_tol_option = nullptr;
  CLI::Option* ts_option = nullptr;
};

void check_option_use(const DesignArgs& a, shaping::ShaperType type) {
  for (CLI::Option* option : a.p_options)
    if (option->count() > 0 && type != shaping::ShaperType::kZv4)
      throw core::InputError(core::at_field(option->get_name()), "applies only to --type zv4, not " + a.type);
  if (a.v_tol_option->count() > 0 && type != shaping::ShaperType::kEi && type != shaping::ShaperType::kTwoHumpEi &&
      type != shaping::ShaperType::kThreeHumpEi)
    throw core::InputError(core::at_field("--v-tol"), "applies only to the EI family (ei, 2hump_ei, 3hump_ei), not " + a.type);
  if (a.p_options[3]->count() > 0 && (a.p_options[0]->count() + a.p_options[1]->count() + a.p_options[2]->count()) > 0)
    throw core::InputError(core::at_field("--preset"), "give either --preset or --p1/--p2/--p3, not both");
}

void check_mode(const DesignArgs& a) {
  if (!std::isfinite(a.freq_hz) || a.freq_hz < 1e-3 || a.freq_hz > 1e5)
    throw core::InputError(core::at_field("--freq-hz"),
                           fmt::format("expected a mode frequency from 0.001 to 1e5 Hz, got {}", a.freq_hz));
  if (!std::isfinite(a.zeta) || a.zeta < 0.0 || a.zeta >= 1.0)
    throw core::InputError(core::at_field("--zeta"), fmt::format("expected a damping ratio in [0, 1), got {}", a.zeta));
  if (a.ts_option->count() > 0) {
    check_sample_period(a.ts);
    check_below_nyquist(a.freq_hz, a.ts, "--freq-hz");
  }
}

int run_design(const DesignArgs& a, const GlobalOptions& global) {
  const shaping::ShaperType type = shaping::parse_shaper_type(a.type, "--type");
  check_option_use(a, type);
  check_mode(a);
  const double omega = kTwoPi * a.freq_hz;
  io::ShaperFileExtras extras;
  shaping::Shaper shaper;
  if (type == shaping::ShaperType::kZv4) {
    const shaping::Zv4Parameters p =
        a.preset.empty() ? shaping::Zv4Parameters{a.p1, a.p2, a.p3} : shaping::zv4_preset(a.preset, "--preset");
    shaper = shaping::zv4_shaper(omega, a.zeta, p);
    extras.parameters = {{"p1", p.p1}, {"p2", p.p2}, {"p3", p.p3}};
    if (!a.preset.empty()) extras.parameters["preset"] = a.preset;
  } else {
    shaper = shaping::design_shaper(type, omega, a.zeta, a.v_tol);
    if (type == shaping::ShaperType::kEi || type == shaping::ShaperType::kTwoHumpEi ||
        type == shaping::ShaperType::kThreeHumpEi)
      extras.parameters = {{"v_tol", a.v_tol}};
  }
  if (a.method_option->count() > 0 && a.ts_option->count() == 0)
    throw core::InputError(core::at_field("--method"), "applies to a discrete shaper: give the sample period with --ts");
  if (a.json && a.exported.requested())
    throw core::InputError(core::at_field("--export"), "give either --json or --export, not both");
  if (a.ts_option->count() > 0) {
    // The discrete shaper on the sample grid (exact vector decomposition or rounding): what a
    // drive running at ts executes, and what `shaper apply` then uses as it is.
    const shaping::DiscretizationMethod method =
        a.method == "round" ? shaping::DiscretizationMethod::Round : shaping::DiscretizationMethod::Exact;
    const shaping::DiscreteShaper discrete = shaping::discretize(shaper, a.ts, method);
    io::DiscreteForm form;
    form.samples = discrete.delays;
    form.discretization = shaping::discretization_method_name(method);
    form.continuous = shaper;
    extras.discrete = form;
    extras.ts = a.ts;
    shaper = discrete.to_shaper();
  }
  if (!(a.level > 0.0 && a.level < 1.0))
    throw core::InputError(core::at_field("--level"), fmt::format("expected a vibration level in (0, 1), got {}", a.level));
  nlohmann::json robustness = {{"band_level", a.level}};
  try {
    const shaping::InsensitiveBand band = shaping::insensitivity_band(shaper, a.level, a.zeta);
    robustness["band_low_hz"] = band.omega_low / kTwoPi;
    robustness["band_high_hz"] = band.omega_high / kTwoPi;
    robustness["band_width_normalized"] = band.normalized_width;
  } catch (const core::InputError&) {
    robustness["band_width_normalized"] = 0.0;  // empty band: V exceeds the level near the mode
  }
  const shaping::SmoothingOffsets smoothing = shaping::smoothing_offsets(shaper, a.accel, a.scv);
  robustness["smoothing"] = smoothing.smoothing();
  robustness["smoothing_accel"] = a.accel;
  robustness["smoothing_scv"] = a.scv;
  extras.robustness = robustness;
  const nlohmann::json document = io::shaper_to_json(shaper, extras);

  std::string text;
  if (a.json) {
    text = document.dump(2) + "\n";
  } else if (a.exported.requested()) {
    text = a.exported.text(shaper);
  } else {
    text = fmt::format("{} shaper for {} Hz, zeta {}: {} impulses, duration {:.6g} s{}\n", shaper.type, a.freq_hz, a.zeta,
                       shaper.times.size(), shaper.duration(),
                       extras.discrete ? fmt::format(" (discrete at ts = {} s, {})", a.ts, extras.discrete->discretization) : "");
    text += "  t [s]            A\n";
    for (std::size_t i = 0; i < shaper.times.size(); ++i)
      text += fmt::format("  {:<16.9g} {:.9f}\n", shaper.times[i], shaper.amplitudes[i]);
    text += fmt::format("  residual vibration at the design frequency: {:.3g}\n",
                        document.at("residual_at_design").get<double>());
    if (robustness.contains("band_low_hz"))
      text += fmt::format("  vibration <= {:g} % from {:.4g} to {:.4g} Hz (width {:.3g} of the design frequency)\n",
                          100.0 * a.level, robustness["band_low_hz"].get<double>(), robustness["band_high_hz"].get<double>(),
                          robustness["band_width_normalized"].get<double>());
    else
      text += fmt::format("  vibration exceeds {:g} % everywhere near the design frequency\n", 100.0 * a.level);
    text += fmt::format("  smoothing {:.4g} (accel {}, scv {}; Klipper's measure)\n", smoothing.smoothing(), a.accel, a.scv);
  }
  if (a.output.empty()) {
    fmt::print("{}", text);
  } else {
    // -o writes the JSON, or the firmware text with --export.
    auto out = open_output(a.output, global);
    out->stream() << (a.json || a.exported.requested() ? text : document.dump(2) + "\n");
    out->commit();
    progress(global, "wrote {} shaper to {}", shaper.type, a.output);
    if (!a.json && !a.exported.requested()) fmt::print("{}", text);
  }
  return kSuccess;
}

void add_design(CLI::App& shaper, Action& selected) {
  auto* design = shaper.add_subcommand("design", "Design an input shaper for a mode of known frequency and damping");
  auto args = std::make_shared<DesignArgs>();
  std::string types;
  for (const std::string& name : shaping::shaper_type_names()) types += (types.empty() ? "" : "|") + name;
  design->add_option("--type", args->type, "Shaper family: " + types)->required();
  design->add_option("--freq-hz", args->freq_hz, "Mode (design) frequency [Hz]")->required();
  design->add_option("--zeta", args->zeta, "Mode damping ratio, [0, 1)")->required();
  args->p_options[0] = design->add_option("--p1", args->p1, "zv4: duration/asymmetry, [-1, 1] (default 0)");
  args->p_options[1] = design->add_option("--p2", args->p2, "zv4: insensitivity, [0, 1) (default 0.5)");
  args->p_options[2] = design->add_option("--p3", args->p3, "zv4: additional parameter for p1 = 0, [0, 1) (default 0)");
  std::string presets;
  for (const auto& preset : shaping::zv4_presets()) presets += (presets.empty() ? "" : "|") + preset.name;
  args->p_options[3] = design->add_option("--preset", args->preset, "zv4: a row of Table 6.1: " + presets);
  args->v_tol_option = design->add_option("--v-tol", args->v_tol, "EI family: vibration tolerance (default 0.05)");
  args->ts_option = design->add_option(
      "--ts", args->ts,
      "Sample period the shaper will run at [s]: writes the discrete shaper, impulses on the grid (checks Nyquist)");
  args->method_option = design->add_option("--method", args->method,
                                           "With --ts: exact (vector decomposition: zero residual kept) or round")
                            ->check(CLI::IsMember({"exact", "round"}))
                            ->capture_default_str();
  args->exported.add_to(*design);
  design->add_option("--level", args->level, "Vibration level of the insensitivity band (default 0.05)");
  design->add_option("--accel", args->accel, "Acceleration for the smoothing measure (default 5000, mm/s^2)");
  design->add_option("--scv", args->scv, "Square-corner velocity for the smoothing measure (default 5, mm/s)");
  design->add_flag("--json", args->json, "Print the shaper as servotwin.shaper/1 JSON");
  design->add_option("-o,--output", args->output, "Write the shaper JSON to this file ('-' = stdout)");
  set_examples(*design,
               "  servotwin shaper design --type zv4 --freq-hz 4.22 --zeta 0.0079 --p1 0.3 --p2 0.5 --ts 0.001 --json\n"
               "  servotwin shaper design --type mzv --freq-hz 50 --zeta 0.1\n"
               "  servotwin shaper design --type zv4 --preset 2hei5 --freq-hz 12 --zeta 0.02 -o shaper.json\n"
               "  servotwin shaper design --type mzv --freq-hz 42 --zeta 0.1 --export klipper --export-axis y\n"
               "  servotwin shaper design --type zv4 --preset 2hei5 --freq-hz 42 --zeta 0.05 --export rrf\n"
               "  servotwin shaper design --type zvd --freq-hz 30 --zeta 0.05 --ts 0.000125 -o zvd_8k.json");
  design->callback([args, &selected] { selected = [args](const GlobalOptions& g) { return run_design(*args, g); }; });
}

}  // namespace

void register_shaper(CLI::App& app, Action& selected) {
  auto* shaper = app.add_subcommand("shaper", "Input shapers: design, apply to a trajectory, select from a measured spectrum or a fitted model, compare, multi-mode synthesis");
  shaper->require_subcommand(1);
  add_design(*shaper, selected);
  add_apply(*shaper, selected);
  add_select(*shaper, selected);
  add_compare(*shaper, selected);
  add_multimode(*shaper, selected);
}

}  // namespace servotwin::cli
