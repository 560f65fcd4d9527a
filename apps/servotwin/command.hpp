#pragma once
// Shared pieces of the command-line tool: how subcommands register, global options, output files,
// progress messages and exit codes.

#include <CLI/CLI.hpp>
#include <cctype>
#include <fmt/core.h>
#include <functional>
#include <initializer_list>
#include <memory>
#include <numbers>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/io/output_file.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::cli {

/// 2π: Hz ↔ rad/s in what the commands print.
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Exit statuses (README "Command line").
enum ExitStatus : int { kSuccess = 0, kInternalError = 1, kUsageError = 2, kBadInput = 3, kIoError = 4 };

/// Options every subcommand understands.
struct GlobalOptions {
  bool quiet = false;  ///< no progress messages on stderr
  bool force = false;  ///< allow replacing existing output files
  std::size_t threads = 0;  ///< worker threads for long traces (0: every core)
};

/// The action a subcommand runs after parsing; returns the exit status.
using Action = std::function<int(const GlobalOptions&)>;

/// A subcommand adds itself to `app` and stores its action in `selected` when it is chosen.
using Registrar = void (*)(CLI::App& app, Action& selected);

void register_gcode(CLI::App& app, Action& selected);
void register_interpolate(CLI::App& app, Action& selected);
void register_capture(CLI::App& app, Action& selected);
void register_machine(CLI::App& app, Action& selected);
void register_demo(CLI::App& app, Action& selected);
void register_import(CLI::App& app, Action& selected);
void register_identify(CLI::App& app, Action& selected);
void register_solve(CLI::App& app, Action& selected);
void register_model(CLI::App& app, Action& selected);
void register_predict(CLI::App& app, Action& selected);
void register_frf(CLI::App& app, Action& selected);
void register_fit(CLI::App& app, Action& selected);
void register_shaper(CLI::App& app, Action& selected);
void register_tune(CLI::App& app, Action& selected);
void register_simulate(CLI::App& app, Action& selected);

/// Progress line on stderr (suppressed by --quiet).
template <typename... Args>
void progress(const GlobalOptions& global, fmt::format_string<Args...> format, Args&&... args) {
  if (global.quiet) return;
  fmt::print(stderr, "servotwin: ");
  fmt::print(stderr, format, std::forward<Args>(args)...);
  fmt::print(stderr, "\n");
}

/// Opens an output file of this run honouring --force; "-" and /dev/stdout write to stdout, devices
/// are written in place. `option` is what the user typed for it (for messages). A regular file is
/// written beside its target and moved into place by publish_outputs() once the command has
/// finished, so a failing command leaves no output behind. Refused with CLI::ValidationError
/// (exit 2), even with --force, when `path` is the same file (after resolving links) as another
/// output of this run or as any other argument of the command, such as a file it reads.
std::shared_ptr<io::OutputFile> open_output(const std::string& path, const GlobalOptions& global,
                                            const std::string& option = "-o");

/// Records the arguments of the parsed command chain (option and value), against which
/// open_output checks every output. Called by main after parsing.
void note_arguments(const CLI::App& app);
/// Moves every committed output of this run into place (one rename each; core::IoError when one
/// fails). Called by main after the command returned.
void publish_outputs();
/// Drops every output of this run that was not published (their temporary files are removed).
void discard_outputs();

/// Validators with plain messages ("expected a number > 0, got 0"; CLI11's own print a
/// 300-digit range), for options that take a number > 0 or >= 0.
const CLI::Validator& positive_number();
const CLI::Validator& non_negative_number();

/// Transform of a choice by name (case-insensitive) into its value, for enum options: an unknown
/// name gives "expected one of a, b, c; got 'x'" (CLI11's CheckedTransformer prints its map).
template <typename T>
CLI::Validator choice_of(const std::map<std::string, T>& choices) {
  std::string names;
  for (const auto& [name, value] : choices) names += (names.empty() ? "" : ", ") + name;
  return CLI::Validator(
      [choices, names](std::string& text) -> std::string {
        std::string key = text;
        for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        const auto found = choices.find(key);
        if (found == choices.end()) return "expected one of " + names + "; got '" + text + "'";
        text = std::to_string(static_cast<long long>(found->second));
        return {};
      },
      names);
}

/// A library parameter and the option the user typed for it, e.g. {"duration_s", "--duration"}.
using OptionName = std::pair<std::string_view, std::string_view>;
/// The library names its parameters (`ts`, `max_samples`); the user typed options (issue 27 §4).
/// Throws `e` again under the option when it names one of `names`' parameters and no file; returns
/// otherwise, for the caller to name a file or rethrow.
void rethrow_as_option(const core::InputError& e, std::initializer_list<OptionName> names);

/// Throws core::InputError naming `option` unless ts is a finite sample period > 0 s.
void check_sample_period(double ts, const std::string& option = "--ts");

/// Throws core::InputError naming `option` when freq_hz is at or beyond the Nyquist frequency of
/// the sample period ts (a shaper or controller for that mode cannot run at ts).
void check_below_nyquist(double freq_hz, double ts, const std::string& option);

/// "1:500" -> (1, 500): a frequency range BEGIN:END in Hz (core::InputError naming `option`
/// unless both are numbers; their order and signs are checked by the caller).
std::pair<double, double> parse_range_hz(const std::string& text, const std::string& option);

/// Parses axis lists such as "X", "xy", "X,Y" (repeatable option values) into axes.
std::vector<motion::Axis> parse_axes(const std::vector<std::string>& values, const std::string& option);

/// Where a part program comes from and how to read it: the options every command that reads a
/// program shares.
struct ProgramSource {
  std::string path;
  std::string dialect = "auto";  ///< auto, iso, linuxcnc or heidenhain
  bool lenient = false;
};

/// Dialects by their option names (iso, linuxcnc, heidenhain), for CLI::CheckedTransformer.
const std::map<std::string, motion::Dialect>& dialect_names();
/// "ISO", "LinuxCNC", "Heidenhain".
const char* dialect_title(motion::Dialect dialect);

/// `--path-mode exact|exact-path|blend[:TOL]|unstated` of the program generators.
struct PathModeOption {
  std::string text;  ///< as typed; empty = the dialect's default
  /// Adds --path-mode to `command`.
  void add_to(CLI::App& command);
  /// The mode (empty when not given) and the tolerance [mm]; core::InputError naming --path-mode
  /// when the text is malformed or `dialect` cannot state the mode.
  [[nodiscard]] std::pair<std::optional<motion::PathControl>, double> parse(motion::Dialect dialect) const;
};
/// Adds --dialect and --lenient for `source`.
void add_program_reading_options(CLI::App& command, ProgramSource& source);
/// Reads the program starting from `start`, printing lenient-mode warnings on stderr.
motion::Program load_program(const ProgramSource& source, const motion::Point& start = {});

/// Adds `-o,--output` for a file the command writes (issue 25 §7: -o/--output names only files)
/// and the old spelling `--out` (hidden, with a note on stderr).
CLI::Option* add_output_file_option(CLI::App& command, std::string& target, const std::string& help);

/// Adds a hidden old spelling `old_name` of the option `new_name` storing into the same
/// variable; using it prints a note naming the new spelling on stderr.
template <typename T>
void add_old_spelling(CLI::App& command, const std::string& old_name, T& target, const std::string& new_name) {
  command.add_option(old_name, target, "Old spelling of " + new_name)
      ->group("")
      ->each([old_name, new_name](const std::string&) {
        fmt::print(stderr, "servotwin: note: {} is now spelled {}; the old spelling will be removed\n", old_name,
                   new_name);
      });
}

/// Adds the "Examples:" footer shown by --help.
void set_examples(CLI::App& command, const std::string& examples);

/// `one` for a count of 1, else `many` ("1 axis", "2 axes"; issue 27 §4: "2 axises").
inline const char* plural(std::size_t count, const char* one, const char* many) { return count == 1 ? one : many; }

/// Milliseconds elapsed since `start` (steady clock, for progress messages).
double elapsed_ms(std::chrono::steady_clock::time_point start);

/// "0.1234 s", or "never" for a time that was not reached (+infinity: not settled, not risen).
std::string time_or_never(double seconds);

}  // namespace servotwin::cli
