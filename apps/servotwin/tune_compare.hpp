#pragma once
// `servotwin tune compare`: the structures of catalog C7.15 tuned to one spec on one plant.

#include <CLI/CLI.hpp>

#include "command.hpp"

namespace servotwin::cli {

/// Adds the `compare` subcommand to the `tune` command.
void add_tune_compare(CLI::App& tune, Action& selected);

}  // namespace servotwin::cli
