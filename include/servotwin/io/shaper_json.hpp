#pragma once
/// \file
/// Shaper JSON, format "servotwin.shaper/1":
///
///   {"format": "servotwin.shaper/1", "type": "zv4", "freq_hz": 0.6716, "zeta": 0.0079,
///    "times_s": [0, 0.5956, ...], "amplitudes": [0.1424, ...], "duration_s": 1.7867,
///    "residual_at_design": 1e-16,
///    optional "parameters": {"p1": .., "p2": .., "p3": ..} (zv4) or {"v_tol": ..} (EI family),
///    optional "ts": sample period the shaper was designed for [s],
///    optional "robustness": {"band_level": .., "band_low_hz": .., "band_high_hz": ..,
///                            "band_width_normalized": .., "smoothing": .., "smoothing_accel": ..,
///                            "smoothing_scv": ..},
///    optional "alternatives": [...], "reasons": [...] (written by `shaper select`: the runners-up
///    and why the recommendation won; informative, not read back),
///    a discrete shaper (`shaper design --ts`): "discrete": true, "ts", "samples": [0, k1, ...]
///    (the impulses' sample indices: times_s[i] = samples[i] ts), "discretization": "exact" or
///    "round", and the design it came from, "continuous": {"times_s": [...], "amplitudes": [...]};
///    residual_at_design is then the discrete shaper's}
///
/// freq_hz is the design frequency in Hz (the library works in rad/s). The reader checks: the
/// format's major version, required members, finite numbers, times starting at 0 and strictly
/// increasing, as many amplitudes as times, amplitudes summing to 1 within 1e-9, freq_hz > 0,
/// zeta in [0, 1). Derived members (duration_s, residual_at_design, robustness) are informative:
/// duration_s must equal the last time within 1e-9 s. Unknown top-level members are errors (usually
/// typos). A discrete shaper's samples must start at 0, increase strictly and match times_s / ts
/// (within 1e-9 of a sample). Every error is a core::InputError naming the source and the field.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::io {

inline constexpr std::string_view kShaperFormat = "servotwin.shaper/1";

/// Extra, optional members of a shaper file.
/// The sample grid a discrete shaper lies on.
struct DiscreteForm {
  std::vector<std::size_t> samples;  ///< impulse delays [samples], samples.front() == 0
  std::string discretization;        ///< "exact" or "round"
  shaping::Shaper continuous;        ///< the design it was discretized from (times, amplitudes)
};

struct ShaperFileExtras {
  nlohmann::json parameters = nlohmann::json::object();  ///< design parameters (written when not empty)
  std::optional<double> ts;                               ///< sample period [s]
  nlohmann::json robustness = nlohmann::json::object();   ///< robustness/cost summary (written when not empty)
  std::optional<DiscreteForm> discrete;                   ///< set for a discrete shaper (needs ts)
};

/// A shaper read from a file with its optional members.
struct LoadedShaper {
  shaping::Shaper shaper;
  ShaperFileExtras extras;
};

/// The JSON document of a shaper (residual_at_design computed with shaping::residual_vibration).
nlohmann::json shaper_to_json(const shaping::Shaper& shaper, const ShaperFileExtras& extras = {});

/// Parses a shaper document; `source_name` is used in error messages.
LoadedShaper parse_shaper_json(std::string_view text, std::string_view source_name);

/// Reads a shaper file (core::InputError when it cannot be opened).
LoadedShaper load_shaper(const std::string& path);

}  // namespace servotwin::io
