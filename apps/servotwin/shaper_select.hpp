#pragma once
// `servotwin shaper select resonances_x.csv|plant_model.json`: automatic choice of shaper family
// and frequency (shaping/selection.hpp). register_shaper (cmd_shaper.cpp) adds it with
// add_select(*shaper, selected).
#include <CLI/CLI.hpp>

#include "command.hpp"

namespace servotwin::cli {

/// Adds the `select` subcommand to the `shaper` command.
void add_select(CLI::App& shaper, Action& selected);

}  // namespace servotwin::cli
