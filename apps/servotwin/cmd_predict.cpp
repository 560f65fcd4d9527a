// `servotwin predict`: axis models + part program (interpolated by servotwin) or a controller's
// recorded command -> predicted tracking and contour errors, scored against a measurement.
#include <chrono>

#include "capture_input.hpp"
#include "command.hpp"
#include "interpolation_options.hpp"
#include "prediction_summary.hpp"
#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/report/prediction_report.hpp"
#include "servotwin/io/prediction_csv.hpp"
#include "servotwin/io/rapid_json.hpp"

namespace servotwin::cli {

namespace {

struct PredictArgs {
  std::vector<std::string> models;
  ProgramSource program;
  InterpolationInput interpolation;
  std::string capture, command;
  CaptureInput reading;
  double window_s = 0.2;
  double path_tolerance = 0.0;
  std::vector<double> offset;
  CLI::Option* path_tolerance_opt = nullptr;
  std::string output, report;
};

std::vector<vcnc::AxisModelSpec> load_models(const std::vector<std::string>& paths) {
  std::vector<vcnc::AxisModelSpec> models;
  for (const auto& path : paths) {
    io::LoadedAxisModel m = io::load_axis_model(path);
    models.push_back({m.axis, m.model, m.command_shift, path});
  }
  return models;
}

/// From the program, interpolated by servotwin; with --capture, aligned and scored.
std::pair<vcnc::Prediction, std::optional<vcnc::MeasuredComparison>> predict_program(
    const PredictArgs& a, const std::vector<vcnc::AxisModelSpec>& models, std::size_t threads) {
  const ResolvedInterpolation interpolation = resolve_interpolation(a.interpolation);
  const motion::Program program = load_program(a.program, interpolation.start);
  vcnc::PredictionOptions options;
  options.contour_window_s = a.window_s;
  options.workers = threads;
  vcnc::Prediction prediction;
  try {
    prediction = vcnc::predict(program, a.program.path, interpolation.limits, models, options);
  } catch (const core::InputError& e) {
    // The sample period is the models' (vcnc::predict).
    const core::SourceLocation models_ts{models.front().source, 0, 0, "ts"};
    rethrow_interpolation_error(e, a.interpolation, &models_ts);
    throw;
  }
  std::optional<vcnc::MeasuredComparison> comparison;
  if (!a.capture.empty()) {
    const std::vector<vcnc::NamedCapture> captures = read_captures({a.capture}, a.reading);
    comparison = vcnc::compare_with_capture(prediction, captures.front().capture, a.capture);
  }
  return {std::move(prediction), std::move(comparison)};
}

/// From the trace's own command (thesis 4.3.3); its measured positions, when it has them, scored.
std::pair<vcnc::Prediction, std::optional<vcnc::MeasuredComparison>> predict_command(
    const PredictArgs& a, const std::vector<vcnc::AxisModelSpec>& models, std::size_t threads) {
  io::CaptureReadOptions reading = capture_read_options(a.reading);
  reading.allow_missing_actual = true;
  const core::Capture trace = io::read_capture_file(a.command, reading);
  std::optional<motion::Program> program;
  if (!a.program.path.empty()) program = load_program(a.program);
  vcnc::CommandPredictionOptions options;
  options.contour_window_s = a.window_s;
  options.workers = threads;
  if (a.path_tolerance_opt->count() > 0) options.path_tolerance_mm = a.path_tolerance;
  if (!a.offset.empty()) {
    if (a.offset.size() > motion::kAxisCount)
      throw core::InputError({"", 0, 0, "--offset"}, "give at most X Y Z, got " + std::to_string(a.offset.size()) + " values");
    motion::Point offset{};
    for (std::size_t i = 0; i < a.offset.size(); ++i) offset[i] = a.offset[i];
    options.offset = offset;
  }
  vcnc::Prediction prediction = vcnc::predict_from_command(trace, a.command, program ? &*program : nullptr,
                                                           a.program.path, models, options);
  std::optional<vcnc::MeasuredComparison> comparison;
  bool measured = true;
  for (const motion::Axis axis : prediction.axes) {
    const core::AxisTrace* t = trace.find(motion::axis_name(axis));
    measured = measured && t != nullptr && t->act.size() == trace.size();
  }
  if (measured) comparison = vcnc::compare_with_trace(prediction, trace, a.command);
  return {std::move(prediction), std::move(comparison)};
}

int run(const PredictArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  if (a.command.empty() && a.program.path.empty())
    throw core::InputError({"", 0, 0, "--program"}, "give the part program (--program) or a recorded command (--command)");
  if (!a.command.empty() && !a.capture.empty())
    throw core::InputError({"", 0, 0, "--capture"},
                           "--command already scores the prediction against the trace's measured positions; --capture "
                           "is for predictions from the program");
  const auto report_file = open_report(a.report, global);
  const std::vector<vcnc::AxisModelSpec> models = load_models(a.models);
  auto [prediction, comparison] =
      a.command.empty() ? predict_program(a, models, global.threads) : predict_command(a, models, global.threads);
  progress(global, "predicted {} {} over {} samples in {:.1f} ms", prediction.axes.size(),
           plural(prediction.axes.size(), "axis", "axes"), prediction.size(),
           elapsed_ms(start));
  print_prediction_summary(prediction);
  if (comparison) print_comparison(*comparison, prediction.ts, !a.command.empty());
  if (!a.output.empty()) {
    auto out = open_output(a.output, global);
    io::write_prediction_csv(out->stream(), prediction, comparison ? &*comparison : nullptr);
    out->commit();
    progress(global, "wrote {}", out->path());
  }
  if (report_file) {
    const std::string& name = a.program.path.empty() ? a.command : a.program.path;
    write_report(report::prediction_report(name, prediction, comparison ? &*comparison : nullptr), *report_file, global);
  }
  return kSuccess;
}

}  // namespace

void register_predict(CLI::App& app, Action& selected) {
  auto a = std::make_shared<PredictArgs>();
  CLI::App* cmd = app.add_subcommand(
      "predict", "Predict tracking and contour errors of a part program, or of a controller's recorded command, from "
                 "identified axis models (one per moving axis)");
  cmd->add_option("--model", a->models, "Axis model file (servotwin.axis-model/1), one per axis; repeatable")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-p,--program", a->program.path,
                  "Part program (ISO, LinuxCNC or Heidenhain): interpolated by servotwin, or with --command the "
                  "geometry contour errors are measured against")
      ->check(CLI::ExistingFile);
  add_program_reading_options(*cmd, a->program);
  add_interpolation_options(*cmd, a->interpolation, false);
  cmd->add_option("--command", a->command,
                  "Trace whose <axis>_cmd columns drive the models (the controller's own interpolation, blending and "
                  "override, as they happened); its <axis>_act columns, when present, are scored beside the prediction")
      ->check(CLI::ExistingFile);
  cmd->add_option("--capture", a->capture,
                  "Measured capture of the same program: aligned in time and scored against the prediction")
      ->check(CLI::ExistingFile);
  add_capture_input_options(*cmd, a->reading);
  cmd->add_option("--window", a->window_s,
                  "Contour error: distance to the part of the path run within this many seconds of the commanded point")
      ->capture_default_str()
      ->check(positive_number());
  a->path_tolerance_opt =
      cmd->add_option("--path-tolerance", a->path_tolerance,
                      "With --command and --program: largest distance [mm] the trace's command may keep from the "
                      "programmed path (default: from the program's path-control mode)")
          ->check(non_negative_number());
  cmd->add_option("--offset", a->offset,
                  "With --command and --program: trace coordinates minus program coordinates, X [Y [Z]] mm "
                  "(default: none, or found from the program's end point)")
      ->expected(1, 3);
  cmd->add_option("-o,--output", a->output,
                  "Prediction CSV: t, <axis>_cmd, <axis>_pred, <axis>_err, contour_err, path [, measured columns]");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin predict --model x.json --model y.json --program circle.nc -o prediction.csv\n"
               "  servotwin predict --model x.json --model y.json --program circle.nc --report prediction.html\n"
               "  servotwin predict --model x.json --model y.json --program part.nc --machine fadal-pid \\\n"
               "      --capture measured.csv -o prediction.csv\n"
               "  servotwin predict --model x.json --model y.json --command trace.csv --program diamond.ngc \\\n"
               "      --dialect linuxcnc --report diamond.html\n"
               "  servotwin predict --model x.json --model y.json --command trace.csv   # the command's own path\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
