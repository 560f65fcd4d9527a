// Closed-loop estimates (issue 25 §3). The loop is simulated here sample by sample: a strictly
// proper resonance P(z) = (0.05 z⁻¹ + 0.02 z⁻²)/(1 − 1.6 z⁻¹ + 0.9 z⁻²) under a proportional
// controller u = 2 (r − y_m), y_m = y + v with white measurement noise v that feeds back. The
// expected response is P's closed form at z = e^{jωts}; the loop is stable (characteristic
// polynomial 1 − 1.5 z⁻¹ + 0.94 z⁻², |z| = 0.97) and S = 1/(1 + 2P) is computed in closed form
// to select the lines where the sensitivity is not tiny.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "field_of.hpp"
#include "servotwin/frf/excitation_design.hpp"
#include "servotwin/frf/offline.hpp"

namespace servotwin::frf {
namespace {

constexpr double kLoopTs = 1e-3;
constexpr double kLoopGain = 2.0;

std::complex<double> loop_plant(double freq_hz) {
  const std::complex<double> z1 = std::polar(1.0, -2.0 * std::numbers::pi * freq_hz * kLoopTs);
  return (0.05 * z1 + 0.02 * z1 * z1) / (1.0 - 1.6 * z1 + 0.9 * z1 * z1);
}

struct LoopRecord {
  std::vector<double> r, u, y;  // y is the measured output (with the noise the controller sees)
};

LoopRecord run_loop(const std::vector<double>& r, double noise_std, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_std);
  LoopRecord rec{r, std::vector<double>(r.size()), std::vector<double>(r.size())};
  double u1 = 0, u2 = 0, y1 = 0, y2 = 0;
  for (std::size_t n = 0; n < r.size(); ++n) {
    const double y = 0.05 * u1 + 0.02 * u2 + 1.6 * y1 - 0.9 * y2;  // strictly proper: no algebraic loop
    rec.y[n] = y + noise(rng);
    rec.u[n] = kLoopGain * (r[n] - rec.y[n]);
    u2 = u1;
    u1 = rec.u[n];
    y2 = y1;
    y1 = y;
  }
  return rec;
}

double db_error(std::complex<double> estimate, std::complex<double> truth) {
  return std::abs(20.0 * std::log10(std::abs(estimate) / std::abs(truth)));
}

double deg_error(std::complex<double> estimate, std::complex<double> truth) {
  return std::abs(std::arg(estimate / truth)) * 180.0 / std::numbers::pi;
}

TEST(ClosedLoopEstimate, IndirectH1IsUnbiasedWhereTheOpenLoopEstimateIsNot) {
  std::mt19937 rng(11);
  std::normal_distribution<double> white(0.0, 1.0);
  std::vector<double> r(1 << 20);
  for (double& v : r) v = white(rng);
  const double noise = 0.3;
  const LoopRecord rec = run_loop(r, noise, 12);
  WelchOptions o;
  o.segment_length = 1024;
  o.max_freq_hz = 450.0;
  const core::FrequencyResponse closed = estimate_closed_loop_h1(rec.r, rec.u, rec.y, kLoopTs, o);
  const core::FrequencyResponse naive = estimate_h1(rec.u, rec.y, kLoopTs, o);
  ASSERT_EQ(closed.size(), naive.size());
  double worst_db = 0.0, worst_deg = 0.0, naive_worst_db = 0.0, naive_model_db = 0.0, normalized = 0.0;
  std::size_t used = 0;
  for (std::size_t i = 0; i < closed.size(); ++i) {
    const double f = closed.points[i].freq_hz;
    const std::complex<double> p = loop_plant(f);
    if (std::abs(1.0 / (1.0 + kLoopGain * p)) < 0.1) continue;  // the loop hides the plant there
    if (kLoopGain * std::abs(p) * 1.0 < noise) continue;            // the noise hides it there
    ++used;
    worst_db = std::max(worst_db, db_error(closed.points[i].value, p));
    worst_deg = std::max(worst_deg, deg_error(closed.points[i].value, p));
    naive_worst_db = std::max(naive_worst_db, db_error(naive.points[i].value, p));
    // What the open-loop H1 converges to with white r and v: u = CS(r − v), y_m = PCS r + S v, so
    // S_uy/S_uu = (P σ_r² − σ_v²/C) / (σ_r² + σ_v²).
    const std::complex<double> limit = (p * 1.0 - noise * noise / kLoopGain) / (1.0 + noise * noise);
    naive_model_db = std::max(naive_model_db, db_error(naive.points[i].value, limit));
    normalized += std::norm(closed.points[i].value - p) / std::pow(closed.points[i].std_dev, 2);
  }
  // Lines where |S| >= 0.1 and the reference's part of y exceeds the noise's (|CP| σ_r >= σ_v).
  EXPECT_GT(used, 100u);
  // Issue 25 §3: within 1 dB / 5° wherever |S| is not tiny.
  EXPECT_LT(worst_db, 1.0);
  EXPECT_LT(worst_deg, 5.0);
  // The open-loop H1 on the same data is biased by σ_v²(1 + 1/(CP))/(σ_r² + σ_v²), 0.36 at
  // |CP| = 0.3 (2.6 … 3.8 dB), and lands on that limit.
  EXPECT_GT(naive_worst_db, 2.0);
  EXPECT_LT(naive_model_db, 0.5);
  // σ honest: |e|²/σ² averages to 1 (the Hann-overlapped lines are not independent: 0.6 … 1.6).
  EXPECT_GT(normalized / static_cast<double>(used), 0.6);
  EXPECT_LT(normalized / static_cast<double>(used), 1.6);
}

TEST(ClosedLoopEstimate, PeriodicReferenceAveragesBothSignals) {
  ExcitationRequest q;
  q.f_begin_hz = 2.0;
  q.f_end_hz = 400.0;
  q.ts = kLoopTs;
  q.duration_s = 100.0;
  q.amplitude = 1.0;
  q.periods = 100;
  const Excitation e = design_excitation(q);
  const double noise = 0.05;
  const LoopRecord rec = run_loop(e.samples, noise, 21);
  const double reference_rms = e.amplitude / e.crest_factor;
  MultisineOptions o;
  o.period_samples = e.period_samples;
  o.skip_periods = 1;
  const MultisineEstimate m = estimate_closed_loop_multisine(rec.r, rec.u, rec.y, kLoopTs, o);
  EXPECT_EQ(m.lines, e.lines);  // detected on the reference
  // P̂ − P ≈ V̄/(C R̄) per line (U = CS(R − V), Y = PCS R + S V and (1 + PC) S = 1), so the
  // relative standard deviation is σ_v √(2K) / (|CP| σ_r √(N·P)) with K lines, N samples per
  // period and P averaged periods.
  const double lines = static_cast<double>(e.lines.size());
  const double averaged = static_cast<double>(e.period_samples * (e.periods - 1));
  double normalized = 0.0;
  std::size_t used = 0, precise = 0;
  for (const auto& p : m.response.points) {
    const std::complex<double> truth = loop_plant(p.freq_hz);
    if (std::abs(1.0 / (1.0 + kLoopGain * truth)) < 0.1) continue;
    ++used;
    normalized += std::norm(p.value - truth) / (p.std_dev * p.std_dev);
    const double relative_std =
        noise * std::sqrt(2.0 * lines) / (kLoopGain * std::abs(truth) * reference_rms * std::sqrt(averaged));
    if (relative_std > 0.015) continue;  // 1 dB and 5° are then more than 5.8 σ
    ++precise;
    EXPECT_LT(db_error(p.value, truth), 1.0) << p.freq_hz;
    EXPECT_LT(deg_error(p.value, truth), 5.0) << p.freq_hz;
  }
  EXPECT_GT(used, 300u);
  EXPECT_GT(precise, 50u);
  // σ honest over every line where |S| >= 0.1 (mean |e|²/σ² = 1; 0.8 … 1.25 for ~350 lines).
  EXPECT_GT(normalized / static_cast<double>(used), 0.8);
  EXPECT_LT(normalized / static_cast<double>(used), 1.25);
}

TEST(ClosedLoopEstimate, RefusesSignalsOfDifferentLengths) {
  std::vector<double> a(1000, 1.0), b(999, 1.0);
  EXPECT_EQ(test::field_of([&] { (void)estimate_closed_loop_h1(a, a, b, kLoopTs); }), "reference");
}

}  // namespace
}  // namespace servotwin::frf
