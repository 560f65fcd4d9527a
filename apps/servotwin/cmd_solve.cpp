// `servotwin solve`: sufficient statistics (one or more files, added up) -> axis model.
#include <chrono>

#include "command.hpp"
#include "model_summary.hpp"
#include "servotwin/io/rapid_json.hpp"
#include "solver_options.hpp"

namespace servotwin::cli {

namespace {

struct SolveArgs {
  std::vector<std::string> statistics;
  SolverInput solver;
  std::string output;
};

int run(const SolveArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const io::LoadedStatistics stats = io::load_statistics(a.statistics);
  vcnc::IdentificationSettings settings;
  apply_solver_input(a.solver, settings);
  vcnc::AxisIdentification record;
  record.axis = stats.axis.empty() ? "x" : stats.axis;
  record.ts = stats.problem.ts();
  record.bounds = vcnc::complete_bounds(settings.bounds, record.ts);
  record.regressors.command_shift = stats.command_shift;
  record.solution = rapid::solve(stats.problem, settings.method, record.bounds, settings.solve);
  record.solution.warnings.insert(record.solution.warnings.begin(), stats.warnings.begin(), stats.warnings.end());
  record.sources = a.statistics;
  print_model_summary(record);
  if (!a.output.empty()) {
    auto out = open_output(a.output, global);
    out->stream() << io::axis_model_to_json(record).dump(2) << '\n';
    out->commit();
    progress(global, "wrote {}", a.output);
  }
  progress(global, "solved {} {} of statistics in {:.1f} ms", stats.problem.samples(),
           plural(stats.problem.samples(), "sample", "samples"), elapsed_ms(start));
  return kSuccess;
}

}  // namespace

void register_solve(CLI::App& app, Action& selected) {
  auto a = std::make_shared<SolveArgs>();
  CLI::App* cmd = app.add_subcommand("solve", "Solve sufficient statistics (added up over files) for the axis model");
  cmd->add_option("statistics", a->statistics, "servotwin.normal-equations/1 files; several are added up")
      ->required()
      ->check(CLI::ExistingFile);
  add_solver_options(*cmd, a->solver);
  cmd->add_option("-o,--output", a->output, "Model file (servotwin.axis-model/1)");
  set_examples(*cmd,
               "  servotwin solve stats.json --method exact -o model.json\n"
               "  servotwin solve low.json high.json --method ga --generations 500 -o model.json\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
