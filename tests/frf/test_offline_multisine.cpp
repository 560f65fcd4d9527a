// Per-period (multisine) estimator. Expected values: closed forms (the steady-state response of
// a multisine through a known continuous transfer function is again a multisine with the
// transfer function's gain and phase on each line), the statistics of white noise in an
// N-point DFT (E|X(k)|² = N·σ²), and the FdiTools measurements' published numbers
// (data/twomass-motor-bench-fditools/README.md).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/offline.hpp"

namespace {

using servotwin::core::InputError;
using namespace servotwin::frf;
using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;

/// A two-mass-like motor-side response: (s² + 2ζz ωz s + ωz²) / (s²·(s² + 2ζp ωp s + ωp²))·k.
cd two_mass(double f_hz) {
  const cd s(0.0, 2.0 * kPi * f_hz);
  const double wz = 2.0 * kPi * 53.0, wp = 2.0 * kPi * 76.0;
  return 500.0 * (s * s + 2.0 * 0.03 * wz * s + wz * wz) / (s * s * (s * s + 2.0 * 0.05 * wp * s + wp * wp));
}

cd resonance(double f_hz) {
  const cd s(0.0, 2.0 * kPi * f_hz);
  const double w0 = 2.0 * kPi * 100.0;
  return w0 * w0 / (s * s + 2.0 * 0.1 * w0 * s + w0 * w0);
}

struct Multisine {
  std::vector<double> x, y;
  std::vector<std::size_t> lines;
  std::vector<double> amplitude;
};

/// Odd lines 3, 5, ... up to `last`, random phases; y is the exact steady-state response.
template <typename Tf>
Multisine make_multisine(std::size_t period, std::size_t periods, double ts, std::size_t last, Tf tf, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * kPi);
  Multisine m;
  m.x.assign(period * periods, 0.0);
  m.y.assign(period * periods, 0.0);
  for (std::size_t k = 3; k <= last; k += 2) {
    const double a = 1.0 + 0.5 * std::sin(static_cast<double>(k));  // not flat: 0.5 ... 1.5
    const double phi = phase(rng);
    const double f = static_cast<double>(k) / (static_cast<double>(period) * ts);
    const cd g = tf(f);
    for (std::size_t n = 0; n < m.x.size(); ++n) {
      const double arg = 2.0 * kPi * static_cast<double>(k * (n % period)) / static_cast<double>(period) + phi;
      m.x[n] += a * std::cos(arg);
      m.y[n] += a * std::abs(g) * std::cos(arg + std::arg(g));
    }
    m.lines.push_back(k);
    m.amplitude.push_back(a);
  }
  return m;
}

TEST(Multisine, NoiseFreePeriodicDataGiveTheTransferFunctionExactly) {
  const std::size_t period = 1000, periods = 6;
  const double ts = 1.0 / 2500.0;
  Multisine m = make_multisine(period, periods, ts, 201, two_mass, 7);
  // Output drift (a position that creeps): removed by the drift line through the period means.
  for (std::size_t n = 0; n < m.y.size(); ++n) m.y[n] += -7.4 + 0.03 * static_cast<double>(n) * ts;
  MultisineOptions o;
  o.periods = periods;
  o.skip_periods = 1;
  const MultisineEstimate e = estimate_multisine(m.x, m.y, ts, o);
  EXPECT_EQ(e.lines, m.lines);  // detected from input power alone
  EXPECT_EQ(e.period_samples, period);
  EXPECT_EQ(e.periods_used, periods - 1);
  EXPECT_EQ(e.periods_skipped, 1u);
  EXPECT_EQ(e.samples_dropped, 0u);
  EXPECT_DOUBLE_EQ(e.df_hz, 2.5);
  EXPECT_DOUBLE_EQ(*e.response.duration_s, static_cast<double>(period * periods) * ts);
  ASSERT_EQ(e.response.size(), m.lines.size());
  for (std::size_t i = 0; i < e.lines.size(); ++i) {
    const auto& p = e.response.points[i];
    const cd truth = two_mass(p.freq_hz);
    EXPECT_DOUBLE_EQ(p.freq_hz, 2.5 * static_cast<double>(m.lines[i]));
    EXPECT_LT(std::abs(p.value - truth), 1e-10 * std::abs(truth)) << p.freq_hz;
    EXPECT_NEAR(p.amplitude, m.amplitude[i], 1e-10);
    EXPECT_LT(p.std_dev, 1e-10 * std::abs(truth));
    EXPECT_NEAR(p.quality, 1.0, 1e-12);
  }

  // Without drift removal the same data are visibly biased: the detrend is what makes them exact.
  o.detrend = Detrend::kNone;
  const MultisineEstimate raw = estimate_multisine(m.x, m.y, ts, o);
  double worst = 0.0;
  for (const auto& p : raw.response.points)
    worst = std::max(worst, std::abs(p.value - two_mass(p.freq_hz)) / std::abs(two_mass(p.freq_hz)));
  EXPECT_GT(worst, 1e-4);
}

TEST(Multisine, PeriodFromLengthOrCountAndTrailingSamplesDropped) {
  const double ts = 1e-3;
  Multisine m = make_multisine(200, 5, ts, 41, resonance, 3);
  m.x.insert(m.x.end(), {0.1, 0.2, 0.3});  // an incomplete period at the end
  m.y.insert(m.y.end(), {0.0, 0.0, 0.0});
  MultisineOptions by_length;
  by_length.period_samples = 200;
  const auto a = estimate_multisine(m.x, m.y, ts, by_length);
  EXPECT_EQ(a.periods_used, 5u);
  EXPECT_EQ(a.samples_dropped, 3u);
  MultisineOptions by_count;
  by_count.periods = 5;
  const auto b = estimate_multisine(m.x, m.y, ts, by_count);
  EXPECT_EQ(b.period_samples, 200u);
  ASSERT_EQ(a.response.size(), b.response.size());
  for (std::size_t i = 0; i < a.response.size(); ++i)
    EXPECT_LT(std::abs(a.response.points[i].value - resonance(a.response.points[i].freq_hz)), 1e-10);
  // Explicit lines and an explicit threshold select the same lines here.
  MultisineOptions explicit_lines = by_count;
  explicit_lines.excited_lines = {7, 3, 5, 7};
  EXPECT_EQ(estimate_multisine(m.x, m.y, ts, explicit_lines).lines, (std::vector<std::size_t>{3, 5, 7}));
  MultisineOptions threshold = by_count;
  threshold.excitation_threshold_db = -30.0;
  EXPECT_EQ(estimate_multisine(m.x, m.y, ts, threshold).lines, m.lines);
}

TEST(Multisine, NoiseVariancesAndFrfVarianceMatchTheInjectedNoise) {
  // 199 lines, P = 10 periods of N = 1000 samples, white noise σx on the input and σy on the
  // output. Each line's per-period DFT noise has variance N·σ² (complex); the estimator's sample
  // variances have 2(P−1) degrees of freedom, so their mean over 199 lines has a relative standard
  // deviation of 1/sqrt(199·9) ≈ 2.4 %: tolerance 10 %.
  const std::size_t period = 1000, periods = 10;
  const double ts = 1e-3, sigma_x = 0.3, sigma_y = 0.5;
  Multisine m = make_multisine(period, periods, ts, 399, resonance, 11);
  std::mt19937_64 rng(99);
  std::normal_distribution<double> gauss;
  for (auto& v : m.x) v += sigma_x * gauss(rng);
  for (auto& v : m.y) v += sigma_y * gauss(rng);
  MultisineOptions o;
  o.periods = periods;
  const auto e = estimate_multisine(m.x, m.y, ts, o);
  ASSERT_EQ(e.lines, m.lines);
  const double n = static_cast<double>(period), p = static_cast<double>(periods);
  double ratio_x = 0.0, ratio_y = 0.0, cross = 0.0, ratio_var = 0.0, ratio_err = 0.0;
  for (std::size_t i = 0; i < e.lines.size(); ++i) {
    const auto& pt = e.response.points[i];
    const cd g = resonance(pt.freq_hz);
    ratio_x += e.noise_var_x[i] / (n * sigma_x * sigma_x);
    ratio_y += e.noise_var_y[i] / (n * sigma_y * sigma_y);
    cross += std::abs(e.noise_cov_yx[i]) / (n * sigma_x * sigma_y);
    // True variance of Ĝ: N(σy² + |G|²σx²) / (P·|X̄|²), |X̄| = A·N/2.
    const double x_line = m.amplitude[i] * n / 2.0;
    const double var_true = n * (sigma_y * sigma_y + std::norm(g) * sigma_x * sigma_x) / (p * x_line * x_line);
    ratio_var += pt.std_dev * pt.std_dev / var_true;
    ratio_err += std::norm(pt.value - g) / var_true;
    EXPECT_NEAR(pt.snr, std::abs(pt.value) / pt.std_dev, 1e-12 * pt.snr);
    EXPECT_NEAR(pt.quality, std::norm(pt.value) / (std::norm(pt.value) + p * pt.std_dev * pt.std_dev), 1e-12);
    EXPECT_GT(pt.quality, 0.0);
    EXPECT_LT(pt.quality, 1.0);
  }
  const double lines = static_cast<double>(e.lines.size());
  EXPECT_NEAR(ratio_x / lines, 1.0, 0.10);
  EXPECT_NEAR(ratio_y / lines, 1.0, 0.10);
  EXPECT_LT(cross / lines, 0.5);  // |cov| of independent noises: E ≈ sqrt(π/4)/sqrt(P−1) ≈ 0.3
  EXPECT_NEAR(ratio_var / lines, 1.0, 0.10);
  // The actual errors scatter as the predicted variance says: mean of a χ²₂/2 over 199 lines,
  // relative standard deviation 7 %: tolerance 25 %.
  EXPECT_NEAR(ratio_err / lines, 1.0, 0.25);
}

TEST(Multisine, BadInputIsRejectedWithTheOptionNamed) {
  const Multisine m = make_multisine(100, 4, 1e-3, 21, resonance, 5);
  const auto field_of = [&](const MultisineOptions& o, const std::vector<double>& x) {
    try {
      estimate_multisine(x, m.y, 1e-3, o);
    } catch (const InputError& e) {
      return e.where().field;
    }
    return std::string("no error");
  };
  MultisineOptions o;
  EXPECT_EQ(field_of(o, m.x), "periods");  // neither period nor count
  o.periods = 4;
  o.skip_periods = 3;
  EXPECT_EQ(field_of(o, m.x), "skip-periods");  // 1 period left: no noise estimate
  o = {};
  o.periods = 200;
  EXPECT_EQ(field_of(o, m.x), "periods");  // 2-sample periods
  o = {};
  o.period_samples = 100;
  o.periods = 5;
  EXPECT_EQ(field_of(o, m.x), "periods");  // 500 samples needed, 400 given
  o = {};
  o.periods = 4;
  o.excited_lines = {0};
  EXPECT_EQ(field_of(o, m.x), "excited_lines");
  o.excited_lines = {51};
  EXPECT_EQ(field_of(o, m.x), "excited_lines");
  o.excited_lines = {4};  // not excited: no input power
  EXPECT_EQ(field_of(o, m.x), "excited_lines");
  o = {};
  o.periods = 4;
  o.excitation_threshold_db = 3.0;
  EXPECT_EQ(field_of(o, m.x), "excitation-threshold-db");
  // Broadband noise is no multisine: it does not repeat with the period --periods gives (issue 27
  // §3; before, it was refused later, for having no gap between excited and other lines).
  std::vector<double> noise(400);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss;
  for (auto& v : noise) v = gauss(rng);
  o = {};
  o.periods = 4;
  EXPECT_EQ(field_of(o, noise), "periods");
  EXPECT_EQ(field_of(o, std::vector<double>(400, 1.0)), "input");  // constant
}

// Issue 27 §3: --periods 7 on a record of 8 periods returned a few meaningless lines without a
// word. Consecutive "periods" of the wrong length do not correlate: refused, naming the period
// the input does repeat with (detect_period). A multiple of the true period is a valid layout.
TEST(Multisine, AWrongPeriodCountIsRefusedNamingTheRightOne) {
  const Multisine m = make_multisine(1000, 8, 1e-3, 201, two_mass, 3);
  MultisineOptions o;
  o.periods = 7;
  try {
    (void)estimate_multisine(m.x, m.y, 1e-3, o);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().field, "periods");
    EXPECT_THAT(e.what(), ::testing::HasSubstr("does not repeat every 1142 samples"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("it repeats every 1000 samples"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("8 periods in the record"));
  }
  o.periods = 4;  // two true periods each
  EXPECT_EQ(estimate_multisine(m.x, m.y, 1e-3, o).period_samples, 2000u);
  o.periods = 8;
  EXPECT_EQ(estimate_multisine(m.x, m.y, 1e-3, o).period_samples, 1000u);
}

// ---- the FdiTools two-mass motor bench (measured) -------------------------------------------

struct Recording {
  std::vector<double> iq_adx, theta_mx;
};

Recording read_fditools(const std::string& name) {
  const std::string path = std::string(SERVOTWIN_REPO_DATA_DIR) + "/twomass-motor-bench-fditools/" + name;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "missing " << path;
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "time_us,iq_refx,iq_adx,theta_mx,theta_my,omega_max,omega_may");
  Recording r;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(row, cell, ',')) v.push_back(std::stod(cell));
    r.iq_adx.push_back(v.at(2));
    r.theta_mx.push_back(v.at(3));
  }
  return r;
}

struct MotorSide {
  double antiresonance_hz = 0.0, resonance_hz = 0.0, rigid_level = 0.0, min_quality = 1.0;
};


MotorSide analyse(const servotwin::core::FrequencyResponse& r) {
  MotorSide m;
  double min_mag = 1e300, max_mag = 0.0, rigid = 0.0;
  int rigid_count = 0;
  for (const auto& p : r.points) {
    const double mag = std::abs(p.value);
    if (p.freq_hz > 40.0 && p.freq_hz < 65.0 && mag < min_mag) {
      min_mag = mag;
      m.antiresonance_hz = p.freq_hz;
    }
    if (p.freq_hz > 65.0 && p.freq_hz < 100.0 && mag > max_mag) {
      max_mag = mag;
      m.resonance_hz = p.freq_hz;
    }
    if (p.freq_hz >= 11.0 && p.freq_hz <= 20.0) {
      const double w = 2.0 * kPi * p.freq_hz;
      rigid += 1.0 / (mag * w * w);
      ++rigid_count;
    }
    if (p.freq_hz <= 100.0) m.min_quality = std::min(m.min_quality, p.quality);
  }
  m.rigid_level = rigid / rigid_count;
  return m;
}

TEST(FdiTools, SchroederMultisineTypeAShowsTheTwoMassDynamics) {
  // README: fs 2500 Hz, period 2500, 20 periods, first one dropped; lines 11 … 250 Hz; motor side
  // antiresonance ≈ 53 Hz, resonance ≈ 75–77 Hz, rigid level 1/(|G|ω²) ≈ 0.0099 over 11–20 Hz.
  const Recording r = read_fditools("MultisineTypeA.csv");
  ASSERT_EQ(r.iq_adx.size(), 50000u);
  MultisineOptions o;
  o.periods = 20;
  o.skip_periods = 1;
  const auto e = estimate_multisine(r.iq_adx, r.theta_mx, 1.0 / 2500.0, o);
  ASSERT_EQ(e.lines.size(), 240u);
  EXPECT_EQ(e.lines.front(), 11u);
  EXPECT_EQ(e.lines.back(), 250u);
  EXPECT_DOUBLE_EQ(e.df_hz, 1.0);
  const MotorSide m = analyse(e.response);
  EXPECT_NEAR(m.antiresonance_hz, 53.0, 1.0);
  EXPECT_GE(m.resonance_hz, 75.0);
  EXPECT_LE(m.resonance_hz, 77.0);
  EXPECT_NEAR(m.rigid_level, 0.0099, 0.0003);
  EXPECT_GT(m.min_quality, 0.9);
}

TEST(FdiTools, OddOddRandomPhaseMultisineTypeBAgrees) {
  // Odd-odd lines 13, 17, … 249 Hz (every 4th line; the others detect nonlinear distortion).
  const Recording r = read_fditools("MultisineTypeB.csv");
  MultisineOptions o;
  o.periods = 20;
  o.skip_periods = 1;
  const auto e = estimate_multisine(r.iq_adx, r.theta_mx, 1.0 / 2500.0, o);
  ASSERT_EQ(e.lines.size(), 60u);
  for (std::size_t i = 0; i < e.lines.size(); ++i) EXPECT_EQ(e.lines[i], 13u + 4u * i);
  const MotorSide m = analyse(e.response);
  EXPECT_NEAR(m.antiresonance_hz, 53.0, 2.0);  // 4 Hz line spacing: 49, 53, 57
  EXPECT_NEAR(m.resonance_hz, 77.0, 2.0);      // 73, 77, 81
  EXPECT_NEAR(m.rigid_level, 0.0099, 0.0005);
}

}  // namespace
