#include "command.hpp"

#include <cctype>
#include <cmath>

#include "servotwin/core/error.hpp"
#include "servotwin/io/program_file.hpp"

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

void add_program_reading_options(CLI::App& command, ProgramSource& source) {
  command.add_option("--dialect", source.dialect, "Dialect of the program: auto, iso or heidenhain")
      ->check(CLI::IsMember({"auto", "iso", "heidenhain"}))
      ->capture_default_str();
  command.add_flag("--lenient", source.lenient, "Report unknown G-code words as warnings instead of errors");
}

motion::Program load_program(const ProgramSource& source, const motion::Point& start) {
  motion::ParseOptions options;
  options.lenient = source.lenient;
  options.start = start;
  std::optional<motion::Dialect> dialect;
  if (source.dialect == "iso") dialect = motion::Dialect::Iso;
  if (source.dialect == "heidenhain") dialect = motion::Dialect::Heidenhain;
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
