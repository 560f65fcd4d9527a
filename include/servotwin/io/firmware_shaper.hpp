#pragma once
/// \file
/// A shaper written as a firmware takes it (issue 25 §6):
///
/// * Klipper: the `[input_shaper]` section, `shaper_type_<axis>`, `shaper_freq_<axis>` [Hz],
///   `damping_ratio_<axis>` (docs/Config_Reference.md). Klipper has no impulse table: only its own
///   types (zv, mzv, zvd, ei, 2hump_ei, 3hump_ei), whose impulses it computes itself
///   (shaping/firmware.hpp). For zv, zvd and mzv those are servotwin's; for the EI family a
///   comment gives the vibration Klipper's version leaves at the design mode beside servotwin's.
/// * RepRapFirmware: `M593 P"custom" H<a:b:..> T<t:u:..>` (docs.duet3d.com M593, RRF's
///   AxisShaper.cpp). 3.4 and 3.5: H the cumulative amplitudes of every impulse but the last (the
///   last is 1), T the durations between consecutive impulses [s]. 3.6: H the amplitudes of every
///   impulse but the last (the last is 1 minus their sum), T the delays of every impulse but the
///   first [s]. At most 5 impulses. Any shaper with positive impulses can be written.
/// * A plain table, one impulse a line: `t [s]` and `A`.

#include <string>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::io {

/// Text for a firmware and what the user should know about it.
struct FirmwareShaper {
  std::string text;                ///< lines to put in the firmware's configuration
  std::vector<std::string> notes;  ///< also written into `text` as comments
};

/// Klipper's `[input_shaper]` lines for `axis` ('x', 'y' or 'z'). core::InputError (field
/// "type") for a shaper Klipper has no type for, naming Klipper's types and the RepRapFirmware /
/// table exports, and (field "zeta") for a damping beyond Klipper's limit for that type.
FirmwareShaper klipper_config(const shaping::Shaper& shaper, char axis);

enum class RrfVersion { V3_5, V3_6 };  ///< 3.4 reads as 3.5
/// RepRapFirmware's M593 custom shaper. core::InputError for more than 5 impulses or a negative
/// amplitude (RRF's custom shaper assumes a monotone step response).
FirmwareShaper rrf_m593(const shaping::Shaper& shaper, RrfVersion version);

/// The impulse table: a header line, then `t_s A` per impulse (shortest exact numbers).
std::string impulse_table(const shaping::Shaper& shaper);

}  // namespace servotwin::io
