#pragma once
// `servotwin shaper apply`: shape a commanded trajectory CSV with a shaper JSON file and report
// the contour distortion. register_shaper (cmd_shaper.cpp) adds it with add_apply(*shaper, selected).
#include <CLI/CLI.hpp>

#include "command.hpp"

namespace servotwin::cli {

/// Adds the `apply` subcommand to the `shaper` command.
void add_apply(CLI::App& shaper, Action& selected);

}  // namespace servotwin::cli
