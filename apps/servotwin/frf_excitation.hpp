#pragma once
// `servotwin frf excitation`: write an excitation (multisine, chirp, sine steps) for a drive's own
// signal generator. register_frf (cmd_frf.cpp) adds it with add_excitation(*frf, selected).
#include <CLI/CLI.hpp>

#include "command.hpp"

namespace servotwin::cli {

/// Adds the `excitation` subcommand to the `frf` command.
void add_excitation(CLI::App& frf, Action& selected);

}  // namespace servotwin::cli
