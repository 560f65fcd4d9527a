// The fit's rules for the points that remain poor (issue 25 §1): the outlier rule (FitOptions::
// reject_outliers) and the distortion-inflated weights of swept-sine points. Reference: the true
// plant the responses are sampled from (catalog E37 configuration 2), and the same fit without the
// rule, which the corrupted point must bias.
#include <gtest/gtest.h>

#include <cmath>

#include "fit_test_support.hpp"
#include "servotwin/fit/fit.hpp"

namespace servotwin::fit::test {
namespace {

double rel_error(double a, double b) { return std::abs(a - b) / std::abs(b); }

/// Configuration 2 sampled on 60 points, complex noise of relative size `noise` with its std (seeded).
core::FrequencyResponse noisy_bed(unsigned seed, double noise = 0.01) {
  core::FrequencyResponse r = sample(e37_plant(2), 1.0, 2000.0, 60);
  add_relative_noise(r, noise, seed, true);
  return r;
}

/// The point nearest `omega` [rad/s].
std::size_t nearest(const core::FrequencyResponse& r, double omega) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < r.points.size(); ++i)
    if (std::abs(kTwoPi * r.points[i].freq_hz - omega) < std::abs(kTwoPi * r.points[best].freq_hz - omega)) best = i;
  return best;
}

/// Between the antiresonance and the resonance, where a wrong value moves both.
std::size_t between_the_pair(const core::FrequencyResponse& r) {
  const PlantModel bed = e37_plant(2);  // named: a reference into a temporary would dangle
  const Mode& m = bed.modes[0];
  return nearest(r, std::sqrt(m.antiresonance.omega_rad_s * m.resonance.omega_rad_s));
}

FitOptions options_with_lag() {
  FitOptions o;
  o.output = OutputChoice::kVelocity;
  o.lag = true;
  return o;
}

TEST(FitRobust, AnOutlierIsLeftOutListedAndNoLongerBiasesTheModel) {
  const PlantModel truth = e37_plant(2);
  const double wz = truth.modes[0].antiresonance.omega_rad_s;
  for (unsigned seed : {3u, 4u, 5u}) {
    core::FrequencyResponse r = noisy_bed(seed);
    const std::size_t k = between_the_pair(r);
    r.points[k].value *= 1.3;  // a glitch of 30 %, its std left as measured (1 %)
    FitOptions off = options_with_lag();
    off.reject_outliers = false;
    const FitReport biased = fit_plant(r, {ModelRequest::Kind::kTwoMass, 1}, off);
    const FitReport robust = fit_plant(r, {ModelRequest::Kind::kTwoMass, 1}, options_with_lag());
    ASSERT_TRUE(robust.result.converged) << robust.result.message;
    ASSERT_EQ(robust.left_out.size(), 1u) << seed;
    EXPECT_NE(robust.left_out.front().find("outlier"), std::string::npos) << robust.left_out.front();
    const double e_robust = rel_error(robust.result.model.modes[0].antiresonance.omega_rad_s, wz);
    const double e_biased = rel_error(biased.result.model.modes[0].antiresonance.omega_rad_s, wz);
    // 1 % noise on 60 points: the antiresonance within 0.5 % (the target) once the glitch
    // is out, and closer than with it.
    EXPECT_LT(e_robust, 5e-3) << seed;
    EXPECT_LT(e_robust, e_biased) << seed;
  }
}

TEST(FitRobust, CleanDataLoseNoPoint) {
  // Over 20 seeds of Gaussian noise no point crosses 4.5 robust sigma (Rayleigh tail 4e-5 per point,
  // 1200 points: P(any) ≈ 5 %, and the seeds below are fixed).
  std::size_t rejected = 0;
  for (unsigned seed = 100; seed < 120; ++seed)
    rejected += fit_plant(noisy_bed(seed), {ModelRequest::Kind::kTwoMass, 1}, options_with_lag()).left_out.size();
  EXPECT_LE(rejected, 1u);
}

TEST(FitRobust, DistortedPointsWeighLess) {
  // A swept-sine response whose point between the antiresonance and the resonance is off by 15 % and carries THD
  // 0.4 (a friction-bound point): weighted by sqrt(σ² + (THD |P|)²/2) it pulls the fit less than
  // the same point with THD 0.
  const PlantModel truth = e37_plant(2);
  core::FrequencyResponse r = noisy_bed(7, 1e-3);  // 0.1 %: the glitch, not the noise, pulls the fit
  r.quality_kind = core::QualityKind::kThd;
  for (auto& p : r.points) p.quality = 0.0;
  const std::size_t k = between_the_pair(r);
  r.points[k].value *= 1.15;
  FitOptions o = options_with_lag();
  o.reject_outliers = false;
  // How far the fitted model moves at that frequency from the fit of the same data without the
  // glitch (the clean fit's own error there is not the glitch's doing).
  const double w = kTwoPi * r.points[k].freq_hz;
  const auto at_w = [&] { return fit_plant(r, {ModelRequest::Kind::kTwoMass, 1}, o).result.model.response(w); };
  r.points[k].value /= 1.15;
  const std::complex<double> clean = at_w();
  r.points[k].value *= 1.15;
  const double plain = std::abs(at_w() / clean - 1.0);
  r.points[k].quality = 0.4;
  const double weighted = std::abs(at_w() / clean - 1.0);
  // The weight drops by sqrt(1e-6 + 0.08)/1e-3 ≈ 280: the pull by well over ten.
  EXPECT_GT(plain, 1e-3);
  EXPECT_LT(weighted, 0.1 * plain) << "with THD " << weighted << ", without " << plain;
}

}  // namespace
}  // namespace servotwin::fit::test
