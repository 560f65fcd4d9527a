#pragma once
/// \file
/// Trace profiles (`servotwin.trace-profile/1`): how to read one controller's trace files, stored
/// once instead of retyped: the layout (`trace_format`, `delimiter`, `comment_prefix`), the
/// column names of a headerless file (`columns`), the map from servotwin's names to the file's
/// (`map`), the unit of its positions (`units`, or a `scale` to mm) and its sample period (`ts`).
///
/// ```json
/// {"format": "servotwin.trace-profile/1",
///  "description": "LinuxCNC halsampler -t, servotwin's integration rig",
///  "trace_format": "halsampler",
///  "columns": ["x_cmd", "x_act", "x_u", "y_cmd", "y_act", "y_u"],
///  "units": "mm", "ts": 0.001}
/// ```
///
/// `units` is one of mm, m, um, nm, inch: it sets the scale to mm (m: 1000); a `scale` beside it
/// must agree, one alone is any factor to mm. Every member but `format` is optional.

#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "servotwin/io/capture_csv.hpp"

namespace servotwin::io {

struct TraceProfile {
  std::string description;
  CaptureReadOptions reading;  ///< format, columns, delimiter, comment prefix, map, scale, ts, max_jitter
  std::string units;  ///< as written in the file ("" when it gives a scale or nothing)
};

/// Millimetres per unit of "mm", "m", "um", "nm", "inch" (empty when unknown).
std::optional<double> millimetres_per(std::string_view unit) noexcept;

/// Parses a profile; core::InputError naming the source and the member for an unknown format
/// version, member, trace format, unit or a scale that disagrees with the unit.
TraceProfile parse_trace_profile(std::string_view text, std::string_view source_name);
TraceProfile read_trace_profile(const std::string& path);
/// Writes a profile (members that are at their defaults are left out).
void write_trace_profile(std::ostream& out, const TraceProfile& profile);

}  // namespace servotwin::io
