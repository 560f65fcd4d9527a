#pragma once
// `servotwin shaper multimode`: one shaper for several modes, by direct LP synthesis (catalog C6.4,
// shaping/lp_shaper.hpp) or by convolution of single-mode shapers (shaping/multimode.hpp).
// register_shaper (cmd_shaper.cpp) adds it with add_multimode(*shaper, selected).
#include <CLI/CLI.hpp>

#include "command.hpp"

namespace servotwin::cli {

/// Adds the `multimode` subcommand to the `shaper` command.
void add_multimode(CLI::App& shaper, Action& selected);

}  // namespace servotwin::cli
