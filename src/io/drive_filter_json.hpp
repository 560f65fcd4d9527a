#pragma once
// The "drive_filters" member of servotwin.controller/1 (issue 25 §5): each filter by its spec
// (the centre/width/depth or frequency/damping a drive's menu takes), its continuous transfer
// function and its discrete biquad (b0 b1 b2 a1 a2 at the drive's period).

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "json_reader.hpp"
#include "servotwin/tuning/drive_filter.hpp"

namespace servotwin::io::detail {

[[nodiscard]] nlohmann::json drive_filters_json(const std::vector<tuning::DriveFilter>& filters);

/// Reads the array at `key` of `parent` (absent: none, as in files written before 2026-12-02). Each
/// filter is rebuilt from its spec; the continuous and discrete coefficients in the file must agree
/// with it (1e-6 relative), and a filter's discrete period must be the controller's
/// (`controller_ts`, when it has one), else core::InputError naming the member.
[[nodiscard]] std::vector<tuning::DriveFilter> read_drive_filters(const nlohmann::json& parent, const JsonObject& object,
                                                                  std::string_view key,
                                                                  std::optional<double> controller_ts);

}  // namespace servotwin::io::detail
