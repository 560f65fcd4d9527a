// Reading a drive's recording of an excitation (issue 25 §4). The plant is a discrete resonance
// H(z) = (0.1 + 0.05 z⁻¹ + 0.02 z⁻²)/(1 − 1.6 z⁻¹ + 0.9 z⁻²) run sample by sample here, so the
// expected response is its closed form at z = e^{jωts}; the THD and the fundamental of a cubic
// nonlinearity come from sin³ = (3 sin − sin 3·)/4; the noise check from the distribution of a
// circular Gaussian error (|e|²/σ² is exponential with mean 1).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "field_of.hpp"
#include "servotwin/frf/excitation_recording.hpp"

namespace servotwin::frf {
namespace {

constexpr double kRecTs = 1e-3;

std::complex<double> recording_plant(double freq_hz) {
  const std::complex<double> z1 = std::polar(1.0, -2.0 * std::numbers::pi * freq_hz * kRecTs);
  return (0.1 + 0.05 * z1 + 0.02 * z1 * z1) / (1.0 - 1.6 * z1 + 0.9 * z1 * z1);
}

std::vector<double> recording_filter(const std::vector<double>& x) {
  std::vector<double> y(x.size());
  double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    y[n] = 0.1 * x[n] + 0.05 * x1 + 0.02 * x2 + 1.6 * y1 - 0.9 * y2;
    x2 = x1;
    x1 = x[n];
    y2 = y1;
    y1 = y[n];
  }
  return y;
}

Excitation recording_design(ExcitationType type, std::size_t periods, double duration) {
  ExcitationRequest r;
  r.type = type;
  // Sine steps: 21 steps of 2.19 s, 3.3 cycles of 2 Hz in the first window.
  r.f_begin_hz = type == ExcitationType::kSineSteps ? 2.0 : 1.0;
  r.f_end_hz = 200.0;
  r.ts = kRecTs;
  r.duration_s = duration;
  r.amplitude = 1.0;
  r.periods = periods;
  return design_excitation(r);
}

/// `lead` zeros, the excitation scaled by `gain`, `tail` zeros: what a drive records around a run.
std::vector<double> recording_of(const Excitation& e, std::size_t lead, std::size_t tail, double gain) {
  std::vector<double> x(lead, 0.0);
  for (double v : e.samples) x.push_back(gain * v);
  x.resize(x.size() + tail, 0.0);
  return x;
}

TEST(ExcitationAlignment, FindsAShiftedScaledInvertedOrLateRecording) {
  const Excitation e = recording_design(ExcitationType::kMultisine, 4, 4.0);
  std::vector<double> x = recording_of(e, 123, 77, -0.5);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-3);
  for (double& v : x) v += noise(rng);
  const Alignment a = align_excitation(x, e.samples);
  EXPECT_EQ(a.offset, 123);
  EXPECT_NEAR(a.gain, -0.5, 1e-3);
  EXPECT_GT(a.correlation, 0.99);
  EXPECT_EQ(a.overlap, e.samples.size());
  // The recording started 777 samples into the sequence.
  const std::vector<double> late(e.samples.begin() + 777, e.samples.end());
  EXPECT_EQ(align_excitation(late, e.samples).offset, -777);
  // A sequence of 1200 periods recorded whole: a shift by one period loses only 1/1200 of the
  // match and must not win the tie-break meant for partial recordings.
  ExcitationRequest many;
  many.f_begin_hz = 50.0;
  many.f_end_hz = 450.0;
  many.ts = kRecTs;
  many.duration_s = 24.0;
  many.amplitude = 1.0;
  const Excitation m = design_excitation(many);
  ASSERT_EQ(m.periods, 1200u);
  EXPECT_EQ(align_excitation(recording_of(m, 37, 100, 1.0), m.samples).offset, 37);
  // Not the excitation at all.
  std::vector<double> other(x.size());
  for (double& v : other) v = noise(rng);
  EXPECT_EQ(test::field_of([&] { (void)align_excitation(other, e.samples); }), "input");
}

TEST(ExcitationAlignment, DetectsThePeriodOfARepeatedSequence) {
  const Excitation e = recording_design(ExcitationType::kMultisine, 5, 5.0);
  std::vector<double> x(e.samples.begin() + 311, e.samples.end());  // any phase of the period
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (double& v : x) v += noise(rng);
  const PeriodDetection d = detect_period(x);
  EXPECT_EQ(d.period_samples, 1000u);
  EXPECT_GT(d.correlation, 0.99);
  std::vector<double> white(5000);
  for (double& v : white) v = noise(rng);
  EXPECT_EQ(detect_period(white).period_samples, 0u);
  // A slow sequence (lines 1 … 20 Hz of an 8000-sample period at 8 kHz): its autocorrelation falls
  // smoothly from lag 0, which is no period at the shortest lag.
  ExcitationRequest slow;
  slow.f_begin_hz = 1.0;
  slow.f_end_hz = 20.0;
  slow.ts = 1.0 / 8000.0;
  slow.duration_s = 3.0;
  slow.amplitude = 1.0;
  const Excitation s = design_excitation(slow);
  ASSERT_EQ(s.period_samples, 8000u);
  EXPECT_EQ(detect_period(s.samples).period_samples, 8000u);
}

TEST(RecordedEstimate, PeriodicMultisineAndChirpAreLeakageFree) {
  for (const auto type : {ExcitationType::kMultisine, ExcitationType::kChirp}) {
    const Excitation e = recording_design(type, 5, 5.0);
    const std::vector<double> x = recording_of(e, 300, 200, 1.0);
    const std::vector<double> y = recording_filter(x);
    const RecordedEstimate r = estimate_recorded(e, x, y);
    EXPECT_EQ(r.alignment.offset, 300);
    EXPECT_EQ(r.periods_used, 4u);  // the first is skipped as transient
    ASSERT_EQ(r.response.size(), e.lines.size());
    for (const auto& p : r.response.points) {
      const std::complex<double> h = recording_plant(p.freq_hz);
      // The transient of the first period has decayed by 0.949^1000 ≈ 1e-23: exact up to rounding.
      EXPECT_LT(std::abs(p.value - h), 1e-9 * std::abs(h)) << excitation_type_name(type) << " " << p.freq_hz;
    }
  }
}

TEST(RecordedEstimate, SingleChirpThroughH1) {
  const Excitation e = recording_design(ExcitationType::kChirp, 0, 10.0);  // ten cycles of 1 Hz
  const std::vector<double> x = recording_of(e, 500, 1000, 1.0);
  const std::vector<double> y = recording_filter(x);
  const RecordedEstimate r = estimate_recorded(e, x, y);
  EXPECT_EQ(r.alignment.offset, 500);
  ASSERT_GT(r.response.size(), 10u);
  // Noise-free H1: the bias is the part of each segment's response that leaks past its end (the
  // plant's impulse response decays as 0.949^n, about 20 samples, against 512-sample segments):
  // a few percent at most.
  for (const auto& p : r.response.points) {
    const std::complex<double> h = recording_plant(p.freq_hz);
    EXPECT_LT(std::abs(p.value - h), 0.05 * std::abs(h)) << p.freq_hz;
  }
}

TEST(RecordedEstimate, SineStepsAreExactAndTheirThdIsTheCubicsClosedForm) {
  const Excitation e = recording_design(ExcitationType::kSineSteps, 0, 46.0);
  const std::vector<double> x = recording_of(e, 250, 0, 0.8);
  const std::vector<double> y = recording_filter(x);
  const RecordedEstimate r = estimate_recorded(e, x, y);
  EXPECT_EQ(r.alignment.offset, 250);
  ASSERT_EQ(r.steps_used, e.steps.size());
  EXPECT_EQ(r.response.quality_kind, core::QualityKind::kThd);
  for (std::size_t j = 0; j < e.steps.size(); ++j) {
    const auto& p = r.response.points[j];
    EXPECT_EQ(p.freq_hz, e.steps[j].freq_hz);
    const std::complex<double> h = recording_plant(p.freq_hz);
    EXPECT_LT(std::abs(p.value - h), 1e-9 * std::abs(h)) << p.freq_hz;
    // The sine amplitude: 0.8 over the sampled peak's shortfall (the largest sample of the slow
    // steps misses the crest by at most (π f ts)²/2 ≈ 2e-5 at 2 Hz), the same in every step.
    EXPECT_NEAR(p.amplitude, r.response.points.front().amplitude, 1e-12);
    EXPECT_NEAR(p.amplitude, 0.8, 0.8 * 2e-5);
    EXPECT_LT(p.quality, 1e-9);  // a linear plant: no harmonics
  }
  // y = x + 0.1 x³ with x = A sin: fundamental (A + 0.075 A³), third harmonic 0.025 A³.
  std::vector<double> cubic(x.size());
  for (std::size_t n = 0; n < x.size(); ++n) cubic[n] = x[n] + 0.1 * x[n] * x[n] * x[n];
  const RecordedEstimate c = estimate_recorded(e, x, cubic);
  for (const auto& p : c.response.points) {
    const double a = p.amplitude;  // 0.8 up to the sampled peak's shortfall (checked above)
    EXPECT_NEAR(p.value.real(), 1.0 + 0.075 * a * a, 1e-9) << p.freq_hz;
    EXPECT_NEAR(p.value.imag(), 0.0, 1e-9);
    // Harmonics above the window's Nyquist line are not counted (the highest steps).
    if (3 * 2 * p.freq_hz < 0.5 / kRecTs) {
      EXPECT_NEAR(p.quality, 0.025 * a * a * a / (a + 0.075 * a * a * a), 1e-9) << p.freq_hz;
    }
  }
}

TEST(RecordedEstimate, SineStepStandardDeviationsMatchTheScatter) {
  const Excitation e = recording_design(ExcitationType::kSineSteps, 0, 46.0);
  const std::vector<double> x = recording_of(e, 100, 0, 1.0);
  const std::vector<double> clean = recording_filter(x);
  double sum = 0.0;
  std::size_t count = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.01);
    std::vector<double> y = clean;
    for (double& v : y) v += noise(rng);
    const RecordedEstimate r = estimate_recorded(e, x, y);
    for (const auto& p : r.response.points) {
      sum += std::norm(p.value - recording_plant(p.freq_hz)) / (p.std_dev * p.std_dev);
      ++count;
    }
  }
  // Mean of |e|²/σ² over 105 points: 1 for an honest σ, with a standard error of about 0.1.
  EXPECT_NEAR(sum / static_cast<double>(count), 1.0, 0.3);
}

TEST(RecordedEstimate, RefusesRecordingsTooShortToEstimate) {
  const Excitation e = recording_design(ExcitationType::kMultisine, 4, 4.0);
  // Two periods recorded, the first skipped: one left.
  const std::vector<double> x(e.samples.begin(), e.samples.begin() + 2000);
  EXPECT_EQ(test::field_of([&] { (void)estimate_recorded(e, x, recording_filter(x)); }), "skip_periods");
  const Excitation steps = recording_design(ExcitationType::kSineSteps, 0, 46.0);
  const std::vector<double> first(steps.samples.begin(), steps.samples.begin() + 3000);
  EXPECT_EQ(test::field_of([&] { (void)estimate_recorded(steps, first, recording_filter(first)); }), "output");
}

}  // namespace
}  // namespace servotwin::frf
