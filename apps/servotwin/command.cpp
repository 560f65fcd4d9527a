#include "command.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "servotwin/core/error.hpp"
#include "servotwin/io/program_file.hpp"
#include "servotwin/motion/gcode.hpp"

namespace servotwin::cli {

namespace {

CLI::Validator number_at_least(double bound, bool strict, const char* name) {
  return CLI::Validator(
      [bound, strict](const std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || value < bound || (strict && value == bound))
          return fmt::format("expected a number {} {}, got '{}'", strict ? ">" : ">=", bound, text);
        return {};
      },
      name);
}

}  // namespace

const CLI::Validator& positive_number() {
  static const CLI::Validator v = number_at_least(0.0, true, "POSITIVE");
  return v;
}

const CLI::Validator& non_negative_number() {
  static const CLI::Validator v = number_at_least(0.0, false, "NONNEGATIVE");
  return v;
}

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

namespace {

/// What makes two paths the same file: the device and inode of an existing file (after links),
/// else the path made absolute with its existing part's links resolved; standard output by name.
struct FileIdentity {
  bool standard_output = false;
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string canonical;
};

FileIdentity identify(const std::string& path) {
  FileIdentity id;
  if (io::output_kind(path) == io::OutputKind::kStandardOutput) {
    id.standard_output = true;
    return id;
  }
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0) {
    id.exists = true;
    id.device = info.st_dev;
    id.inode = info.st_ino;
  }
  std::error_code ec;
  id.canonical = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec).string();
  return id;
}

bool same_file(const FileIdentity& a, const FileIdentity& b) {
  if (a.standard_output || b.standard_output) return a.standard_output && b.standard_output;
  if (a.exists && b.exists) return a.device == b.device && a.inode == b.inode;
  return a.exists == b.exists && !a.canonical.empty() && a.canonical == b.canonical;
}

struct Argument {
  std::string option;  ///< the option's main name, for messages
  std::string names;   ///< all its names, comma-separated ("-o,--output")
  std::string value;
};

bool names_option(const Argument& argument, const std::string& option) {
  std::size_t begin = 0;
  while (begin <= argument.names.size()) {
    const std::size_t end = std::min(argument.names.find(',', begin), argument.names.size());
    if (argument.names.compare(begin, end - begin, option) == 0) return true;
    begin = end + 1;
  }
  return false;
}

struct OpenedOutput {
  std::shared_ptr<io::OutputFile> file;
  FileIdentity identity;
};

/// The outputs and arguments of this run (the tool runs one command per process).
struct Run {
  std::vector<Argument> arguments;
  std::vector<OpenedOutput> outputs;
};

Run& this_run() {
  static Run run;
  return run;
}

void note_arguments_of(const CLI::App& app, std::vector<Argument>& out) {
  for (const CLI::Option* option : app.get_options()) {
    if (option->count() == 0) continue;
    const std::string name = option->get_name(), names = option->get_name(false, true);
    for (const std::string& value : option->results())
      if (!value.empty() && value != "-") out.push_back({name, names, value});
  }
  for (const CLI::App* sub : app.get_subcommands()) note_arguments_of(*sub, out);
}

/// Two outputs on one file, or an output onto an argument (issue 27 §2: `-o X --report X`,
/// `interpolate -p a.nc -o a.nc --force`): the second would silently replace the first.
void refuse_shared_file(const std::string& path, const std::string& option, const FileIdentity& id) {
  Run& run = this_run();
  for (const OpenedOutput& other : run.outputs)
    if (same_file(id, other.identity))
      throw CLI::ValidationError(option, fmt::format("'{}' is already the output of {}: two outputs cannot share one file",
                                                     path, other.file->option()));
  if (id.standard_output) return;
  // The argument this output came from: its value under the option's name, else (an old spelling
  // such as --out) the first argument with that value.
  const auto own = [&]() -> const Argument* {
    const Argument* first = nullptr;
    for (const Argument& argument : run.arguments) {
      if (argument.value != path) continue;
      if (names_option(argument, option)) return &argument;
      if (first == nullptr) first = &argument;
    }
    return first;
  }();
  for (const Argument& argument : run.arguments) {
    if (&argument == own || !same_file(id, identify(argument.value))) continue;
    throw CLI::ValidationError(
        option, fmt::format("'{}' is also the file of {} ('{}'): an output must not replace a file the command reads "
                            "or writes (refused even with --force); choose another name",
                            path, argument.option, argument.value));
  }
}

}  // namespace

void rethrow_as_option(const core::InputError& e, std::initializer_list<OptionName> names) {
  if (!e.where().file.empty()) return;
  for (const auto& [parameter, option] : names)
    if (e.where().field == parameter) throw core::InputError(core::at_field(std::string(option)), e.reason());
}

std::shared_ptr<io::OutputFile> open_output(const std::string& path, const GlobalOptions& global, const std::string& option) {
  const bool device = io::output_kind(path) == io::OutputKind::kDevice;
  const FileIdentity id = identify(path);
  if (!device) refuse_shared_file(path, option, id);
  auto file = std::make_shared<io::OutputFile>(path, global.force ? io::Overwrite::Allow : io::Overwrite::Refuse, option,
                                               io::Publish::Deferred);
  if (!device) this_run().outputs.push_back({file, id});
  else this_run().outputs.push_back({file, {}});
  return file;
}

void note_arguments(const CLI::App& app) { note_arguments_of(app, this_run().arguments); }

void publish_outputs() {
  Run& run = this_run();
  for (OpenedOutput& output : run.outputs) output.file->publish();
  run.outputs.clear();
}

void discard_outputs() { this_run().outputs.clear(); }

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
