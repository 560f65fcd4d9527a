// Excitation design (issue 25 §4). Expected values: Schroeder crest factors and the chirp's cycles
// from tools/reference/excitation_reference.py (numpy, independent synthesis); the line spectra
// from a direct O(N²) DFT written here; the rest from the definitions (peak = amplitude, whole
// cycles per window, periodicity).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "field_of.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_design.hpp"

namespace servotwin::frf {
namespace {

/// |DFT| of u[first … first+n) at every line 0 … n/2, summed directly.
double design_line_magnitude(const std::vector<double>& u, std::size_t first, std::size_t n, std::size_t k) {
  std::complex<double> sum;
  for (std::size_t i = 0; i < n; ++i)
    sum += u[first + i] * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>((k * i) % n) / static_cast<double>(n));
  return std::abs(sum);
}

std::vector<double> design_line_magnitudes(const std::vector<double>& u, std::size_t first, std::size_t n) {
  std::vector<double> mags(n / 2 + 1);
  for (std::size_t k = 0; k <= n / 2; ++k) mags[k] = design_line_magnitude(u, first, n, k);
  return mags;
}

ExcitationRequest design_request(ExcitationType type, double f0, double f1, double ts, double duration, double amp) {
  ExcitationRequest r;
  r.type = type;
  r.f_begin_hz = f0;
  r.f_end_hz = f1;
  r.ts = ts;
  r.duration_s = duration;
  r.amplitude = amp;
  return r;
}

double peak_of(const std::vector<double>& u) {
  double p = 0.0;
  for (double v : u) p = std::max(p, std::abs(v));
  return p;
}

TEST(MultisineDesign, FullBandPeriodLinesAndSchroederCrestFactor) {
  const Excitation e = design_excitation(design_request(ExcitationType::kMultisine, 1.0, 499.0, 1e-3, 10.0, 2.0));
  // Period: the shortest with df <= 1 Hz (1000 samples), repeated as often as 10 s allows.
  EXPECT_EQ(e.period_samples, 1000u);
  EXPECT_EQ(e.periods, 10u);
  ASSERT_EQ(e.samples.size(), 10000u);
  ASSERT_EQ(e.lines.size(), 499u);
  EXPECT_EQ(e.lines.front(), 1u);
  EXPECT_EQ(e.lines.back(), 499u);
  // tools/reference/excitation_reference.py: 1.47752007712716.
  EXPECT_NEAR(e.schroeder_crest_factor, 1.47752007712716, 1e-12);
  EXPECT_LE(e.crest_factor, e.schroeder_crest_factor);
  EXPECT_EQ(peak_of(e.samples), 2.0);
  // Every period the same sequence.
  for (std::size_t i = 1000; i < e.samples.size(); ++i) ASSERT_EQ(e.samples[i], e.samples[i - 1000]) << i;
}

TEST(MultisineDesign, SwappingLowersThePartBandCrestFactorAndKeepsTheSpectrumFlat) {
  ExcitationRequest r = design_request(ExcitationType::kMultisine, 2.0, 200.0, 5e-4, 6.0, 1.5);
  r.periods = 6;  // periods of 1 s: lines 1 Hz apart
  const Excitation e = design_excitation(r);
  EXPECT_EQ(e.period_samples, 2000u);
  EXPECT_EQ(e.periods, 6u);
  ASSERT_EQ(e.lines.size(), 199u);
  // tools/reference/excitation_reference.py: Schroeder's phases give 1.76444243302297.
  EXPECT_NEAR(e.schroeder_crest_factor, 1.76444243302297, 1e-12);
  // Van der Ouderaa et al. (1988) report crest factors near 1.4 for such flat multisines after
  // the swapping; require a clear gain over Schroeder.
  EXPECT_LT(e.crest_factor, 1.55);
  EXPECT_NEAR(peak_of(e.samples), 1.5, 0.0);
  const auto mags = design_line_magnitudes(e.samples, 2000, 2000);
  const double line = mags[e.lines.front()];
  for (std::size_t k = 0; k < mags.size(); ++k) {
    const bool excited = std::find(e.lines.begin(), e.lines.end(), k) != e.lines.end();
    if (excited) EXPECT_NEAR(mags[k], line, 1e-9 * line) << "line " << k;
    else EXPECT_LT(mags[k], 1e-9 * line) << "line " << k;
  }
}

TEST(MultisineDesign, LogarithmicSpacingAndExplicitPeriods) {
  ExcitationRequest r = design_request(ExcitationType::kMultisine, 1.0, 400.0, 1e-3, 20.0, 1.0);
  r.spacing = LineSpacing::kLogarithmic;
  r.lines_per_decade = 20;
  r.periods = 4;
  const Excitation e = design_excitation(r);
  EXPECT_EQ(e.period_samples, 5000u);  // 20 s / 4
  // Line spacing 0.2 Hz: lines 5 … 2000, about 20 per decade over 2.6 decades, distinct and rising.
  EXPECT_EQ(e.lines.front(), 5u);
  EXPECT_LE(e.lines.back(), 2000u);
  EXPECT_GE(e.lines.size(), 50u);
  EXPECT_LE(e.lines.size(), 60u);
  for (std::size_t j = 1; j < e.lines.size(); ++j) EXPECT_GT(e.lines[j], e.lines[j - 1]);
}

TEST(ChirpDesign, StartsAndEndsAtZeroWithTheSweepsWholeCycles) {
  ExcitationRequest r = design_request(ExcitationType::kChirp, 5.0, 400.0, 1e-4, 8.0, 0.5);
  r.periods = 2;
  const Excitation e = design_excitation(r);
  ASSERT_EQ(e.period_samples, 40000u);
  EXPECT_EQ(e.periods, 2u);
  EXPECT_EQ(e.samples.front(), 0.0);
  EXPECT_EQ(peak_of(e.samples), 0.5);
  EXPECT_NEAR(e.crest_factor, std::sqrt(2.0), 0.01);  // a sine's, up to the sweep's ends
  // Zero crossings count half cycles: tools/reference/excitation_reference.py gives 360.56 cycles,
  // rounded to 361 so the period closes.
  std::size_t crossings = 0;
  for (std::size_t i = 1; i < e.period_samples; ++i)
    if ((e.samples[i - 1] < 0.0) != (e.samples[i] < 0.0)) ++crossings;
  EXPECT_NEAR(static_cast<double>(crossings), 2.0 * 361.0, 1.0);
  // Closing on a whole cycle: the repeat continues the sine (next sample after the last ≈ 0).
  EXPECT_LT(std::abs(e.samples[e.period_samples]), 1e-9);
  EXPECT_LT(std::abs(e.samples[e.period_samples - 1]), 2.0 * std::numbers::pi * 400.0 * 1e-4 * 0.5 * 1.01);
  // Logarithmic: the mean frequency of 10 whole cycles (20 zero crossings) after half-way is
  // f_b (f_e/f_b)^{t/T} at their centre t (to (ln 80 · 0.2 s / 4 s)²/24 = 0.2 %), times the
  // closing scale 361 / 360.56.
  std::vector<std::size_t> crossings_at;
  for (std::size_t i = e.period_samples / 2; crossings_at.size() < 21; ++i)
    if ((e.samples[i - 1] < 0.0) != (e.samples[i] < 0.0)) crossings_at.push_back(i);
  const double span_s = static_cast<double>(crossings_at.back() - crossings_at.front()) * 1e-4;
  const double centre_s = 0.5 * static_cast<double>(crossings_at.back() + crossings_at.front()) * 1e-4;
  const double expected_hz = 5.0 * std::pow(80.0, centre_s / 4.0) * 361.0 / 360.563760041497;
  EXPECT_NEAR(10.0 / span_s, expected_hz, 0.005 * expected_hz);
  for (std::size_t i = 0; i < e.period_samples; ++i) ASSERT_EQ(e.samples[i], e.samples[i + e.period_samples]);
}

TEST(SineStepDesign, WholeCyclesPerWindowRisingFrequenciesContinuousSignal) {
  const Excitation e = design_excitation(design_request(ExcitationType::kSineSteps, 2.0, 200.0, 5e-4, 42.0, 1.0));
  ASSERT_EQ(e.steps.size(), 21u);  // 10 per decade over 2 decades, both ends
  EXPECT_EQ(peak_of(e.samples), 1.0);
  for (std::size_t j = 0; j < e.steps.size(); ++j) {
    const SineStep& s = e.steps[j];
    EXPECT_EQ(s.begin, j * 4000u);
    EXPECT_EQ(s.settle_samples, 1000u);
    EXPECT_EQ(s.measure_samples, 3000u);
    EXPECT_DOUBLE_EQ(s.freq_hz, static_cast<double>(s.cycles) / (3000 * 5e-4));
    const double wanted = 2.0 * std::pow(100.0, static_cast<double>(j) / 20.0);
    EXPECT_LE(std::abs(s.freq_hz - wanted), 0.5 / 1.5 + 1e-9) << j;  // rounded to the nearest line
    if (j > 0) {
      EXPECT_GT(s.freq_hz, e.steps[j - 1].freq_hz);
    }
    // Whole cycles: all the window's energy (less the mean) on its line `cycles`.
    const double line = design_line_magnitude(e.samples, s.begin + s.settle_samples, s.measure_samples, s.cycles);
    double energy = 0.0, mean = 0.0;
    for (std::size_t i = 0; i < s.measure_samples; ++i) mean += e.samples[s.begin + s.settle_samples + i];
    mean /= 3000.0;
    for (std::size_t i = 0; i < s.measure_samples; ++i)
      energy += std::pow(e.samples[s.begin + s.settle_samples + i] - mean, 2);
    EXPECT_NEAR(2.0 * line * line / 3000.0, energy, 1e-9 * energy) << j;
  }
  // The phase runs on: no jump larger than one sample's advance at the highest frequency.
  double largest = 0.0;
  for (std::size_t i = 1; i < e.samples.size(); ++i) largest = std::max(largest, std::abs(e.samples[i] - e.samples[i - 1]));
  EXPECT_LE(largest, 2.0 * std::numbers::pi * e.steps.back().freq_hz * 5e-4);
}

TEST(ExcitationDesign, RefusesWhatCannotBePlayedNamingTheField) {
  using test::field_of;
  const auto make = [](ExcitationType t, double f0, double f1, double ts, double d, double a) {
    return [=] { (void)design_excitation(design_request(t, f0, f1, ts, d, a)); };
  };
  EXPECT_EQ(field_of(make(ExcitationType::kMultisine, 1, 500, 1e-3, 10, 1)), "f_end_hz");  // at Nyquist
  EXPECT_EQ(field_of(make(ExcitationType::kChirp, 1, 600, 1e-3, 10, 1)), "f_end_hz");
  EXPECT_EQ(field_of(make(ExcitationType::kMultisine, 10, 5, 1e-3, 10, 1)), "f_begin_hz");
  EXPECT_EQ(field_of(make(ExcitationType::kMultisine, 1, 100, 1e-3, 10, 0)), "amplitude");
  EXPECT_EQ(field_of(make(ExcitationType::kMultisine, 1, 100, 0, 10, 1)), "ts");
  EXPECT_EQ(field_of(make(ExcitationType::kMultisine, 1, 100, 1e-3, 1.5, 1)), "duration_s");  // < 2 periods of 1 s
  EXPECT_EQ(field_of(make(ExcitationType::kChirp, 1, 100, 1e-3, 0.5, 1)), "duration_s");
  EXPECT_EQ(field_of(make(ExcitationType::kSineSteps, 1, 100, 1e-3, 10, 1)), "duration_s");  // 21 steps of 0.48 s
  EXPECT_EQ(field_of(make(ExcitationType::kMultisine, 1, 100, 1e-6, 200, 1)), "duration_s");  // 2e8 samples
  try {
    (void)design_excitation(design_request(ExcitationType::kMultisine, 1, 100, 1e-3, 1.5, 1));
  } catch (const core::InputError& e) {
    EXPECT_THAT(e.reason(), ::testing::HasSubstr("give at least 2 s"));
  }
  ExcitationRequest steps = design_request(ExcitationType::kSineSteps, 1, 100, 1e-3, 100, 1);
  steps.steps = 1;
  EXPECT_EQ(field_of([&] { (void)design_excitation(steps); }), "steps");
  steps.steps = 0;
  steps.settle_fraction = 1.0;
  EXPECT_EQ(field_of([&] { (void)design_excitation(steps); }), "settle_fraction");
  ExcitationRequest periods = design_request(ExcitationType::kMultisine, 1, 100, 1e-3, 10, 1);
  periods.periods = 1;
  EXPECT_EQ(field_of([&] { (void)design_excitation(periods); }), "periods");
  periods.periods = 20;  // periods of 0.5 s: lines 2 Hz apart, coarser than the range's 1 Hz
  EXPECT_EQ(field_of([&] { (void)design_excitation(periods); }), "periods");
  // Sine steps that cannot all lie in the range: 50 steps in 10 … 20 Hz with 1 s windows, and a
  // range narrower than one line of the window.
  ExcitationRequest crowded = design_request(ExcitationType::kSineSteps, 10, 20, 1e-3, 67, 1);
  crowded.steps = 50;
  EXPECT_EQ(field_of([&] { (void)design_excitation(crowded); }), "steps");
  EXPECT_EQ(field_of(make(ExcitationType::kSineSteps, 10.2, 10.6, 1e-3, 2.7, 1)), "duration_s");
  // A chirp of too few cycles would be moved by the whole-cycle closing (1.2 … 1.8 Hz in 1 s).
  EXPECT_EQ(field_of(make(ExcitationType::kChirp, 1.2, 1.8, 1e-3, 1, 1)), "duration_s");
  // Period lengths have no prime factor above 5 (the swapping runs hundreds of FFTs of them):
  // 0.3 Hz at 8 kHz needs 26 667 samples, the next such length is 27 000, so 17 periods fit in
  // 60 s, and the longest such length within 60 s / 17 = 28 235 samples is 28 125 = 3² · 5⁵.
  const Excitation odd = design_excitation(design_request(ExcitationType::kMultisine, 0.3, 100, 1.25e-4, 60, 1));
  EXPECT_EQ(odd.periods, 17u);
  EXPECT_EQ(odd.period_samples, 28125u);
}

}  // namespace
}  // namespace servotwin::frf
