#include "command.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "servotwin/core/error.hpp"
#include "servotwin/io/program_file.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::cli {

void check_sample_period(double ts, const std::string& option) {
  if (!std::isfinite(ts) || ts <= 0.0)
    throw core::InputError(core::at_field(option), fmt::format("expected a sample period > 0 s, got {}", ts));
}

void check_below_nyquist(double freq_hz, double ts, const std::string& option) {
  const double nyquist_hz = 0.5 / ts;
  if (freq_hz >= nyquist_hz)
    throw core::InputError(core::at_field(option), fmt::format("{} Hz is at or beyond the Nyquist frequency {} Hz of --ts {} s",
                                                               freq_hz, nyquist_hz, ts));
}

std::pair<double, double> parse_range_hz(const std::string& text, const std::string& option) {
  const auto fail = [&] {
    return core::InputError(core::at_field(option), "expected BEGIN:END in Hz, e.g. 1:500, got \"" + text + "\"");
  };
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw fail();
  try {
    std::size_t used_a = 0, used_b = 0;
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    const double begin = std::stod(a, &used_a);
    const double end = std::stod(b, &used_b);
    if (used_a != a.size() || used_b != b.size()) throw fail();
    return {begin, end};
  } catch (const std::logic_error&) {
    throw fail();
  }
}

CLI::Option* add_output_file_option(CLI::App& command, std::string& target, const std::string& help) {
  CLI::Option* option = command.add_option("-o,--output", target, help);
  add_old_spelling(command, "--out", target, "-o/--output");
  return option;
}

std::unique_ptr<io::OutputFile> open_output(const std::string& path, const GlobalOptions& global) {
  return std::make_unique<io::OutputFile>(path, global.force ? io::Overwrite::Allow : io::Overwrite::Refuse);
}

std::vector<motion::Axis> parse_axes(const std::vector<std::string>& values, const std::string& option) {
  std::vector<motion::Axis> axes;
  for (const auto& value : values) {
    for (char c : value) {
      if (c == ',' || c == ' ') continue;
      motion::Axis axis{};
      switch (std::toupper(static_cast<unsigned char>(c))) {
        case 'X': axis = motion::Axis::X; break;
        case 'Y': axis = motion::Axis::Y; break;
        case 'Z': axis = motion::Axis::Z; break;
        default:
          throw core::InputError({"", 0, 0, option}, "unknown axis '" + std::string(1, c) + "' (expected X, Y or Z)");
      }
      for (motion::Axis a : axes)
        if (a == axis) throw core::InputError({"", 0, 0, option}, "axis " + std::string(1, motion::axis_letter(axis)) + " given twice");
      axes.push_back(axis);
    }
  }
  return axes;
}

const std::map<std::string, motion::Dialect>& dialect_names() {
  static const std::map<std::string, motion::Dialect> names{
      {"iso", motion::Dialect::Iso}, {"linuxcnc", motion::Dialect::LinuxCnc}, {"heidenhain", motion::Dialect::Heidenhain}};
  return names;
}

const char* dialect_title(motion::Dialect dialect) {
  switch (dialect) {
    case motion::Dialect::Iso: return "ISO";
    case motion::Dialect::LinuxCnc: return "LinuxCNC";
    case motion::Dialect::Heidenhain: return "Heidenhain";
  }
  return "?";
}

void PathModeOption::add_to(CLI::App& command) {
  command.add_option("--path-mode", text,
                     "Path-control mode stated in the program: exact (G61; LinuxCNC G61.1), exact-path (LinuxCNC G61), "
                     "blend (G64), blend:TOL (G64 P<TOL> in the linuxcnc dialect, Cycle 32 T<TOL> in heidenhain), "
                     "unstated (no word: the controller's setting). Default: exact, or unstated for heidenhain");
}

namespace {

std::pair<motion::PathControl, double> path_mode_of(const std::string& text) {
  const auto fail = [&](const std::string& why) -> std::pair<motion::PathControl, double> {
    throw core::InputError({"", 0, 0, "--path-mode"}, "'" + text + "': " + why);
  };
  if (text == "exact") return {motion::PathControl::ExactStop, 0.0};
  if (text == "exact-path") return {motion::PathControl::ExactPath, 0.0};
  if (text == "unstated") return {motion::PathControl::Unstated, 0.0};
  if (text == "blend") return {motion::PathControl::Blend, 0.0};
  if (text.rfind("blend:", 0) != 0) return fail("expected exact, exact-path, blend, blend:TOL or unstated");
  const std::string number = text.substr(6);
  double tolerance = 0.0;
  const auto r = std::from_chars(number.data(), number.data() + number.size(), tolerance);
  if (number.empty() || r.ec != std::errc{} || r.ptr != number.data() + number.size())
    return fail("expected blend:TOL with TOL a tolerance in mm, e.g. blend:0.01");
  if (!(tolerance > 0.0 && tolerance <= 1e9)) return fail("the blend tolerance must be > 0 mm");
  return {motion::PathControl::Blend, tolerance};
}

}  // namespace

std::pair<std::optional<motion::PathControl>, double> PathModeOption::parse(motion::Dialect dialect) const {
  if (text.empty()) return {std::nullopt, 0.0};
  const auto [mode, tolerance] = path_mode_of(text);
  if (!motion::can_state(dialect, mode, tolerance)) {
    const std::string hint = dialect == motion::Dialect::Heidenhain
                                 ? "Heidenhain Klartext has Cycle 32 TOLERANCE (blend:TOL) or the machine's setting (unstated)"
                                 : "ISO's G64 takes no tolerance: use --dialect linuxcnc for G64 P<TOL>, or plain blend";
    throw core::InputError({"", 0, 0, "--path-mode"},
                           "'" + text + "' cannot be written in the " + dialect_title(dialect) + " dialect: " + hint);
  }
  return {mode, tolerance};
}

void add_program_reading_options(CLI::App& command, ProgramSource& source) {
  command.add_option("--dialect", source.dialect,
                     "Dialect of the program: auto (Heidenhain when it starts with BEGIN PGM, else ISO), iso, linuxcnc "
                     "(G61 exact path, G61.1 exact stop, G64 P<tol> Q<tol>) or heidenhain")
      ->check(CLI::IsMember({"auto", "iso", "linuxcnc", "heidenhain"}))
      ->capture_default_str();
  command.add_flag("--lenient", source.lenient, "Report unknown G-code words as warnings instead of errors");
}

motion::Program load_program(const ProgramSource& source, const motion::Point& start) {
  motion::ParseOptions options;
  options.lenient = source.lenient;
  options.start = start;
  std::optional<motion::Dialect> dialect;
  if (source.dialect != "auto") dialect = dialect_names().at(source.dialect);
  motion::Program program = io::read_program_file(source.path, options, dialect);
  for (const auto& w : program.warnings)
    fmt::print(stderr, "{}:{}:{}: warning: {}\n", source.path, w.line, w.column, w.message);
  return program;
}

void set_examples(CLI::App& command, const std::string& examples) { command.footer("\nExamples:\n" + examples); }

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string time_or_never(double seconds) {
  return std::isfinite(seconds) ? fmt::format("{:.4g} s", seconds) : std::string("never");
}

}  // namespace servotwin::cli
