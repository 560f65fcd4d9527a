#include "shaper_export.hpp"

#include "servotwin/core/error.hpp"
#include "servotwin/io/firmware_shaper.hpp"

namespace servotwin::cli {

void ShaperExport::add_to(CLI::App& command) {
  command.add_option("--export", target,
                     "Write the shaper as a firmware takes it: klipper ([input_shaper] lines; Klipper's types only), rrf "
                     "(RepRapFirmware M593 P\"custom\" H.. T..) or table (t_s A per impulse)")
      ->check(CLI::IsMember({"klipper", "rrf", "table"}));
  command.add_option("--export-axis", axis, "--export klipper: the axis of the [input_shaper] keys (x, y or z)")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  command.add_option("--rrf-version", rrf_version,
                     "--export rrf: RepRapFirmware 3.5 (also 3.4: H cumulative, T between impulses) or 3.6 (H each, T "
                     "from the first)")
      ->check(CLI::IsMember({"3.4", "3.5", "3.6"}))
      ->capture_default_str();
}

std::string ShaperExport::text(const shaping::Shaper& shaper) const {
  try {
    if (target == "klipper") return io::klipper_config(shaper, axis.front()).text;
    if (target == "rrf") return io::rrf_m593(shaper, rrf_version == "3.6" ? io::RrfVersion::V3_6 : io::RrfVersion::V3_5).text;
    return io::impulse_table(shaper);
  } catch (const core::InputError& e) {
    throw core::InputError(core::at_field("--export " + target), e.reason());
  }
}

}  // namespace servotwin::cli
