#pragma once
// `servotwin shaper compare a.json b.json ... [--report shapers.html] [--json]`: the cost and
// robustness measures of any set of shapers for one axis, side by side, with an optional HTML
// report of their sensitivity curves, impulse trains and step responses. register_shaper
// (cmd_shaper.cpp) adds it with add_compare(*shaper, selected).
#include <CLI/CLI.hpp>

#include "command.hpp"

namespace servotwin::cli {

/// Adds the `compare` subcommand to the `shaper` command.
void add_compare(CLI::App& shaper, Action& selected);

}  // namespace servotwin::cli
