#pragma once
/// \file
/// Machine description JSON, format "servotwin.machine/1" (schema in docs/file-formats.md), and
/// the closed-loop report printed by `servotwin machine --json`.

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "servotwin/machine/axis_config.hpp"
#include "servotwin/machine/closed_loop.hpp"

namespace servotwin::io {

inline constexpr std::string_view kMachineFormat = "servotwin.machine/1";

/// Parses a machine description. Unknown fields are errors (they are usually typos); every error
/// names the source, the line:column for syntax errors, and the JSON path of a bad field
/// (e.g. "axes[1].controller.kp").
machine::MachineConfig parse_machine_json(std::string_view text, std::string_view source_name);

/// A preset name, or else a path to a machine JSON file.
machine::MachineConfig load_machine(const std::string& name_or_path);

/// Full description (round-trips through parse_machine_json).
nlohmann::json machine_to_json(const machine::MachineConfig& machine);

/// Closed-loop report of every axis: `closed_loop` {a1 a2 a3 b0 b1 b2 d0 d1}, poles and zeros
/// (hz, zeta, re, im in rad/s), discrete poles/zeros, `exact` and `method`.
nlohmann::json closed_loop_report(const machine::MachineConfig& machine);

/// Checks the "format" member: missing, not a string, another family, or an unknown major
/// version -> core::InputError.
void check_format(const nlohmann::json& document, std::string_view expected, std::string_view source_name);

}  // namespace servotwin::io
