// `servotwin shaper multimode --mode-hz F:ZETA ... [--method lp|convolve]`: one shaper that cancels
// several modes. lp (default) solves the LP of catalog C6.4 on the grid Tp = j·ts (searched, or
// fixed with --tp/--n); convolve multiplies single-mode shapers of one family (C6.4 option 2).
// Prints a summary (impulses, duration, residual vibration at each mode) or servotwin.shaper/1 JSON.
#include "shaper_multimode.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/lp_shaper.hpp"
#include "servotwin/shaping/multimode.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::cli {

namespace {

constexpr std::size_t kCandidatesShown = 5;

struct MultimodeArgs {
  std::vector<std::string> modes;   // "freq_hz:zeta"
  std::vector<std::string> bounds;  // "ratio:s_max"
  std::string method = "lp";
  std::string family = "zvd";
  int derivatives = 0;
  double ts = 0.0;
  double tp = 0.0;
  int n = 0;
  double cost_k = 1.0;
  bool json = false;
  std::string output;
  std::map<std::string, CLI::Option*> given;  // options whose presence matters
  [[nodiscard]] bool has(const std::string& name) const { return given.at(name)->count() > 0; }
};

struct ModeHz {
  double freq_hz = 0.0;
  double zeta = 0.0;
};

struct BoundRatio {
  double ratio = 0.0;
  double s_max = 0.0;
};

double parse_number(const std::string& text, const std::string& option, const std::string& value, const char* what) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(x))
    throw core::InputError(core::at_field(option),
                           fmt::format("expected {} as a finite number in '{}', got '{}'", what, value, text));
  return x;
}

/// "A:B" -> (A, B).
std::pair<double, double> parse_pair(const std::string& value, const std::string& option, const char* first,
                                     const char* second) {
  const std::size_t colon = value.find(':');
  if (colon == std::string::npos || value.find(':', colon + 1) != std::string::npos)
    throw core::InputError(core::at_field(option), fmt::format("expected {}:{}, got '{}'", first, second, value));
  return {parse_number(value.substr(0, colon), option, value, first),
          parse_number(value.substr(colon + 1), option, value, second)};
}

std::vector<ModeHz> parse_modes(const MultimodeArgs& a) {
  std::vector<ModeHz> modes;
  for (const std::string& value : a.modes) {
    const auto [f, z] = parse_pair(value, "--mode-hz", "FREQ_HZ", "ZETA");
    if (f <= 0.0)
      throw core::InputError(core::at_field("--mode-hz"), fmt::format("expected a frequency > 0 Hz in '{}'", value));
    if (z < 0.0 || z >= 1.0)
      throw core::InputError(core::at_field("--mode-hz"), fmt::format("expected a damping ratio in [0, 1) in '{}'", value));
    if (a.has("--ts")) check_below_nyquist(f, a.ts, "--mode-hz");
    modes.push_back({f, z});
  }
  return modes;
}

std::vector<BoundRatio> parse_bounds(const MultimodeArgs& a) {
  std::vector<BoundRatio> bounds;
  for (const std::string& value : a.bounds) {
    const auto [ratio, s_max] = parse_pair(value, "--bound", "F_RATIO", "S_MAX");
    if (ratio <= 0.0)
      throw core::InputError(core::at_field("--bound"), fmt::format("expected a frequency ratio > 0 in '{}'", value));
    if (s_max <= 0.0)
      throw core::InputError(core::at_field("--bound"),
                             fmt::format("expected a vibration bound > 0 (e.g. 0.05 for 5 %) in '{}'", value));
    bounds.push_back({ratio, s_max});
  }
  return bounds;
}

void check_option_use(const MultimodeArgs& a) {
  if (a.method != "lp" && a.method != "convolve")
    throw core::InputError(core::at_field("--method"), "expected lp or convolve, got '" + a.method + "'");
  if (a.has("--ts")) check_sample_period(a.ts);
  if (a.method == "convolve") {
    for (const char* option : {"--derivatives", "--bound", "--tp", "--n", "--cost-k"})
      if (a.has(option)) throw core::InputError(core::at_field(option), "applies only to --method lp");
    return;
  }
  if (a.has("--family")) throw core::InputError(core::at_field("--family"), "applies only to --method convolve");
  if (!a.has("--ts") && !a.has("--tp"))
    throw core::InputError(core::at_field("--ts"),
                           "give --ts (the sample period: the pulse spacing is searched over its multiples) or --tp "
                           "(a fixed pulse spacing)");
  if (a.has("--n") && !a.has("--tp"))
    throw core::InputError(core::at_field("--n"), "needs --tp (a pulse count on a fixed spacing)");
  if (a.has("--tp") && (!std::isfinite(a.tp) || a.tp <= 0.0))
    throw core::InputError(core::at_field("--tp"), fmt::format("expected a pulse spacing > 0 s, got {}", a.tp));
  if (a.has("--tp") && a.has("--ts")) {
    const double multiple = std::round(a.tp / a.ts);
    if (multiple < 1.0 || std::abs(a.tp - multiple * a.ts) > 1e-9 * a.tp)
      throw core::InputError(core::at_field("--tp"),
                             fmt::format("expected a whole multiple of --ts {} s (pulses on the sample grid), got {} s",
                                         a.ts, a.tp));
  }
  if (a.has("--n") && a.n < 1) throw core::InputError(core::at_field("--n"), fmt::format("expected n >= 1, got {}", a.n));
}

/// Library field names -> the options they come from, so errors name what the user typed.
[[noreturn]] void rethrow_as_option(const core::InputError& e) {
  static const std::map<std::string, std::string> options = {
      {"pulse_spacing", "--tp"}, {"pulse_count", "--n"},          {"derivative_order", "--derivatives"},
      {"cost_k", "--cost-k"},    {"sample_period", "--ts"},      {"max_multiple", "--ts"}};
  const std::string& field = e.where().field;
  std::string option;
  if (const auto it = options.find(field); it != options.end()) option = it->second;
  if (field.rfind("bounds[", 0) == 0) option = "--bound";
  if (field.rfind("modes", 0) == 0) option = "--mode-hz";
  if (option.empty()) throw e;
  throw core::InputError(core::at_field(option), e.reason());
}

struct Design {
  shaping::Shaper shaper;
  nlohmann::json parameters;
  std::string grid_text;  // the lp grid summary (empty for convolve)
};

Design design_lp(const MultimodeArgs& a, const std::vector<ModeHz>& modes_hz, const std::vector<BoundRatio>& ratios) {
  std::vector<shaping::LpMode> modes;
  for (const ModeHz& m : modes_hz) modes.push_back({kTwoPi * m.freq_hz, m.zeta});
  shaping::LpShaperOptions options;
  options.derivative_order = a.derivatives;
  options.cost_k = a.cost_k;
  for (const shaping::LpMode& m : modes)
    for (const BoundRatio& b : ratios) options.bounds.push_back({b.ratio * m.omega, m.zeta, b.s_max});
  Design d;
  shaping::LpCandidate best;
  std::string searched;
  try {
    if (a.has("--tp")) {
      options.pulse_spacing = a.tp;
      options.pulse_count = a.has("--n") ? a.n : 0;
      best = shaping::lp_shaper_design(modes, options);
    } else {
      const std::vector<shaping::LpCandidate> found = shaping::lp_shaper_search(modes, options, {a.ts, 0});
      best = found.front();
      searched = fmt::format("  searched Tp = j*{} s: {} feasible spacings; the shortest:\n", a.ts, found.size());
      for (std::size_t i = 0; i < std::min(kCandidatesShown, found.size()); ++i)
        searched += fmt::format("    Tp = {:<8.6g} s  n = {:<5} Tf = {:.6g} s  cost {:.6g}\n", found[i].pulse_spacing,
                                found[i].pulse_count, found[i].grid_duration(), found[i].cost);
    }
  } catch (const core::InputError& e) {
    rethrow_as_option(e);
  }
  d.shaper = best.shaper;
  nlohmann::json freqs = nlohmann::json::array(), zetas = nlohmann::json::array(), bounds = nlohmann::json::array();
  for (const ModeHz& m : modes_hz) {
    freqs.push_back(m.freq_hz);
    zetas.push_back(m.zeta);
  }
  for (const BoundRatio& b : ratios) bounds.push_back({{"ratio", b.ratio}, {"s_max", b.s_max}});
  d.parameters = {{"method", "lp"},       {"modes_hz", freqs},          {"zetas", zetas},
                  {"tp", best.pulse_spacing}, {"n", best.pulse_count}, {"derivative_order", a.derivatives},
                  {"cost_k", a.cost_k},   {"cost", best.cost},          {"bounds", bounds}};
  d.grid_text = searched + fmt::format("  grid: Tp = {:.6g} s, n = {} (grid duration {:.6g} s), cost {} = {:.6g}\n",
                                       best.pulse_spacing, best.pulse_count, best.grid_duration(),
                                       a.cost_k == 0.0 ? "J1" : fmt::format("J2(k={})", a.cost_k), best.cost);
  return d;
}

Design design_convolve(const MultimodeArgs& a, const std::vector<ModeHz>& modes_hz) {
  const shaping::ShaperType type = shaping::parse_shaper_type(a.family, "--family");
  if (type == shaping::ShaperType::kZv4)
    throw core::InputError(core::at_field("--family"), "zv4 needs its p-parameters: design it with `shaper design`");
  std::vector<shaping::Shaper> factors;
  nlohmann::json freqs = nlohmann::json::array(), zetas = nlohmann::json::array();
  for (const ModeHz& m : modes_hz) {
    factors.push_back(shaping::design_shaper(type, kTwoPi * m.freq_hz, m.zeta));
    freqs.push_back(m.freq_hz);
    zetas.push_back(m.zeta);
  }
  Design d;
  d.shaper = shaping::convolve_shapers(factors);
  d.parameters = {{"method", "convolve"}, {"family", a.family}, {"modes_hz", freqs}, {"zetas", zetas}};
  return d;
}

std::string summary(const Design& d, const std::vector<ModeHz>& modes, const std::vector<BoundRatio>& bounds,
                    const nlohmann::json& residuals) {
  const shaping::Shaper& s = d.shaper;
  std::string text = fmt::format("{} shaper for {} {}: {} impulses, duration {:.6g} s\n", s.type, modes.size(),
                                 plural(modes.size(), "mode", "modes"),
                                 s.times.size(), s.duration());
  text += d.grid_text;
  text += "  t [s]            A\n";
  for (std::size_t i = 0; i < s.times.size(); ++i) text += fmt::format("  {:<16.9g} {:.9f}\n", s.times[i], s.amplitudes[i]);
  text += "  residual vibration at each mode:\n";
  for (std::size_t k = 0; k < modes.size(); ++k)
    text += fmt::format("    {:.6g} Hz (zeta {:.4g}): {:.3g}\n", modes[k].freq_hz, modes[k].zeta, residuals[k].get<double>());
  if (!bounds.empty()) {
    text += "  residual vibration at the bound points:\n";
    for (const ModeHz& m : modes)
      for (const BoundRatio& b : bounds)
        text += fmt::format("    {:.6g} Hz ({} x {:.6g} Hz): {:.4g} (bound {:g})\n", b.ratio * m.freq_hz, b.ratio,
                            m.freq_hz, shaping::residual_vibration(s, kTwoPi * b.ratio * m.freq_hz, m.zeta), b.s_max);
  }
  return text;
}

int run_multimode(const MultimodeArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  check_option_use(a);
  const std::vector<ModeHz> modes = parse_modes(a);
  const std::vector<BoundRatio> bounds = parse_bounds(a);
  const Design d = a.method == "lp" ? design_lp(a, modes, bounds) : design_convolve(a, modes);
  progress(global, "{} design of a {}-mode shaper in {:.1f} ms", a.method, modes.size(), elapsed_ms(start));

  io::ShaperFileExtras extras;
  extras.parameters = d.parameters;
  if (a.has("--ts")) extras.ts = a.ts;
  nlohmann::json residuals = nlohmann::json::array();
  for (const ModeHz& m : modes) residuals.push_back(shaping::residual_vibration(d.shaper, kTwoPi * m.freq_hz, m.zeta));
  extras.robustness = {{"residual_at_modes", residuals}};
  const nlohmann::json document = io::shaper_to_json(d.shaper, extras);

  const std::string text = a.json ? document.dump(2) + "\n" : summary(d, modes, bounds, residuals);
  if (a.output.empty()) {
    fmt::print("{}", text);
  } else {
    auto out = open_output(a.output, global);
    out->stream() << (a.json ? text : document.dump(2) + "\n");
    out->commit();
    progress(global, "wrote {} shaper to {}", d.shaper.type, a.output);
    if (!a.json) fmt::print("{}", text);
  }
  return kSuccess;
}

}  // namespace

void add_multimode(CLI::App& shaper, Action& selected) {
  auto a = std::make_shared<MultimodeArgs>();
  CLI::App* cmd = shaper.add_subcommand(
      "multimode", "Design one shaper for several modes: direct LP synthesis (default) or convolution of single-mode shapers");
  cmd->add_option("--mode-hz", a->modes, "A mode to cancel, FREQ_HZ:ZETA (repeat for every mode)")->required();
  cmd->add_option("--method", a->method, "lp (direct LP synthesis on a pulse grid) or convolve")->capture_default_str();
  std::string families;
  for (const std::string& name : shaping::shaper_type_names())
    if (name != "zv4") families += (families.empty() ? "" : "|") + name;
  a->given["--family"] = cmd->add_option("--family", a->family, "convolve: single-mode family per mode: " + families)
                             ->capture_default_str();
  a->given["--derivatives"] = cmd->add_option(
      "--derivatives", a->derivatives, "lp: 0 = zero vibration, 1 = plus zero slope, 2 = plus zero curvature per mode");
  a->given["--bound"] = cmd->add_option(
      "--bound", a->bounds, "lp: vibration bound F_RATIO:S_MAX at F_RATIO x every mode (repeatable, e.g. 0.85:0.05)");
  a->given["--ts"] = cmd->add_option("--ts", a->ts, "Sample period [s]; lp: the pulse spacing is searched over its multiples");
  a->given["--tp"] = cmd->add_option("--tp", a->tp, "lp: fixed pulse spacing [s] (a multiple of --ts when both are given)");
  a->given["--n"] = cmd->add_option("--n", a->n, "lp: pulse count on the --tp grid (default: the smallest feasible)");
  a->given["--cost-k"] = cmd->add_option("--cost-k", a->cost_k, "lp: k of the cost J2 = [1, k+1, 2k+1, ...]·A; 0 = J1")
                             ->capture_default_str();
  cmd->add_flag("--json", a->json, "Print the shaper as servotwin.shaper/1 JSON");
  cmd->add_option("-o,--output", a->output, "Write the shaper JSON to this file ('-' = stdout)");
  set_examples(*cmd,
               "  servotwin shaper multimode --mode-hz 0.159155:0.1 --mode-hz 0.358099:0.1 --mode-hz 0.541127:0.1 \\\n"
               "      --derivatives 1 --ts 0.01 -o shaper.json\n"
               "  servotwin shaper multimode --mode-hz 0.159155:0.1 --mode-hz 0.358099:0.1 --mode-hz 0.541127:0.1 \\\n"
               "      --tp 0.63 --n 14 --bound 0.85:0.05 --bound 1.15:0.05\n"
               "  servotwin shaper multimode --mode-hz 12:0.02 --mode-hz 31:0.05 --method convolve --family mzv --json");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run_multimode(*a, g); }; });
}

}  // namespace servotwin::cli
