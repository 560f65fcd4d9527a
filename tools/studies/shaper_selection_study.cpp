// Generates the side-by-side table of docs/shaper-selection-study.md: Klipper's recommendation
// (current commit 84104bb, from the data READMEs) vs servotwin's, both scored by
// shaping::remaining_vibrations and shaping::shaper_smoothing. Built with the tests (target
// shaper_selection_study; the test study.shaper_selection_table checks the document is current), or:
//   build/<dir>/tests/shaper_selection_study data > table.md
#include <fmt/format.h>

#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "servotwin/io/klipper_csv.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/selection.hpp"
#include "servotwin/shaping/smoothing.hpp"

using namespace servotwin;

struct Case {
  const char* file;
  const char* klipper_family;
  double klipper_freq;
};

std::string freq_text(const shaping::ShaperCandidate& c) {
  std::string out;
  for (std::size_t i = 0; i < c.freq_hz.size(); ++i) out += fmt::format("{}{:.1f}", i ? "+" : "", c.freq_hz[i]);
  return out;
}

int main(int argc, char** argv) {
  const std::string data = argc > 1 ? argv[1] : "data";
  const std::vector<Case> cases = {
      {"klipper-ender5s1-psd/resonances_x_20230321_171058.csv", "3hump_ei", 58.4},
      {"klipper-ender5s1-psd/resonances_y_20230321_171849.csv", "3hump_ei", 72.8},
      {"klipper-ender5s1-psd/calibration_data_x_20230321_165958.csv", "2hump_ei", 40.4},
      {"klipper-ender5s1-psd/calibration_data_y_20230321_165958.csv", "mzv", 31.0},
      {"klipper-voron24-psd/resonances_x_20221231_212825.csv", "mzv", 63.4},
      {"klipper-voron24-psd/resonances_y_20221231_213042.csv", "mzv", 44.0},
  };
  fmt::print("| file | Klipper 84104bb | vibr. | smoothing | ours, default rule | vibr. | smoothing | "
             "ours at Klipper's smoothing (least vibration) | vibr. | smoothing | peaks [Hz] |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Case& c : cases) {
    const shaping::Spectrum s = io::load_klipper_csv(data + "/" + c.file);
    const shaping::PreparedSpectrum p = shaping::prepare_spectrum(s);
    const shaping::Shaper theirs = shaping::design_shaper(shaping::parse_shaper_type(c.klipper_family),
                                                          2.0 * std::numbers::pi * c.klipper_freq, 0.1);
    const double tv = shaping::remaining_vibrations(theirs, p);
    const double ts = shaping::shaper_smoothing(theirs);
    const shaping::SpectrumSelectionOptions defaults;
    const shaping::ShaperSelection ours = shaping::select_shaper_from_spectrum(s, defaults);
    shaping::SpectrumSelectionOptions equal;
    equal.max_smoothing = ts;
    equal.vibration_tolerance = 0.0;
    const shaping::ShaperSelection matched = shaping::select_shaper_from_spectrum(s, equal);
    std::string peaks;
    for (const shaping::SpectrumPeak& pk : ours.peaks) peaks += fmt::format("{}{:.1f}", peaks.empty() ? "" : ", ", pk.freq_hz);
    const std::string name = std::string(c.file).substr(std::string(c.file).find('/') + 1);
    fmt::print("| {} | {} @ {:.1f} | {:.2f} % | {:.3f} | {} @ {} | {:.2f} % | {:.3f} | {} @ {} | {:.2f} % | {:.3f} | {} |\n",
               name, c.klipper_family, c.klipper_freq, 100 * tv, ts, ours.recommended.name,
               freq_text(ours.recommended), 100 * ours.recommended.vibrations, ours.recommended.smoothing,
               matched.recommended.name, freq_text(matched.recommended), 100 * matched.recommended.vibrations,
               matched.recommended.smoothing, peaks);
  }
  fmt::print("\nPer-family choices of the default rule (vibrations %, smoothing):\n\n");
  for (const Case& c : cases) {
    const shaping::Spectrum s = io::load_klipper_csv(data + "/" + c.file);
    const shaping::SpectrumSelectionOptions defaults;
    const shaping::ShaperSelection ours = shaping::select_shaper_from_spectrum(s, defaults);
    std::string row;
    for (const shaping::ShaperCandidate& a : ours.alternatives)
      row += fmt::format("{}{} @ {} ({:.1f} %, {:.3f})", row.empty() ? "" : "; ", a.name, freq_text(a),
                         100 * a.vibrations, a.smoothing);
    fmt::print("- `{}`: {}\n", std::string(c.file).substr(std::string(c.file).find('/') + 1), row);
  }
  return 0;
}
