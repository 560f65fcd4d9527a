// Automatic shaper selection (shaping/selection.hpp) on the real Klipper spectra in data/.
// References: tools/reference/klipper_selection_reference.py (independent numpy implementation of
// the remaining-vibration measure → tests/data/shaping/klipper_selection.json), the percentages
// Klipper printed (data/klipper-*/README.md, Klipper commit 84104bb), brute-force scans, and
// closed-form properties (convolution = product of vibration ratios).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/multimode.hpp"
#include "servotwin/shaping/selection.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/smoothing.hpp"

namespace servotwin::shaping {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Minimal reader of the Klipper files for this test (the real reader, io/klipper_csv, is tested
/// in tests/io; the shaping tests do not link io).
Spectrum load_psd(const std::string& relative) {
  const std::string path = std::string(SERVOTWIN_REPO_DATA_DIR) + "/" + relative;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("missing data file " + path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ',');) header.push_back(cell);
  Spectrum s;
  s.source = relative;
  s.normalized = line.find('(') != std::string::npos;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::vector<double> v;
    std::size_t col = 0;
    for (std::string cell; std::getline(ls, cell, ','); ++col)
      if (col < 5) v.push_back(std::stod(cell));
    s.freq_hz.push_back(v[0]);
    s.psd_x.push_back(v[1]);
    s.psd_y.push_back(v[2]);
    s.psd_z.push_back(v[3]);
    s.psd_sum.push_back(v[4]);
  }
  return s;
}

Shaper klipper_choice(const std::string& family, double freq_hz) {
  return design_shaper(parse_shaper_type(family), kTwoPi * freq_hz, 0.1);
}

TEST(Selection, RemainingVibrationsMatchIndependentReference) {
  const nlohmann::json fixture = test::load_fixture("klipper_selection.json");
  for (const auto& c : fixture.at("cases")) {
    const Spectrum s = load_psd(c.at("file").get<std::string>());
    EXPECT_EQ(s.normalized, c.at("normalized").get<bool>()) << c.at("file");
    const PreparedSpectrum p = prepare_spectrum(s);
    ASSERT_EQ(p.freq_hz.size(), c.at("bins").get<std::size_t>());
    double top = 0.0;
    for (double v : p.psd) top = std::max(top, v);
    EXPECT_NEAR(top, c.at("psd_max").get<double>(), 1e-12 * top);
    for (const auto& e : c.at("shapers")) {
      Shaper sh;
      sh.times = e.at("times_s").get<std::vector<double>>();
      sh.amplitudes = e.at("amplitudes").get<std::vector<double>>();
      const double expected = e.at("remaining_vibrations").get<double>();
      EXPECT_NEAR(remaining_vibrations(sh, p), expected, 1e-10) << c.at("file") << " " << e.at("family");
      const std::string family = e.at("family").get<std::string>();
      if (family == "zv*zv") continue;
      // Our family designs are the same impulses as the reference's closed forms.
      const Shaper ours = klipper_choice(family, e.at("freq_hz").get<double>());
      test::expect_near_all(ours.times, sh.times, 1e-12);
      test::expect_near_all(ours.amplitudes, sh.amplitudes, 1e-12);
    }
  }
}

/// Klipper's per-family choices and printed vibrations (README, current Klipper 84104bb; for the
/// calibration_data files the run with the `shapers:` marker added).
struct KlipperRow {
  const char* family;
  double freq_hz;
  double printed_percent;
};
struct KlipperFile {
  const char* file;
  std::vector<KlipperRow> rows;
  const char* recommended;
  double recommended_freq_hz;
};

std::vector<KlipperFile> klipper_results() {
  return {
      {"klipper-ender5s1-psd/resonances_x_20230321_171058.csv",
       {{"zv", 21.0, 40.6}, {"mzv", 27.6, 42.9}, {"ei", 33.2, 43.8}, {"2hump_ei", 46.2, 41.6}, {"3hump_ei", 58.4, 41.4}},
       "3hump_ei", 58.4},
      {"klipper-ender5s1-psd/resonances_y_20230321_171849.csv",
       {{"zv", 22.4, 44.6}, {"mzv", 31.6, 38.9}, {"ei", 43.8, 41.4}, {"2hump_ei", 57.6, 41.2}, {"3hump_ei", 72.8, 40.9}},
       "3hump_ei", 72.8},
      {"klipper-ender5s1-psd/calibration_data_x_20230321_165958.csv",
       {{"zv", 21.0, 28.9}, {"mzv", 25.0, 35.0}, {"ei", 29.0, 31.9}, {"2hump_ei", 40.4, 28.0}, {"3hump_ei", 48.0, 24.6}},
       "2hump_ei", 40.4},
      {"klipper-ender5s1-psd/calibration_data_y_20230321_165958.csv",
       {{"zv", 51.0, 21.9}, {"mzv", 31.0, 1.7}, {"ei", 42.2, 3.5}, {"2hump_ei", 40.8, 0.0}, {"3hump_ei", 49.4, 0.0}},
       "mzv", 31.0},
      {"klipper-voron24-psd/resonances_x_20221231_212825.csv",
       {{"zv", 61.2, 1.2}, {"mzv", 63.4, 0.0}, {"ei", 57.4, 0.0}, {"2hump_ei", 99.8, 0.0}, {"3hump_ei", 125.2, 0.0}},
       "mzv", 63.4},
      {"klipper-voron24-psd/resonances_y_20221231_213042.csv",
       {{"zv", 43.0, 0.9}, {"mzv", 44.0, 0.0}, {"ei", 54.2, 0.0}, {"2hump_ei", 69.6, 0.0}, {"3hump_ei", 87.2, 0.0}},
       "mzv", 44.0},
  };
}

TEST(Selection, KlipperPrintedVibrationsReproduced) {
  for (const KlipperFile& k : klipper_results()) {
    const PreparedSpectrum p = prepare_spectrum(load_psd(k.file));
    for (const KlipperRow& r : k.rows) {
      const double ours = 100.0 * remaining_vibrations(klipper_choice(r.family, r.freq_hz), p);
      const std::string family = r.family;
      // ZV and MZV impulses are identical to Klipper's: only the printed rounding (0.05 points)
      // separates the values. Our EI family solves the defining conditions exactly where Klipper
      // uses curve fits (families.hpp): the same (type, freq) leaves up to ~1.5 points more or less.
      const double tolerance = family == "zv" || family == "mzv" ? 0.051 : 1.5;
      EXPECT_NEAR(ours, r.printed_percent, tolerance) << k.file << " " << family << " @ " << r.freq_hz;
    }
  }
}

TEST(Selection, OursLeavesNoMoreVibrationThanKlippersPickAtEqualOrLowerSmoothing) {
  for (const KlipperFile& k : klipper_results()) {
    const Spectrum s = load_psd(k.file);
    const PreparedSpectrum p = prepare_spectrum(s);
    const Shaper theirs = klipper_choice(k.recommended, k.recommended_freq_hz);
    const double their_vibrations = remaining_vibrations(theirs, p);
    SpectrumSelectionOptions o;
    o.max_smoothing = shaper_smoothing(theirs);
    o.vibration_tolerance = 0.0;  // pure minimization: the claim is about least vibration
    const ShaperSelection ours = select_shaper_from_spectrum(s, o);
    EXPECT_LE(ours.recommended.smoothing, *o.max_smoothing * (1.0 + 1e-12)) << k.file;
    EXPECT_LE(ours.recommended.vibrations, their_vibrations + 1e-12) << k.file;
    // Reported numbers are exact evaluations of the reported shaper.
    EXPECT_DOUBLE_EQ(ours.recommended.vibrations, remaining_vibrations(ours.recommended.shaper, p)) << k.file;
    EXPECT_NEAR(ours.recommended.smoothing, shaper_smoothing(ours.recommended.shaper), 1e-12) << k.file;
  }
}

TEST(Selection, FrequencyScanAgreesWithBruteForceExactScan) {
  // One family, no tolerance: the tabulated scan must find the exact minimum of the 0.2 Hz grid.
  for (const char* file : {"klipper-ender5s1-psd/resonances_y_20230321_171849.csv",
                           "klipper-ender5s1-psd/calibration_data_x_20230321_165958.csv"}) {
    const Spectrum s = load_psd(file);
    const PreparedSpectrum p = prepare_spectrum(s);
    for (ShaperType t : {ShaperType::kMzv, ShaperType::kThreeHumpEi}) {
      SpectrumSelectionOptions o;
      o.families = {t};
      o.multi_mode = false;
      o.vibration_tolerance = 0.0;
      const ShaperSelection sel = select_shaper_from_spectrum(s, o);
      double brute = 1e9;
      for (int k = 25; k <= 1000; ++k) {
        const double f = 0.2 * k;
        const Shaper sh = design_shaper(t, kTwoPi * f, 0.1);
        if (shaper_smoothing(sh, 1500.0, 5.0) > 0.12) continue;  // suggested max_accel < 1500
        brute = std::min(brute, remaining_vibrations(sh, p));
      }
      EXPECT_NEAR(sel.recommended.vibrations, brute, 1e-9) << file << " " << to_string(t);
      EXPECT_GE(sel.recommended.max_accel, 1500.0 * (1.0 - 1e-9));
    }
  }
}

/// PSD of two lightly damped modes seen by an accelerometer, 1.25 Hz bins like Klipper's.
Spectrum two_mode_spectrum(double f1, double f2, double zeta, double gain2) {
  Spectrum s;
  s.source = "synthetic";
  for (int k = 0; k <= 160; ++k) {
    const double f = 1.25 * k;
    auto mode = [&](double fn) {
      const double r = f / fn;
      return r * r * r * r / ((1 - r * r) * (1 - r * r) + (2 * zeta * r) * (2 * zeta * r));
    };
    const double v = 1e3 * (mode(f1) + gain2 * mode(f2)) * (f + 0.1);
    s.freq_hz.push_back(f);
    s.psd_x.push_back(v);
    s.psd_y.push_back(0.0);
    s.psd_z.push_back(0.0);
    s.psd_sum.push_back(v);
  }
  return s;
}

TEST(Selection, TwoSeparatedResonancesGiveATwoModeCandidate) {
  const Spectrum s = two_mode_spectrum(35.0, 95.0, 0.04, 0.8);
  const PreparedSpectrum p = prepare_spectrum(s);
  const std::vector<SpectrumPeak> peaks = find_spectrum_peaks(p);
  ASSERT_EQ(peaks.size(), 2u);
  EXPECT_NEAR(peaks[0].freq_hz, 35.0, 1.25);
  EXPECT_NEAR(peaks[1].freq_hz, 95.0, 1.25);

  SpectrumSelectionOptions o;
  o.vibration_tolerance = 0.0;
  o.max_smoothing = 0.08;
  const ShaperSelection with = select_shaper_from_spectrum(s, o);
  o.multi_mode = false;
  const ShaperSelection without = select_shaper_from_spectrum(s, o);
  const ShaperCandidate* two = nullptr;
  for (const ShaperCandidate& c : with.alternatives)
    if (c.freq_hz.size() == 2) two = &c;
  ASSERT_NE(two, nullptr);
  // The convolved shaper is scored exactly like any other, its smoothing computed without building
  // it agrees with smoothing.hpp on the built shaper.
  EXPECT_NEAR(two->vibrations, remaining_vibrations(two->shaper, p), 1e-5);
  EXPECT_NEAR(two->smoothing, shaper_smoothing(two->shaper), 1e-12);
  EXPECT_LE(two->smoothing, 0.08 * (1 + 1e-12));
  // A larger pool can only help the pure minimization.
  EXPECT_LE(with.recommended.vibrations, without.recommended.vibrations + 1e-12);
  // On this spectrum one single-mode shaper under the limit cannot cancel both peaks.
  EXPECT_LT(two->vibrations, without.recommended.vibrations);
  EXPECT_EQ(with.recommended.freq_hz.size(), 2u);
}

TEST(Selection, ConvolutionVibrationIsTheProductOfFactors) {
  // The property the two-mode scan relies on: V(conv) = V(a)·V(b) at every frequency and damping.
  const Shaper a = design_shaper(ShaperType::kMzv, kTwoPi * 30.0, 0.1);
  const Shaper b = design_shaper(ShaperType::kZv, kTwoPi * 80.0, 0.1);
  const Shaper ab = convolve_shapers(a, b);
  for (double f : {5.0, 29.0, 47.5, 80.0, 133.0})
    for (double z : {0.0, 0.075, 0.15})
      EXPECT_NEAR(residual_vibration(ab, kTwoPi * f, z),
                  residual_vibration(a, kTwoPi * f, z) * residual_vibration(b, kTwoPi * f, z), 1e-13);
}

TEST(Selection, DefaultRuleTradesNegligibleVibrationForLessSmoothing) {
  const Spectrum s = load_psd("klipper-voron24-psd/resonances_x_20221231_212825.csv");
  const SpectrumSelectionOptions defaults;
  const ShaperSelection sel = select_shaper_from_spectrum(s, defaults);
  double least = 1.0;
  for (const ShaperCandidate& c : sel.alternatives) least = std::min(least, c.vibrations);
  EXPECT_LE(sel.recommended.vibrations, least + 0.005 + 1e-12);
  for (const ShaperCandidate& c : sel.alternatives) {
    if (c.vibrations <= least + 0.005) {
      EXPECT_GE(c.smoothing, sel.recommended.smoothing - 1e-12) << c.name;
    }
    EXPECT_GE(c.max_accel, 1500.0 * (1.0 - 1e-9)) << c.name;
  }
  EXPECT_FALSE(sel.reasons.empty());
}

TEST(Selection, LimitsAreRespectedOrReported) {
  const Spectrum s = load_psd("klipper-ender5s1-psd/resonances_x_20230321_171058.csv");
  SpectrumSelectionOptions o;
  o.max_delay_s = 0.012;
  const ShaperSelection sel = select_shaper_from_spectrum(s, o);
  for (const ShaperCandidate& c : sel.alternatives) EXPECT_LE(c.duration_s, 0.012 * (1 + 1e-12)) << c.name;
  o.max_delay_s.reset();
  o.max_smoothing = 1e-4;  // below what any shaper up to 200 Hz reaches
  EXPECT_THROW((void)select_shaper_from_spectrum(s, o), core::InputError);
}

TEST(Selection, BadSpectraAreRejected) {
  Spectrum s = two_mode_spectrum(35.0, 95.0, 0.04, 0.8);
  Spectrum bad = s;
  bad.freq_hz[10] = bad.freq_hz[9];
  EXPECT_THROW((void)prepare_spectrum(bad), core::InputError);
  bad = s;
  bad.psd_sum[20] = -1.0;
  EXPECT_THROW((void)prepare_spectrum(bad), core::InputError);
  bad = s;
  bad.psd_sum[20] = std::nan("");
  EXPECT_THROW((void)prepare_spectrum(bad), core::InputError);
  bad = s;
  bad.psd_sum.pop_back();
  EXPECT_THROW((void)prepare_spectrum(bad), core::InputError);
  bad = s;
  for (double& v : bad.psd_sum) v = 0.0;
  EXPECT_THROW((void)prepare_spectrum(bad), core::InputError);
  SpectrumSelectionOptions o;
  o.design_zeta = 1.0;
  EXPECT_THROW((void)select_shaper_from_spectrum(s, o), core::InputError);
}

TEST(Selection, NormalizationFollowsItsDefinition) {
  const std::vector<double> f = {0.0, 5.0, 9.9, 10.0, 50.0};
  const std::vector<double> p = {1.0, 2.0, 3.0, 4.0, 5.0};
  const std::vector<double> n = normalize_psd(f, p);
  EXPECT_NEAR(n[0], 1.0 / 0.1 * std::exp(1.0 - 100.0 / 0.01), 1e-300);
  EXPECT_NEAR(n[1], 2.0 / 5.1 * std::exp(1.0 - std::pow(10.0 / 5.1, 2)), 1e-15);
  EXPECT_NEAR(n[2], 3.0 / 10.0 * std::exp(1.0 - 1.0), 1e-15);
  EXPECT_DOUBLE_EQ(n[3], 4.0 / 10.1);
  EXPECT_DOUBLE_EQ(n[4], 5.0 / 50.1);
}

// ---------------------------------------------------------------------------------------------
// Known damping (fitted plant model).

double brute_worst(const Shaper& sh, const std::vector<KnownMode>& modes, double band, double dz) {
  double worst = 0.0;
  for (const KnownMode& m : modes)
    for (int k = 0; k <= 200; ++k) {
      const double w = kTwoPi * m.freq_hz * (1.0 - band + 2.0 * band * k / 200.0);
      for (double z : {std::max(0.0, m.zeta - dz), m.zeta, m.zeta + dz}) worst = std::max(worst, residual_vibration(sh, w, z));
    }
  return worst;
}

TEST(Selection, ModelPathDesignsWithTheFittedDamping) {
  const std::vector<KnownMode> modes = {{42.0, 0.015}};
  ModelSelectionOptions o;
  o.band_points = 201;
  const ShaperSelection sel = select_shaper_from_model(modes, o);
  for (const ShaperCandidate& c : sel.alternatives) {
    // Each candidate cancels the mode exactly at the fitted frequency and damping (EI: by design
    // V = v_tol there).
    const double at_mode = residual_vibration(c.shaper, kTwoPi * 42.0, 0.015);
    if (c.name == "ei" || c.name == "3hump_ei") {
      EXPECT_NEAR(at_mode, 0.05, 1e-6) << c.name;
    } else {
      EXPECT_NEAR(at_mode, 0.0, 1e-9) << c.name;
    }
    EXPECT_NEAR(c.vibrations, brute_worst(c.shaper, modes, 0.05, 0.02), 1e-12) << c.name;
  }
  // ZV designed for the assumed 0.1 instead of 0.015 leaves much more at the fitted mode.
  for (const ShaperCandidate& c : sel.alternatives)
    if (c.name == "zv") {
      EXPECT_GT(c.vibrations_assumed_damping, c.vibrations + 0.05);
    }
}

TEST(Selection, ModelPathHandlesSeveralModes) {
  const std::vector<KnownMode> modes = {{18.0, 0.01}, {61.0, 0.03}};
  ModelSelectionOptions o;
  o.freq_uncertainty = 0.0;
  o.zeta_uncertainty = 0.0;
  o.band_points = 1;
  o.families = {ShaperType::kZv, ShaperType::kZvd, ShaperType::kMzv};
  const ShaperSelection sel = select_shaper_from_model(modes, o);
  EXPECT_EQ(sel.alternatives.size(), 3u);
  for (const ShaperCandidate& c : sel.alternatives) {
    EXPECT_NEAR(residual_vibration(c.shaper, kTwoPi * 18.0, 0.01), 0.0, 1e-9) << c.name;
    EXPECT_NEAR(residual_vibration(c.shaper, kTwoPi * 61.0, 0.03), 0.0, 1e-9) << c.name;
    EXPECT_EQ(c.freq_hz.size(), 2u);
  }
  // All cancel exactly; the tie is broken by least smoothing: ZV*ZV.
  EXPECT_EQ(sel.recommended.name, "zv");
  o.max_smoothing = 1e-4;
  EXPECT_THROW((void)select_shaper_from_model(modes, o), core::InputError);
  const ModelSelectionOptions defaults;
  EXPECT_THROW((void)select_shaper_from_model(std::vector<KnownMode>{}, defaults), core::InputError);
  EXPECT_THROW((void)select_shaper_from_model({{-1.0, 0.1}}, defaults), core::InputError);
  EXPECT_THROW((void)select_shaper_from_model({{10.0, 1.0}}, defaults), core::InputError);
}

}  // namespace
}  // namespace servotwin::shaping
