// servotwin command-line tool: dispatches to one subcommand per source file and maps errors to
// exit statuses (0 success, 2 usage error, 3 bad input, 4 output not written, 1 internal error).
#include <cstdio>
#include <exception>
#include <string>
#include <string_view>

#include "command.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/version.hpp"

namespace {

/// The first word that is neither a global option nor its value, when it names no subcommand
/// ("servotwin frobnicate": CLI11 says only "A subcommand is required"); empty otherwise.
std::string unknown_subcommand(CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "-j" || word == "--threads") {
      ++i;  // its value
      continue;
    }
    if (word.empty() || word[0] == '-') continue;
    for (const CLI::App* sub : app.get_subcommands({}))
      if (sub->check_name(word)) return {};
    return word;
  }
  return {};
}

/// An error message on stderr with its control bytes escaped (issue 27 §4): a message quotes what
/// the user gave, and a carriage return or an escape sequence from a file must not rewrite the
/// terminal. Line breaks and tabs of the message itself, and UTF-8 such as "µm", stay.
void print_error(const char* kind, const char* message) {
  std::string shown;
  for (const char* c = message; *c != '\0'; ++c) {
    const auto byte = static_cast<unsigned char>(*c);
    if ((byte < 0x20 && byte != '\n' && byte != '\t') || byte == 0x7f) shown += servotwin::core::printable(std::string_view(c, 1));
    else shown += *c;
  }
  std::fprintf(stderr, "servotwin: %s: %s\n", kind, shown.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  using namespace servotwin::cli;
  CLI::App app{"servotwin - digital twins of machine axes: identification programs, interpolation, "
               "virtual machine tools and captures.",
               "servotwin"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags (-q, -f) may follow the subcommand
  app.set_version_flag("--version", std::string("servotwin ") + servotwin::kVersion);
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No progress messages on stderr");
  app.add_flag("-f,--force", global.force, "Overwrite existing output files");
  app.add_option("-j,--threads", global.threads,
                 "Worker threads for long traces (predict, identify); 0 = every core (default). The results are "
                 "the same for any number")
      ->check(CLI::Range(std::size_t{0}, std::size_t{1024}));
  app.footer(
      "\nRun 'servotwin <command> --help' for the options and examples of a command.\n"
      "Exit status: 0 success, 2 usage error, 3 bad input (file, value), 4 an output could not be written (disk full, "
      "closed pipe), 1 internal error.");

  Action selected;
  for (Registrar add : {register_gcode, register_interpolate, register_capture, register_import, register_identify, register_solve,
                         register_model, register_predict, register_machine, register_demo, register_frf, register_fit, register_shaper,
                         register_tune, register_simulate})
    add(app, selected);

  if (const std::string unknown = unknown_subcommand(app, argc, argv); !unknown.empty()) {
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    std::fprintf(stderr, "servotwin: error: unknown subcommand '%s' (commands: %s; see servotwin --help)\n",
                 servotwin::core::printable(unknown).c_str(), names.c_str());
    return kUsageError;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kUsageError;
  }
  note_arguments(app);
  try {
    if (!selected) return kUsageError;
    const int status = selected(global);
    publish_outputs();
    // What went to stdout outside an output file (summaries, tables) must have arrived too.
    if (std::fflush(stdout) != 0 || std::ferror(stdout))
      throw servotwin::core::IoError({"<stdout>", 0, 0, ""}, "writing to standard output failed");
    return status;
  } catch (const CLI::ParseError& e) {
    discard_outputs();
    print_error("error", e.what());
    return kUsageError;
  } catch (const servotwin::core::IoError& e) {
    discard_outputs();
    print_error("error", e.what());
    return kIoError;
  } catch (const servotwin::core::InputError& e) {
    discard_outputs();
    print_error("error", e.what());
    return kBadInput;
  } catch (const std::exception& e) {
    discard_outputs();
    print_error("internal error", e.what());
    return kInternalError;
  }
}
