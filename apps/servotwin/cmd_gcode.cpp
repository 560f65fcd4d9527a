// `servotwin gcode`: identification-program generator, program check and dialect conversion.
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "command.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::cli {

namespace {


struct IdentificationArgs {
  std::vector<std::string> axes{"X"};
  std::string speed = "standard";
  std::size_t moves = 0;
  double range = 0.0, feed = 0.0;
  std::vector<double> center;
  std::uint64_t seed = 1;
  motion::Dialect dialect = motion::Dialect::Iso;
  std::string name = "RAPIDIDENT";
  PathModeOption path_mode;
  std::string output = "-";
  CLI::Option *moves_opt = nullptr, *range_opt = nullptr, *feed_opt = nullptr;
};


int run_identification(const IdentificationArgs& a, const GlobalOptions& global) {
  const std::map<std::string, motion::IdentificationSet> sets{{"standard", motion::IdentificationSet::Standard},
                                                              {"low", motion::IdentificationSet::Low},
                                                              {"high", motion::IdentificationSet::High}};
  motion::IdentificationOptions o = motion::identification_defaults(sets.at(a.speed));
  o.axes = parse_axes(a.axes, "--axis");
  if (a.moves_opt->count() > 0) o.moves = a.moves;
  if (a.range_opt->count() > 0) o.range_mm = a.range;
  if (a.feed_opt->count() > 0) o.feed_mm_min = a.feed;
  if (!a.center.empty()) {
    if (a.center.size() != o.axes.size())
      throw core::InputError({"", 0, 0, "--center"}, "give one centre per axis (" + std::to_string(o.axes.size()) +
                                                         "), got " + std::to_string(a.center.size()));
    for (std::size_t i = 0; i < o.axes.size(); ++i) o.center[static_cast<std::size_t>(o.axes[i])] = a.center[i];
  }
  o.seed = a.seed;
  o.name = a.name;
  o.dialect = a.dialect;
  std::tie(o.path_control, o.blend_tolerance_mm) = a.path_mode.parse(o.dialect);
  const motion::Program program = motion::make_identification_program(o);
  auto out = open_output(a.output, global);
  out->stream() << motion::write_program(program);
  out->commit();
  progress(global, "wrote {} ({} moves, +-{} mm, F{}, seed {})", a.output == "-" ? "program to stdout" : a.output,
           o.moves, o.range_mm, o.feed_mm_min, o.seed);
  return kSuccess;
}

struct ContourArgs {
  std::string shape = "circle";
  motion::ContourProgramOptions options;
  std::vector<double> center;
  PathModeOption path_mode;
  std::string output = "-";
};

int run_contour(const ContourArgs& a, const GlobalOptions& global) {
  motion::ContourProgramOptions o = a.options;
  if (!a.center.empty()) {
    if (a.center.size() > motion::kAxisCount)
      throw core::InputError({"", 0, 0, "--center"}, "give at most X Y Z, got " + std::to_string(a.center.size()) + " values");
    for (std::size_t i = 0; i < a.center.size(); ++i) o.center[i] = a.center[i];
  }
  std::tie(o.path_control, o.blend_tolerance_mm) = a.path_mode.parse(o.dialect);
  const motion::Program program = a.shape == "circle" ? motion::make_circle_program(o) : motion::make_diamond_program(o);
  auto out = open_output(a.output, global);
  out->stream() << motion::write_program(program);
  out->commit();
  progress(global, "wrote {} ({} of {} mm at F{})", a.output == "-" ? "program to stdout" : a.output, a.shape, o.size_mm,
           o.feed_mm_min);
  return kSuccess;
}

struct ProgramArgs {
  ProgramSource program;
  std::string to = "iso";
  std::string output = "-";
};

std::string counted(std::size_t n, const char* word) { return fmt::format("{} {}{}", n, word, n == 1 ? "" : "s"); }

/// The modes the motion blocks run in, in order of first use, with their block counts.
std::string path_control_summary(const motion::Program& program) {
  std::vector<std::pair<std::string, std::size_t>> modes;
  for (const auto& b : program.blocks) {
    if (b.type == motion::BlockType::None || b.type == motion::BlockType::Dwell) continue;
    const std::string text = motion::describe_path_control(b.path_control, b.blend_tolerance_mm);
    auto it = std::find_if(modes.begin(), modes.end(), [&](const auto& m) { return m.first == text; });
    if (it == modes.end()) {
      modes.emplace_back(text, 1);
    } else {
      ++it->second;
    }
  }
  if (modes.empty()) return "no motion";
  std::string out;
  for (const auto& [text, count] : modes) out += (out.empty() ? "" : "; ") + text + " (" + counted(count, "motion block") + ")";
  return out;
}

int run_check(const ProgramArgs& a, const GlobalOptions& /*global*/) {
  const motion::Program program = load_program(a.program);
  std::map<motion::BlockType, std::size_t> counts;
  for (const auto& b : program.blocks) ++counts[b.type];
  fmt::print("{}: {} program, {}: {}, {}, {}, {}\n", a.program.path, dialect_title(program.dialect),
             counted(program.blocks.size(), "block"),
             counted(counts[motion::BlockType::Rapid], "rapid move"), counted(counts[motion::BlockType::Linear], "line"),
             counted(counts[motion::BlockType::ArcCw] + counts[motion::BlockType::ArcCcw], "arc"),
             counted(counts[motion::BlockType::Dwell], "dwell"));
  // The plan gives the true path (arcs included) and a cycle time at the default CNC limits.
  const motion::InterpolationLimits limits;
  const motion::MotionPlan plan = motion::plan_motion(program, limits);
  double path_mm = 0.0;
  for (const auto& move : plan.moves()) path_mm += move.length;
  const motion::Trajectory t = motion::sample(plan);
  for (std::size_t i = 0; i < t.axes.size(); ++i) {
    const auto [lo, hi] = std::minmax_element(t.positions[i].begin(), t.positions[i].end());
    fmt::print("  {}: {:.4f} .. {:.4f} mm\n", motion::axis_letter(t.axes[i]), *lo, *hi);
  }
  fmt::print("  path length {:.3f} mm; cycle time {:.3f} s at {} mm/s^2 (trapezoidal, rapid F{}); {}\n", path_mm,
             plan.duration(), limits.accel, limits.rapid_feed_mm_min, counted(program.warnings.size(), "warning"));
  fmt::print("  path control: {}\n", path_control_summary(program));
  return kSuccess;
}

int run_convert(const ProgramArgs& a, const GlobalOptions& global) {
  const motion::Program program = load_program(a.program);
  auto out = open_output(a.output, global);
  motion::Program converted = program;
  converted.dialect = dialect_names().at(a.to);
  out->stream() << motion::write_program(converted);
  out->commit();
  return kSuccess;
}

void add_program_options(CLI::App& cmd, ProgramArgs& a) {
  cmd.add_option("program", a.program.path, "Part program (ISO G-code or Heidenhain conversational)")
      ->required()
      ->check(CLI::ExistingFile);
  add_program_reading_options(cmd, a.program);
}

}  // namespace

void register_gcode(CLI::App& app, Action& selected) {
  CLI::App* gcode = app.add_subcommand("gcode", "Generate, check and convert part programs");
  gcode->require_subcommand(1);
  set_examples(*gcode,
               "  servotwin gcode identification --axis X --seed 7 -o id.nc\n"
               "  servotwin gcode contour --shape circle -o circle.nc\n"
               "  servotwin gcode check id.nc\n"
               "  servotwin gcode convert id.nc --to heidenhain -o id.h\n");

  auto id = std::make_shared<IdentificationArgs>();
  CLI::App* gen = gcode->add_subcommand(
      "identification", "Write a rapid-identification program: random moves within +-range (thesis Tables 3.2, 4.3, 4.4)");
  gen->add_option("--axis", id->axes, "Axes moved together, e.g. X, Y or XY (repeatable)")->capture_default_str();
  gen->add_option("--speed", id->speed,
                  "Program kind: standard (Table 3.2: 200 moves, +-10 mm, F12000), low (Table 4.3: moves of tens "
                  "of um, F15000) or high (Table 4.4: sweeps and moves up to +-10 mm, F15000)")
      ->check(CLI::IsMember({"standard", "low", "high"}))
      ->capture_default_str();
  id->moves_opt = gen->add_option("--moves", id->moves, "Number of random moves (default from --speed)")
                      ->check(positive_number());
  id->range_opt = gen->add_option("--range", id->range, "Half-width of the motion range around the centre [mm]");
  id->feed_opt = gen->add_option("--feed", id->feed, "Programmed feed [mm/min]");
  gen->add_option("--center", id->center, "Centre of the motion range [mm], one value per axis");
  gen->add_option("--seed", id->seed, "Random seed: the same seed gives the same program")->capture_default_str();
  gen->add_option("--dialect", id->dialect, "Output dialect: iso, linuxcnc or heidenhain")
      ->transform(choice_of(dialect_names()))
      ->capture_default_str();
  id->path_mode.add_to(*gen);
  gen->add_option("--name", id->name, "Program name (Heidenhain BEGIN PGM)")->capture_default_str();
  gen->add_option("-o,--output", id->output, "Output file, - for standard output")->capture_default_str();
  set_examples(*gen,
               "  servotwin gcode identification --axis X --moves 200 --range 10 --feed 12000 --seed 7 -o id.nc\n"
               "  servotwin gcode identification --axis X --dialect heidenhain --speed low --seed 7 -o low.h\n"
               "  servotwin gcode identification --axis XY --speed high --dialect heidenhain -o high.h\n");
  gen->callback([id, &selected] { selected = [id](const GlobalOptions& g) { return run_identification(*id, g); }; });

  auto contour = std::make_shared<ContourArgs>();
  CLI::App* con = gcode->add_subcommand(
      "contour", "Write a contouring test toolpath: the thesis's circle (40 mm diameter) or diamond, counter-clockwise in XY");
  con->add_option("--shape", contour->shape, "circle or diamond")
      ->check(CLI::IsMember({"circle", "diamond"}))
      ->capture_default_str();
  con->add_option("--size", contour->options.size_mm, "Circle diameter or diamond diagonal [mm]")->capture_default_str();
  con->add_option("--feed", contour->options.feed_mm_min, "Programmed feed [mm/min] (F12000 = 200 mm/s)")
      ->capture_default_str();
  con->add_option("--center", contour->center, "Centre X Y [Z] [mm] (default: the origin)");
  con->add_option("--dialect", contour->options.dialect, "Output dialect: iso, linuxcnc or heidenhain")
      ->transform(choice_of(dialect_names()))
      ->capture_default_str();
  contour->path_mode.add_to(*con);
  con->add_option("-o,--output", contour->output, "Output file, - for standard output")->capture_default_str();
  set_examples(*con, "  servotwin gcode contour --shape circle --size 40 --feed 12000 -o circle.nc\n"
                     "  servotwin gcode contour --shape diamond -o diamond.nc\n"
                     "  servotwin gcode contour --shape diamond --dialect linuxcnc --path-mode blend:0.05 -o diamond.ngc\n");
  con->callback([contour, &selected] { selected = [contour](const GlobalOptions& g) { return run_contour(*contour, g); }; });

  auto check = std::make_shared<ProgramArgs>();
  CLI::App* chk = gcode->add_subcommand("check", "Read a program and print a summary (errors: exit status 3)");
  add_program_options(*chk, *check);
  set_examples(*chk, "  servotwin gcode check id.nc\n  servotwin gcode check part.h --lenient\n");
  chk->callback([check, &selected] { selected = [check](const GlobalOptions& g) { return run_check(*check, g); }; });

  auto conv = std::make_shared<ProgramArgs>();
  CLI::App* cvt = gcode->add_subcommand("convert", "Rewrite a program in the other dialect");
  add_program_options(*cvt, *conv);
  cvt->add_option("--to", conv->to, "Output dialect: iso, linuxcnc or heidenhain")
      ->check(CLI::IsMember({"iso", "linuxcnc", "heidenhain"}))
      ->capture_default_str();
  cvt->add_option("-o,--output", conv->output, "Output file, - for standard output")->capture_default_str();
  set_examples(*cvt, "  servotwin gcode convert low.h --to iso -o low.nc\n");
  cvt->callback([conv, &selected] { selected = [conv](const GlobalOptions& g) { return run_convert(*conv, g); }; });
}

}  // namespace servotwin::cli
