// `servotwin demo`: the main job on the built-in default, the rapid-identification thesis's loop
// on a virtual machine: identification program -> capture -> identified axis models (exact
// solver, the thesis's genetic algorithm beside it) -> predicted vs actual contouring of the
// circle and the diamond at 200 mm/s.
#include <algorithm>
#include <chrono>
#include <filesystem>

#include "command.hpp"
#include "model_summary.hpp"
#include "report_output.hpp"
#include "servotwin/report/identification_report.hpp"
#include "servotwin/report/prediction_report.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/capture_csv.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/prediction_csv.hpp"
#include "servotwin/io/rapid_json.hpp"
#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/vcnc/machine_run.hpp"
#include "servotwin/vcnc/thesis_loop.hpp"

namespace servotwin::cli {

namespace {

struct DemoArgs {
  std::string machine = "fadal-pid";
  std::uint64_t seed = 1;
  std::size_t ga_generations = 500;
  bool refine = true;
  std::string out_dir, report;
};

void write_file(const std::filesystem::path& path, const GlobalOptions& global, const auto& writer) {
  auto out = open_output(path.string(), global, "--out");
  writer(out->stream());
  out->commit();
}

void print_experiment(const machine::MachineConfig& machine, const vcnc::IdentificationExperiment& e) {
  const motion::InterpolationLimits limits = vcnc::limits_of(machine);
  std::string axes_text;
  for (auto axis : e.options.axes) axes_text += motion::axis_letter(axis);
  fmt::print("1. identification program (thesis Table 3.2): {} random moves within +-{} mm on {} at F{} mm/min, seed {}: "
             "{} blocks\n",
             e.options.moves, e.options.range_mm, axes_text, e.options.feed_mm_min, e.options.seed, e.program.blocks.size());
  fmt::print("2. interpolation at ts = {} s, acceleration {} mm/s^2, {}{}: {} samples = {:.3f} s of motion\n", limits.ts,
             limits.accel, limits.jerk ? fmt::format("jerk {} mm/s^3", *limits.jerk) : "trapezoidal (no jerk limit)",
             limits.exact_stop_every_block ? ", exact stop after every block" : "", e.capture.size(),
             static_cast<double>(e.capture.size() - 1) * limits.ts);
  fmt::print("3. capture on the virtual machine (friction, saturation, DAC and encoder quantization on):\n");
  for (const auto& axis : e.capture.axes) {
    const vcnc::TrackingStats s = vcnc::tracking_stats(axis);
    fmt::print("   axis {}: tracking error rms {:.2f} um, max {:.2f} um\n", axis.name, 1000.0 * s.rms, 1000.0 * s.max);
  }
}

void print_identification(const machine::MachineConfig& machine, const std::vector<vcnc::AxisIdentification>& models,
                          const std::vector<rapid::Solution>& ga, double ms) {
  fmt::print("4. identification of the closed-loop axis model (thesis Eq. 3.3), exact bounded solver, {:.1f} ms:\n", ms);
  for (std::size_t i = 0; i < models.size(); ++i) {
    const auto& m = models[i];
    const auto& s = m.solution;
    const auto axis = std::find_if(machine.axes.begin(), machine.axes.end(), [&](const auto& c) { return c.name == m.axis; });
    if (axis == machine.axes.end()) continue;
    const auto truth = machine::equivalent_closed_loop(*axis, machine.ts);
    fmt::print("   axis {}: true poles       {}{}\n", m.axis, roots_text(truth.poles), truth.exact ? "" : " (equivalent)");
    fmt::print("           identified poles {}; {}; command shift {}; fit nrmse {:.4f}\n",
               roots_text(rapid::AxisModel(s.coefficients, m.ts).poles()),
               rapid::AxisModel(s.coefficients, m.ts).is_stable() ? "stable" : "UNSTABLE", m.regressors.command_shift,
               m.fit->nrmse);
    fmt::print("           solver: case {}, objective {:.6g}, certified gap {:.2g}, {:.2f} ms\n", s.kkt_case,
               s.objective, s.objective - s.lower_bound, s.time_ms);
    if (i < ga.size()) {
      fmt::print("           thesis GA ({} candidates, {} generations, seed {}): objective {:+.3f} % from the optimum, "
                 "{:.0f} ms\n",
                 4000, ga[i].history.size(), ga[i].seed, 100.0 * (ga[i].objective / s.objective - 1.0), ga[i].time_ms);
    }
  }
}

void print_refinement(const std::vector<vcnc::AxisIdentification>& refined, double ms) {
  fmt::print("   output-error refinement of the exact models (the simulated tracking error fitted to the capture), "
             "{:.0f} ms:\n", ms);
  for (const auto& m : refined) {
    if (!m.refinement) continue;
    fmt::print("   axis {}: refined poles    {}; fit nrmse {:.4f} -> {:.4f} ({} iterations)\n", m.axis,
               roots_text(rapid::AxisModel(m.coefficients(), m.ts).poles()), m.solver_fit->nrmse, m.fit->nrmse,
               m.refinement->iterations);
  }
}

using Runs = std::vector<std::pair<std::string, vcnc::ContouringRun>>;

void print_contour_row(const std::string& name, const char* models, const vcnc::ContouringRun& run) {
  const vcnc::PredictionScore* s = vcnc::overall_score(run.comparison, "contour");
  double max_pred = 0.0, max_act = 0.0;
  for (std::size_t k = run.comparison.first; k < run.comparison.first + run.comparison.count; ++k) {
    max_pred = std::max(max_pred, std::abs(run.prediction.contour_error[k]));
    max_act = std::max(max_act, std::abs(run.comparison.contour_error[k]));
  }
  fmt::print("   {:<8} {:<8} {:>12.2f} / {:>7.2f} um ({:+5.1f} %) {:>12.2f} / {:>7.2f} um\n", name, models,
             1000.0 * s->metrics.rms_predicted, 1000.0 * s->metrics.rms_measured,
             100.0 * (s->metrics.rms_predicted / s->metrics.rms_measured - 1.0), 1000.0 * max_pred, 1000.0 * max_act);
}

void print_contouring(const Runs& runs, const Runs& refined_runs) {
  fmt::print("5. contouring at 200 mm/s (F12000) with the machine's 2000 mm/s^2 (thesis 3.4.1): predicted by the "
             "identified models vs run on the virtual machine\n");
  fmt::print("   {:<8} {:<8} {:>32} {:>28}\n", "toolpath", "models", "contour error rms pred / actual",
             "max pred / actual");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    print_contour_row(runs[i].first, "exact", runs[i].second);
    if (i < refined_runs.size()) print_contour_row(refined_runs[i].first, "refined", refined_runs[i].second);
  }
}

/// The demo's report: the identification report of every axis, then each toolpath's prediction
/// beside the machine's run, after a section with the comparison tables.
report::Document demo_report(const machine::MachineConfig& machine, const std::vector<vcnc::AxisIdentification>& models,
                             const std::vector<vcnc::NamedCapture>& captures, const Runs& runs,
                             const Runs& refined_runs) {
  report::Document doc = report::identification_report(models, captures, {});
  doc.title = "servotwin demo: " + machine.name;
  doc.subtitle = "the rapid-identification loop on a virtual machine: " + machine.description;
  report::Section overview;
  overview.title = "True vs identified closed loop";
  report::Table poles;
  poles.title = "Poles (Hz / damping)";
  poles.header = {"axis", "true (equivalent) closed loop", "identified"};
  for (const auto& m : models) {
    const auto axis = std::find_if(machine.axes.begin(), machine.axes.end(), [&](const auto& c) { return c.name == m.axis; });
    if (axis == machine.axes.end()) continue;
    poles.rows.push_back({m.axis, roots_text(machine::equivalent_closed_loop(*axis, machine.ts).poles),
                          roots_text(rapid::AxisModel(m.coefficients(), m.ts).poles())});
  }
  overview.tables.push_back(std::move(poles));
  report::Table contour;
  contour.title = "Contouring at 200 mm/s: contour error predicted vs run on the virtual machine [um]";
  contour.header = {"toolpath", "models", "rms predicted", "rms actual", "difference"};
  const auto add_row = [&](const std::string& name, const char* which, const vcnc::ContouringRun& run) {
    const vcnc::PredictionScore* s = vcnc::overall_score(run.comparison, "contour");
    contour.rows.push_back({name, which, fmt::format("{:.2f}", 1000.0 * s->metrics.rms_predicted),
                            fmt::format("{:.2f}", 1000.0 * s->metrics.rms_measured),
                            fmt::format("{:+.1f} %", 100.0 * (s->metrics.rms_predicted / s->metrics.rms_measured - 1.0))});
  };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    add_row(runs[i].first, "exact", runs[i].second);
    if (i < refined_runs.size()) add_row(refined_runs[i].first, "exact + output-error refinement", refined_runs[i].second);
  }
  overview.tables.push_back(std::move(contour));
  doc.sections.insert(doc.sections.begin(), std::move(overview));
  for (const auto& [name, run] : runs) {
    for (auto& section : report::prediction_sections(name, run.prediction, &run.comparison))
      doc.sections.push_back(std::move(section));
  }
  return doc;
}

int run(const DemoArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const auto report_file = open_report(a.report, global);
  const machine::MachineConfig machine = io::load_machine(a.machine);
  fmt::print("servotwin demo: the rapid-identification loop on machine '{}'\n  {}\n\n", machine.name, machine.description);

  const vcnc::IdentificationExperiment experiment = vcnc::run_identification_experiment(machine, a.seed);
  print_experiment(machine, experiment);

  const auto identify_start = std::chrono::steady_clock::now();
  const std::vector<vcnc::NamedCapture> captures{{"demo capture", experiment.capture}};
  vcnc::IdentificationSettings settings;
  settings.shift_search = vcnc::ShiftSearch{};
  const std::vector<vcnc::AxisIdentification> models = vcnc::identify_axes(captures, settings);
  const double identify_ms = elapsed_ms(identify_start);
  std::vector<rapid::Solution> ga;
  if (a.ga_generations > 0) {
    for (const auto& m : models) {
      vcnc::IdentificationSettings g;
      g.method = rapid::Method::Ga;
      g.regressors = m.regressors;  // same shift as the exact model, so the objectives compare
      g.solve.ga.generations = a.ga_generations;
      g.solve.ga.seed = a.seed;
      ga.push_back(vcnc::identify_axis(captures, {}, m.axis, g).solution);
    }
  }
  print_identification(machine, models, ga, identify_ms);
  std::vector<vcnc::AxisIdentification> refined;
  if (a.refine) {
    const auto refine_start = std::chrono::steady_clock::now();
    refined = models;
    for (auto& m : refined) vcnc::refine_identification(m, captures);
    print_refinement(refined, elapsed_ms(refine_start));
  }

  motion::ContourProgramOptions toolpath;
  toolpath.center = vcnc::machine_start(machine);
  const std::vector<vcnc::AxisModelSpec> specs = vcnc::model_specs(models);
  Runs runs, refined_runs;
  std::vector<motion::Program> programs{motion::make_circle_program(toolpath), motion::make_diamond_program(toolpath)};
  for (const auto& program : programs) runs.emplace_back(program.name, vcnc::contouring_run(machine, specs, program));
  if (!refined.empty()) {
    const std::vector<vcnc::AxisModelSpec> refined_specs = vcnc::model_specs(refined);
    for (const auto& program : programs)
      refined_runs.emplace_back(program.name, vcnc::contouring_run(machine, refined_specs, program));
  }
  print_contouring(runs, refined_runs);
  fmt::print("\nwhole loop in {:.0f} ms.\n", elapsed_ms(start));
  if (report_file) write_report(demo_report(machine, models, captures, runs, refined_runs), *report_file, global);

  if (!a.out_dir.empty()) {
    const std::filesystem::path dir(a.out_dir);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw core::InputError({a.out_dir, 0, 0, "--out"}, "cannot create the directory: " + ec.message());
    write_file(dir / "identification.nc", global, [&](std::ostream& os) { os << motion::write_iso(experiment.program); });
    write_file(dir / "capture.csv", global, [&](std::ostream& os) { io::write_capture_csv(os, experiment.capture); });
    write_file(dir / "machine.json", global, [&](std::ostream& os) { os << io::machine_to_json(machine).dump(2) << '\n'; });
    for (const auto& m : models) {
      write_file(dir / fmt::format("model_{}.json", m.axis), global,
                 [&](std::ostream& os) { os << io::axis_model_to_json(m).dump(2) << '\n'; });
    }
    for (const auto& m : refined) {
      write_file(dir / fmt::format("model_{}_refined.json", m.axis), global,
                 [&](std::ostream& os) { os << io::axis_model_to_json(m).dump(2) << '\n'; });
    }
    for (std::size_t i = 0; i < programs.size(); ++i) {
      const auto& [name, run] = runs[i];
      write_file(dir / (name + ".nc"), global, [&](std::ostream& os) { os << motion::write_iso(programs[i]); });
      write_file(dir / (name + "_prediction.csv"), global,
                 [&](std::ostream& os) { io::write_prediction_csv(os, run.prediction, &run.comparison); });
    }
    fmt::print("wrote {}: identification.nc, capture.csv, machine.json, model_<axis>[_refined].json, circle.nc, diamond.nc and "
               "<toolpath>_prediction.csv\n",
               a.out_dir);
  } else {
    fmt::print("(--out DIR keeps the programs, the capture, the machine, the models and the predictions)\n");
  }
  return kSuccess;
}

}  // namespace

void register_demo(CLI::App& app, Action& selected) {
  auto a = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "demo", "Run the rapid-identification loop on a built-in virtual machine: identify its axes, predict contouring");
  cmd->add_option("-m,--machine", a->machine, "Machine preset or JSON file")->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed of the identification program and of the genetic algorithm")->capture_default_str();
  cmd->add_option("--ga-generations", a->ga_generations,
                  "Generations of the thesis's genetic algorithm run for comparison (0: skip it)")
      ->capture_default_str();
  cmd->add_flag("!--no-refine", a->refine,
               "Skip the output-error refinement of the exact models (rows 'refined' of the contour table)");
  cmd->add_option("--out", a->out_dir, "Directory to keep the programs, capture, machine, models and predictions in");
  add_report_option(*cmd, a->report);
  set_examples(*cmd, "  servotwin demo\n  servotwin demo --machine fadal-ppi --out demo-run\n  servotwin demo --report demo.html\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
