// `servotwin shaper apply shaper.json trajectory.csv -o shaped.csv`: discretize the shaper at the
// trajectory's sample period, shape every `<axis>_cmd` column, write the shaped columns and the
// contour distortion (distance of each shaped point to the commanded path), print a summary.
#include "shaper_apply.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/io/shaped_csv.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/io/signal_csv.hpp"
#include "servotwin/shaping/discretization.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/shaped_path.hpp"

namespace servotwin::cli {

namespace {

struct ApplyArgs {
  std::string shaper_path;
  std::string trajectory_path;
  std::string output = "-";
  std::optional<double> ts;
  std::string method = "exact";
  CLI::Option* method_option = nullptr;
};

struct CommandColumns {
  std::vector<std::string> axes;  // "x", "y", ... in file order
  shaping::Columns positions;
};

CommandColumns command_columns(const io::SignalTable& table) {
  CommandColumns out;
  const std::string suffix = "_cmd";
  for (std::size_t i = 0; i < table.names.size(); ++i) {
    const std::string& name = table.names[i];
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      out.axes.push_back(name.substr(0, name.size() - suffix.size()));
      out.positions.push_back(table.columns[i]);
    }
  }
  if (out.axes.empty())
    throw core::InputError(core::SourceLocation{table.source, 1, 0, ""},
                           "expected at least one `<axis>_cmd` column (a trajectory CSV: t, x_cmd, ...)");
  return out;
}

// The reader checks --ts as a sample rate; say it in the user's terms.
io::SignalTable read_trajectory(const std::string& path, const io::SignalReadOptions& options,
                                std::optional<double> ts) {
  try {
    return io::read_signal_file(path, options);
  } catch (const core::InputError& e) {
    if (!ts || e.where().field != "--fs") throw;
    core::SourceLocation where = e.where();
    where.field = "--ts";
    throw core::InputError(where, fmt::format("--ts {} s: {}", *ts, e.reason()));
  }
}

shaping::DiscretizationMethod parse_method(const std::string& text) {
  if (text == "exact") return shaping::DiscretizationMethod::Exact;
  if (text == "round") return shaping::DiscretizationMethod::Round;
  throw core::InputError(core::at_field("--method"), "expected exact or round, got '" + text + "'");
}

/// The shaper on the trajectory's grid: a discrete shaper as it is (after checking it was made for
/// this sample period), a continuous one discretized.
shaping::DiscreteShaper discrete_at(const io::LoadedShaper& loaded, const std::string& path, double ts,
                                    shaping::DiscretizationMethod method) {
  if (!loaded.extras.discrete) return shaping::discretize(loaded.shaper, ts, method);
  const double designed = *loaded.extras.ts;
  if (std::abs(designed - ts) > 1e-9 * ts)
    throw core::InputError(core::SourceLocation{path, 0, 0, "ts"},
                           fmt::format("the shaper is discrete at ts = {} s but the trajectory's period is {} s: design it "
                                       "for {} s (shaper design --ts {}) or use the continuous shaper",
                                       designed, ts, ts, ts));
  shaping::DiscreteShaper d;
  d.type = loaded.shaper.type;
  d.omega = loaded.shaper.omega;
  d.zeta = loaded.shaper.zeta;
  d.ts = ts;
  d.delays = loaded.extras.discrete->samples;
  d.amplitudes = loaded.shaper.amplitudes;
  d.residual = shaping::residual_vibration(loaded.shaper, loaded.shaper.omega, loaded.shaper.zeta);
  d.min_amplitude = *std::min_element(d.amplitudes.begin(), d.amplitudes.end());
  return d;
}

int run_apply(const ApplyArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const shaping::DiscretizationMethod method = parse_method(a.method);
  const io::LoadedShaper loaded = io::load_shaper(a.shaper_path);
  if (loaded.extras.discrete && a.method_option->count() > 0)
    throw core::InputError(core::at_field("--method"), a.shaper_path + " is a discrete shaper already (" +
                                                           loaded.extras.discrete->discretization +
                                                           "): --method applies to continuous shapers");
  io::SignalReadOptions options;
  if (a.ts) {
    if (!std::isfinite(*a.ts) || *a.ts <= 0.0)
      throw core::InputError(core::at_field("--ts"), fmt::format("expected a sample period > 0 s, got {}", *a.ts));
    options.fs = 1.0 / *a.ts;  // checked against the time column, or the period of a file without one
  }
  const io::SignalTable table = read_trajectory(a.trajectory_path, options, a.ts);
  const CommandColumns commanded = command_columns(table);

  const shaping::DiscreteShaper discrete = discrete_at(loaded, a.shaper_path, table.ts, method);
  const shaping::Columns shaped = shaping::shape_columns(commanded.positions, discrete);
  const shaping::PathDeviation deviation = shaping::path_deviation(commanded.positions, shaped, discrete.max_delay());

  auto out = open_output(a.output, global);
  io::write_shaped_csv(out->stream(), {table.t0, table.ts, commanded.axes, commanded.positions, shaped, deviation.distance});
  out->commit();

  // The summary goes to stdout unless the CSV does.
  std::FILE* summary = a.output == "-" ? stderr : stdout;
  std::string where;
  for (std::size_t i = 0; i < commanded.axes.size(); ++i)
    where += fmt::format("{}{} = {:.6g}", i ? ", " : "", commanded.axes[i], deviation.max_point[i]);
  fmt::print(summary,
             "shaper {} ({:.6g} Hz, zeta {:.6g}): {} pulses at ts = {} s ({}), residual vibration "
             "{:.3g} %\n"
             "delay added: {:.6g} s ({} samples)\n"
             "contour distortion: rms {:.6g}, max {:.6g} at t = {:.6g} s ({})\n",
             loaded.shaper.type, loaded.shaper.omega / (2.0 * std::numbers::pi), loaded.shaper.zeta,
             discrete.delays.size(), table.ts,
             loaded.extras.discrete ? loaded.extras.discrete->discretization + " discretization, as designed"
                                    : std::string(shaping::discretization_method_name(method)) + " discretization",
             100.0 * discrete.residual,
             discrete.duration(), discrete.max_delay(), deviation.rms, deviation.max,
             table.t0 + static_cast<double>(deviation.max_index) * table.ts, where);
  if (discrete.min_amplitude < 0.0)
    fmt::print(summary,
               "note: the discrete shaper has negative pulses (min {:.4g}): the step response is not monotone\n",
               discrete.min_amplitude);
  progress(global, "{} samples shaped in {:.1f} ms -> {}", deviation.distance.size(), elapsed_ms(start), a.output);
  return kSuccess;
}

}  // namespace

void add_apply(CLI::App& shaper, Action& selected) {
  auto a = std::make_shared<ApplyArgs>();
  CLI::App* cmd = shaper.add_subcommand(
      "apply", "Shape a commanded trajectory CSV (t, <axis>_cmd) and report the contour distortion it causes");
  cmd->add_option("shaper", a->shaper_path, "Shaper JSON (servotwin.shaper/1)")->required()->check(CLI::ExistingFile);
  cmd->add_option("trajectory", a->trajectory_path, "Trajectory CSV: t and <axis>_cmd columns")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a->output,
                  "Output CSV (t, <axis>_cmd, <axis>_shaped, deviation), - for standard output")
      ->capture_default_str();
  cmd->add_option("--ts", a->ts, "Sample period [s] (checked against the time column; needed without one)");
  a->method_option = cmd->add_option("--method", a->method, "Discretization of a continuous shaper: exact (vector decomposition) or round")
      ->capture_default_str();
  set_examples(*cmd,
               "  servotwin shaper apply shaper.json trajectory.csv -o shaped.csv\n"
               "  servotwin shaper apply shaper.json part.csv --method round -o shaped_round.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run_apply(*a, g); }; });
}

}  // namespace servotwin::cli
