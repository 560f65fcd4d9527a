// `servotwin identify`: captures -> closed-loop axis model (thesis chapters 3 and 4).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "capture_input.hpp"
#include "command.hpp"
#include "model_summary.hpp"
#include "report_output.hpp"
#include "servotwin/io/rapid_json.hpp"
#include "servotwin/report/identification_report.hpp"
#include "solver_options.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/vcnc/trace_check.hpp"

namespace servotwin::cli {

namespace {

struct IdentifyArgs {
  std::vector<std::string> captures;
  std::vector<std::string> validate;
  std::vector<std::string> axes;
  CaptureInput reading;
  SolverInput solver;
  std::string shift = "auto";
  double trim_start_s = 0.0, trim_end_s = 0.0, deadband = 0.0;
  CLI::Option* deadband_opt = nullptr;
  bool refine = false;
  ProgramSource program;
  std::string output, stats_output, report;
};

/// "model.json" for one axis; several axes need "{axis}" in the name.
std::string output_for(const std::string& pattern, const std::string& axis, std::size_t axis_count, const char* option) {
  const auto at = pattern.find("{axis}");
  if (at == std::string::npos) {
    if (axis_count > 1)
      throw core::InputError({pattern, 0, 0, option},
                             "several axes are identified: put {axis} in the file name, e.g. model_{axis}.json");
    return pattern;
  }
  return pattern.substr(0, at) + axis + pattern.substr(at + 6);
}

/// --axis as given, else every axis whose command moves in some capture (a 3-axis capture of a
/// one-axis program holds two axes at rest, which are skipped with a note).
std::vector<std::string> axes_to_identify(const IdentifyArgs& a, const std::vector<vcnc::NamedCapture>& captures,
                                          const GlobalOptions& global) {
  if (!a.axes.empty()) return a.axes;
  std::vector<std::string> names = vcnc::moving_axes(captures);
  for (const auto& axis : captures.front().capture.axes) {
    if (std::find(names.begin(), names.end(), axis.name) == names.end())
      progress(global, "axis {}: the command never moves, skipped", axis.name);
  }
  if (names.empty()) {
    throw core::InputError({captures.front().source, 0, 0, "x_cmd"},
                           "no axis's command moves: nothing to identify (capture an identification program, see "
                           "`servotwin gcode identification`)");
  }
  return names;
}

/// The unit of the positions after --scale: mm for the usual conversions (the --scale help's own
/// example, 1000 for metres), else the factor (issue 27 §4: "file unit x 1000" for mm).
std::string scaled_unit(double scale) {
  if (scale == 1000.0) return "mm (file in m, x 1000)";
  if (scale == 0.001) return "mm (file in µm, x 0.001)";
  if (scale == 25.4) return "mm (file in inch, x 25.4)";
  return fmt::format("file unit x {}", scale);
}

/// "--shift auto" searches -3..3 samples; a number fixes the shift.
void apply_shift(const std::string& text, vcnc::IdentificationSettings& settings) {
  if (text == "auto") {
    settings.shift_search = vcnc::ShiftSearch{};
    return;
  }
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty()) {
    throw core::InputError({"", 0, 0, "--shift"}, "expected 'auto' or a whole number of samples, got '" + text + "'");
  }
  settings.regressors.command_shift = value;
}

int run(const IdentifyArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  // Only the axes asked for, and no drive outputs: an hour of three axes fits in memory. A trace
  // checked against its program (--program) keeps every axis the program may move.
  const CaptureSelection selection{a.program.path.empty() ? a.axes : std::vector<std::string>{}, false};
  const std::vector<vcnc::NamedCapture> captures = read_captures(a.captures, a.reading, selection);
  const std::vector<vcnc::NamedCapture> validation = read_captures(a.validate, a.reading, selection);
  progress(global, "read {} {}{} in {:.1f} ms", captures.size(), plural(captures.size(), "capture", "captures"),
           validation.empty() ? ""
                              : fmt::format(" and {} validation {}", validation.size(),
                                            plural(validation.size(), "capture", "captures")),
           elapsed_ms(start));
  if (!a.program.path.empty()) {
    // The identification run checked against its program: units, path, feed override.
    const motion::Program program = load_program(a.program);
    for (const auto& c : captures) {
      const vcnc::TraceCheck check = vcnc::check_trace(c.capture, c.source, &program, a.program.path);
      for (const auto& w : check.warnings) fmt::print(stderr, "warning: {}\n", w);
      for (const auto& n : check.notes) progress(global, "{}", n);
    }
  }

  vcnc::IdentificationSettings settings;
  apply_solver_input(a.solver, settings);
  const double ts = captures.front().capture.ts;
  apply_shift(a.shift, settings);
  settings.regressors.trim_start = static_cast<std::size_t>(std::llround(a.trim_start_s / ts));
  settings.regressors.trim_end = static_cast<std::size_t>(std::llround(a.trim_end_s / ts));
  if (a.deadband_opt->count() > 0) settings.regressors.velocity_deadband = a.deadband;
  settings.refine = a.refine;
  settings.workers = global.threads;

  const std::vector<std::string> axes = axes_to_identify(a, captures, global);
  const io::TraceProfile profile = capture_profile(a.reading);
  const std::string length_unit = profile.reading.scale == 1.0 ? "as in the file"
                                  : !profile.units.empty()     ? "mm (file in " + profile.units + ")"
                                                               : scaled_unit(profile.reading.scale);
  const auto report_file = open_report(a.report, global);
  std::vector<vcnc::AxisIdentification> records;
  records.reserve(axes.size());
  for (const auto& axis : axes) {
    vcnc::AxisIdentification& record = records.emplace_back(vcnc::identify_axis(captures, validation, axis, settings));
    record.length_unit = length_unit;
    print_model_summary(record);
    if (!a.stats_output.empty()) {
      std::vector<std::string> warnings;
      const auto problem = vcnc::axis_problem(captures, axis, record.regressors, warnings);
      auto out = open_output(output_for(a.stats_output, axis, axes.size(), "--stats-out"), global, "--stats-out");
      out->stream() << io::normal_equations_to_json(problem.normal_equations(), axis, a.captures,
                                                    record.regressors.command_shift)
                           .dump(2)
                    << '\n';
      out->commit();
    }
    if (!a.output.empty()) {
      auto out = open_output(output_for(a.output, axis, axes.size(), "-o"), global);
      out->stream() << io::axis_model_to_json(record).dump(2) << '\n';
      out->commit();
      progress(global, "wrote {}", out->path());
    }
  }
  progress(global, "identified {} {} in {:.1f} ms", axes.size(), plural(axes.size(), "axis", "axes"), elapsed_ms(start));
  if (report_file) write_report(report::identification_report(records, captures, validation), *report_file, global);
  return kSuccess;
}

}  // namespace

void register_identify(CLI::App& app, Action& selected) {
  auto a = std::make_shared<IdentifyArgs>();
  CLI::App* cmd = app.add_subcommand(
      "identify", "Identify the closed-loop axis model (thesis Eq. 3.3) from captures of commanded and actual position");
  cmd->add_option("captures", a->captures, "Capture CSV files; several are concatenated (e.g. low- and high-speed runs)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--axis", a->axes, "Axes to identify (default: every axis whose command moves)");
  add_solver_options(*cmd, a->solver);
  cmd->add_option("--shift", a->shift,
                  "Command shift in samples (x_r,k := cmd[k + shift]: a controller's preview, negative for a delay), or "
                  "'auto': the shift in -3..3 whose model fits the identification data best")
      ->capture_default_str();
  cmd->add_option("--trim-start", a->trim_start_s, "Seconds dropped at the start of each capture")
      ->check(non_negative_number())
      ->capture_default_str();
  cmd->add_option("--trim-end", a->trim_end_s, "Seconds dropped at the end of each capture")->capture_default_str();
  a->deadband_opt = cmd->add_option("--deadband", a->deadband,
                                    "Velocity deadband of the direction indicators [length/s] (default: from the data)");
  cmd->add_flag("--refine", a->refine,
               "Refine the solver's model by output error: the coefficients whose simulation follows the measured "
               "position best, within the same bounds (slower: some 100 simulations)");
  add_capture_input_options(*cmd, a->reading);
  cmd->add_option("-p,--program", a->program.path,
                  "The program the captures ran: checks units, that the command follows its path, and the feed")
      ->check(CLI::ExistingFile);
  add_program_reading_options(*cmd, a->program);
  cmd->add_option("--validate", a->validate, "Validation captures: the model's simulated tracking error is scored on them")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a->output, "Model file (servotwin.axis-model/1); {axis} in the name for several axes");
  cmd->add_option("--stats-out", a->stats_output, "Write the sufficient statistics (servotwin.normal-equations/1)");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin identify capture.csv --axis x --method exact -o model.json --stats-out stats.json\n"
               "  servotwin identify DATA_EMPS.csv --map x_cmd=qg --map x_act=qm --scale 1000 --validate other.csv -o model.json\n"
               "  servotwin identify low.csv high.csv --method ga --seed 3 -o model_{axis}.json\n"
               "  servotwin identify capture.csv --validate check.csv --report identification.html\n"
               "  servotwin identify capture.csv --refine --validate check.csv -o model.json\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
