// `servotwin predict`: axis models + part program -> predicted tracking and contour errors.
#include <chrono>

#include "capture_input.hpp"
#include "command.hpp"
#include "interpolation_options.hpp"
#include "prediction_summary.hpp"
#include "report_output.hpp"
#include "servotwin/report/prediction_report.hpp"
#include "servotwin/io/prediction_csv.hpp"
#include "servotwin/io/rapid_json.hpp"

namespace servotwin::cli {

namespace {

struct PredictArgs {
  std::vector<std::string> models;
  ProgramSource program;
  InterpolationInput interpolation;
  std::string capture;
  CaptureInput reading;
  double window_s = 0.2;
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

int run(const PredictArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const auto report_file = open_report(a.report, global);
  const std::vector<vcnc::AxisModelSpec> models = load_models(a.models);
  const ResolvedInterpolation interpolation = resolve_interpolation(a.interpolation);
  const motion::Program program = load_program(a.program, interpolation.start);
  vcnc::PredictionOptions options;
  options.contour_window_s = a.window_s;
  const vcnc::Prediction prediction = vcnc::predict(program, a.program.path, interpolation.limits, models, options);
  progress(global, "predicted {} axis(es) over {} samples in {:.1f} ms", prediction.axes.size(), prediction.size(),
           elapsed_ms(start));
  print_prediction_summary(prediction);

  std::optional<vcnc::MeasuredComparison> comparison;
  if (!a.capture.empty()) {
    const std::vector<vcnc::NamedCapture> captures = read_captures({a.capture}, a.reading);
    comparison = vcnc::compare_with_capture(prediction, captures.front().capture, a.capture);
    print_comparison(*comparison, prediction.ts);
  }
  if (!a.output.empty()) {
    auto out = open_output(a.output, global);
    io::write_prediction_csv(out->stream(), prediction, comparison ? &*comparison : nullptr);
    out->commit();
    progress(global, "wrote {}", out->path());
  }
  if (report_file) {
    write_report(report::prediction_report(a.program.path, prediction, comparison ? &*comparison : nullptr), *report_file,
                 global);
  }
  return kSuccess;
}

}  // namespace

void register_predict(CLI::App& app, Action& selected) {
  auto a = std::make_shared<PredictArgs>();
  CLI::App* cmd = app.add_subcommand(
      "predict", "Predict tracking and contour errors of a part program from identified axis models (one per moving axis)");
  cmd->add_option("--model", a->models, "Axis model file (servotwin.axis-model/1), one per axis; repeatable")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-p,--program", a->program.path, "Part program (ISO or Heidenhain)")->required()->check(CLI::ExistingFile);
  add_program_reading_options(*cmd, a->program);
  add_interpolation_options(*cmd, a->interpolation, false);
  cmd->add_option("--capture", a->capture,
                  "Measured capture of the same program: aligned in time and scored against the prediction")
      ->check(CLI::ExistingFile);
  add_capture_input_options(*cmd, a->reading);
  cmd->add_option("--window", a->window_s,
                  "Contour error: distance to the path run within this many seconds of the commanded point")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("-o,--output", a->output,
                  "Prediction CSV: t, <axis>_cmd, <axis>_pred, <axis>_err, contour_err, path [, measured columns]");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin predict --model x.json --model y.json --program circle.nc -o prediction.csv\n"
               "  servotwin predict --model x.json --model y.json --program circle.nc --report prediction.html\n"
               "  servotwin predict --model x.json --model y.json --program part.nc --machine fadal-pid \\\n"
               "      --capture measured.csv -o prediction.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
