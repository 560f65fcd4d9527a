#include "servotwin/io/firmware_shaper.hpp"

#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/shaping/firmware.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::io {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr std::size_t kRrfMaxImpulses = 5;  ///< RRF's MaxExtraImpulses (4) + 1

std::string joined(const std::vector<double>& values, const char* format) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ":" : "") + fmt::format(fmt::runtime(format), values[i]);
  return out;
}

}  // namespace

FirmwareShaper klipper_config(const shaping::Shaper& shaper, char axis) {
  const std::string type = shaper.type;
  if (!shaping::klipper_has(type))
    throw core::InputError(core::at_field("type"),
                           "Klipper has no '" + type + "' shaper and no custom impulses: its types are zv, mzv, zvd, "
                           "ei, 2hump_ei, 3hump_ei (export to RepRapFirmware or as a table instead, or select among "
                           "Klipper's types)");
  if (shaper.zeta > shaping::klipper_max_damping(type))
    throw core::InputError(core::at_field("zeta"), fmt::format("Klipper accepts damping_ratio up to {} for {}, the shaper "
                                                               "is designed for {}",
                                                               shaping::klipper_max_damping(type), type, shaper.zeta));
  FirmwareShaper out;
  const double f = shaper.omega / kTwoPi;
  if (type == "ei" || type == "2hump_ei" || type == "3hump_ei") {
    // Klipper computes the EI family from curve fits: say what its version leaves at the mode.
    const shaping::Shaper theirs = shaping::klipper_shaper(type, shaper.omega, shaper.zeta);
    out.notes.push_back(fmt::format(
        "Klipper computes {} itself from Singhose's curve fits (5 % vibration tolerance): at {:.6g} Hz, damping {:.4g} its "
        "version leaves {:.2f} % vibration at the mode, servotwin's {:.2f} %",
        type, f, shaper.zeta, 100.0 * shaping::residual_vibration(theirs, shaper.omega, shaper.zeta),
        100.0 * shaping::residual_vibration(shaper, shaper.omega, shaper.zeta)));
  }
  if (axis == 'z') out.notes.push_back("Klipper shapes the Z axis since 2026 (after v0.13.0)");
  for (const auto& n : out.notes) out.text += "# " + n + "\n";
  out.text += fmt::format("[input_shaper]\nshaper_type_{0}: {1}\nshaper_freq_{0}: {2:.6g}\ndamping_ratio_{0}: {3:.6g}\n",
                          axis, type, f, shaper.zeta);
  return out;
}

FirmwareShaper rrf_m593(const shaping::Shaper& shaper, RrfVersion version) {
  const std::size_t n = shaper.times.size();
  if (n < 2 || n > kRrfMaxImpulses)
    throw core::InputError(core::at_field("times_s"),
                           fmt::format("RepRapFirmware's custom shaper takes 2 to {} impulses, this one has {}", kRrfMaxImpulses, n));
  for (const double a : shaper.amplitudes)
    if (a < 0.0) throw core::InputError(core::at_field("amplitudes"), "RepRapFirmware's custom shaper takes positive impulses only");
  std::vector<double> h, t;
  double cumulative = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    cumulative += shaper.amplitudes[i];
    h.push_back(version == RrfVersion::V3_5 ? cumulative : shaper.amplitudes[i]);
    t.push_back(version == RrfVersion::V3_5 ? shaper.times[i + 1] - shaper.times[i] : shaper.times[i + 1]);
  }
  FirmwareShaper out;
  out.notes.push_back(fmt::format("servotwin {} shaper for {:.6g} Hz, damping {:.4g}: {} impulses over {:.6g} ms "
                                  "(RepRapFirmware {}: H {} amplitudes, T {})",
                                  shaper.type, shaper.omega / kTwoPi, shaper.zeta, n, 1e3 * shaper.duration(),
                                  version == RrfVersion::V3_5 ? "3.4/3.5" : "3.6",
                                  version == RrfVersion::V3_5 ? "cumulative" : "individual",
                                  version == RrfVersion::V3_5 ? "durations between impulses" : "delays from the first"));
  for (const auto& note : out.notes) out.text += "; " + note + "\n";
  out.text += fmt::format("M593 P\"custom\" H{} T{}\n", joined(h, "{:.6f}"), joined(t, "{:.7f}"));
  return out;
}

std::string impulse_table(const shaping::Shaper& shaper) {
  std::string out = fmt::format("# servotwin {} shaper for {:.6g} Hz, damping {:.4g}\n# t_s A\n", shaper.type,
                                shaper.omega / kTwoPi, shaper.zeta);
  for (std::size_t i = 0; i < shaper.times.size(); ++i) out += fmt::format("{} {}\n", shaper.times[i], shaper.amplitudes[i]);
  return out;
}

}  // namespace servotwin::io
