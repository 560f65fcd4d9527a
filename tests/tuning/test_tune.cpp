// The one-call tuner. References: E26's printed gains (ω* = 0.30, catalog misprint 3), the
// de-normalization rules of catalog §0, a brute-force ω* scan for the automatic choice, E-PID's
// Kd = (r² − 1)/(r̄² − 1) − 1 (C7.5), and the spec itself (every returned design is re-checked).
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/tuning/tune.hpp"

namespace servotwin::tuning {
namespace {

using test::two_mass_model;

TEST(Tune, GivenOmegaStarReproducesE26AndDenormalizes) {
  const double wz = 2.0 * std::numbers::pi * 12.0, im = 2.5e-3;
  TuneOptions o;
  o.zeta_star = 1.0;
  o.omega_star = 0.30;
  const TuneResult r = tune(two_mass_model(3.0, 0.01, wz, im), o);
  const Controller& c = r.controller;
  EXPECT_NEAR(c.normalized.kp, 4.634937, 1e-6);  // E26 [R]
  EXPECT_NEAR(c.normalized.ki, 0.640260, 1e-6);
  EXPECT_NEAR(c.physical.kp, 4.634937 * im * wz, 1e-6 * im * wz);  // catalog §0: Kp = Kp_n Im ωz
  EXPECT_NEAR(c.physical.ki, 0.640260 * im * wz * wz, 1e-6 * im * wz * wz);
  EXPECT_EQ(c.design.omega_star_source, "given");
  EXPECT_TRUE(c.predicted.closed_loop_stable);
  EXPECT_NEAR(c.plant.omega_z, wz, 1e-9 * wz);
  EXPECT_NEAR(c.plant.r, 3.0, 1e-9);
}

TEST(Tune, DesignDoesNotDependOnUnits) {
  // The same axis in m and in mm (gain ×1000): normalized gains identical, physical ones /1000.
  const fit::PlantModel m = two_mass_model(2.4, 0.02, 150.0, 0.01);
  fit::PlantModel mm = m;
  mm.gain *= 1000.0;
  const TuneResult a = tune(m, {}), b = tune(mm, {});
  EXPECT_NEAR(a.controller.design.omega_star, b.controller.design.omega_star, 1e-12);
  EXPECT_NEAR(a.controller.normalized.kp, b.controller.normalized.kp, 1e-9 * a.controller.normalized.kp);
  EXPECT_NEAR(a.controller.physical.kp, 1000.0 * b.controller.physical.kp, 1e-9 * a.controller.physical.kp);
}

/// Brute force: bandwidth and peaks of the PI placed at ω*, with the HF dynamics.
struct Evaluated {
  bool feasible = false;
  double bandwidth = 0.0;
};
Evaluated evaluate(const NormalizedPlant& plant, double omega_star, const TuneOptions& o) {
  PidGains g;
  const PiGains pi = pi_pole_placement(plant.motor(false), omega_star, o.zeta_star).gains;
  g.kp = pi.kp;
  g.ki = pi.ki;
  const VelocityLoop loop(plant, g);
  if (!loop.stable()) return {};
  std::vector<double> grid = core::log_space(1e-3, 1e3, 4000);
  grid.push_back(1.0);  // the antiresonance and resonance exactly, so their peaks are not stepped over
  grid.push_back(plant.r);
  std::sort(grid.begin(), grid.end());
  const double s = core::peak_on_grid([&](double w) { return loop.sensitivity(w); }, grid).value;
  const double t = core::peak_on_grid([&](double w) { return loop.load_tracking(w); }, grid).value;
  std::vector<double> bw{0.0};
  bw.insert(bw.end(), grid.begin(), grid.end());
  return {s <= o.ms && t <= o.mt, core::bandwidth([&](double w) { return loop.load_tracking(w); }, bw).value_or(0.0)};
}

TEST(Tune, AutomaticOmegaStarIsTheBestFeasibleOnAFineScan) {
  for (double r : {1.6, 2.0, 3.0, 5.0}) {
    TuneOptions o;
    o.hf.delay_s = 0.02 / (2.0 * std::numbers::pi * 20.0);  // 0.02 rad of phase at ωz
    const TuneResult res = tune(two_mass_model(r, 0.02, 2.0 * std::numbers::pi * 20.0, 0.01), o);
    const Controller& c = res.controller;
    EXPECT_LE(c.predicted.peak_s, o.ms * (1.0 + 1e-3)) << r;
    EXPECT_LE(c.predicted.peak_tl, o.mt * (1.0 + 1e-3)) << r;
    double best = 0.0;
    for (double w : core::log_space(0.02 * res.range.omega_max, res.range.omega_max * (1.0 - 1e-9), 150)) {
      const Evaluated e = evaluate(res.plant, w, o);
      if (e.feasible) best = std::max(best, e.bandwidth);
    }
    ASSERT_GT(best, 0.0) << r;
    EXPECT_GE(c.predicted.bandwidth_load, 0.99 * best) << r;
  }
}

TEST(Tune, PidUsesTheVirtualInertia) {
  // E-PID: r = 4, r̄ = 2 ⇒ Kd = (16 − 1)/(4 − 1) − 1 = 4 (normalized, C7.5).
  TuneOptions o;
  o.structure = Structure::kPid;
  o.zeta_star = test::kSqrtHalf;
  o.omega_star = 0.5;
  const TuneResult r = tune(two_mass_model(4.0, 0.01, 100.0, 0.02), o);
  EXPECT_NEAR(r.controller.normalized.kd, 4.0, 1e-12);
  EXPECT_NEAR(r.controller.physical.kd, 4.0 * 0.02, 1e-12);  // Kd = Kd_n Im
  EXPECT_GT(r.controller.normalized.tau, 0.0);
  EXPECT_TRUE(r.controller.predicted.closed_loop_stable);
}

TEST(Tune, DiscretizesAtTheDrivePeriod) {
  TuneOptions o;
  o.ts = 1.0 / 4000.0;
  const TuneResult r = tune(two_mass_model(2.0, 0.02, 2.0 * std::numbers::pi * 30.0, 0.01), o);
  ASSERT_TRUE(r.controller.discrete.has_value());
  EXPECT_DOUBLE_EQ(r.controller.discrete->ts, 1.0 / 4000.0);
  ASSERT_TRUE(r.controller.prewarp_rad_s.has_value());
  EXPECT_LT(*r.controller.prewarp_rad_s, std::numbers::pi * 4000.0);
}

TEST(Tune, UncertaintyWeightGivesRobustPerformance) {
  TuneOptions o;
  const double wz = 2.0 * std::numbers::pi * 20.0;
  o.w2 = core::TransferFunction(core::Polynomial{2.6 / wz, 0.0}, core::Polynomial{1.0 / wz, 15.0});  // E27's W2 at ωz
  const TuneResult r = tune(two_mass_model(3.0, 0.01, wz, 0.01), o);
  ASSERT_TRUE(r.controller.robustness.rp.has_value());
  EXPECT_LT(*r.controller.robustness.rp, 1.0);
  EXPECT_LT(*r.controller.robustness.rs, 1.0);
  EXPECT_LE(*r.controller.robustness.np, *r.controller.robustness.rp);
}

TEST(Tune, PositionLoopIsTheLargestGainWithoutOvershoot) {
  // Reference: φl/φ* = Kpp Tvl/(s + Kpp Tvn) composed here from the velocity loop on a dense grid;
  // the chosen Kpp keeps its peak at 1 and 2 % more gain exceeds it (C7.10's J1 constraint).
  TuneOptions o;
  o.structure = Structure::kPiP;
  o.zeta_star = 1.0;
  o.omega_star = 0.30;
  const double wz = 2.0 * std::numbers::pi * 15.0;
  const TuneResult r = tune(two_mass_model(3.0, 0.01, wz, 0.01), o);
  ASSERT_TRUE(r.controller.kpp_normalized && r.controller.position);
  const double kpp = *r.controller.kpp_normalized;
  EXPECT_NEAR(*r.controller.kpp_physical, kpp * wz, 1e-12 * kpp * wz);  // Kpp = Kpp_n ωz (catalog §0)
  const VelocityLoop loop(r.plant, r.controller.normalized);
  const auto peak = [&](double k) {
    double m = 0.0;
    for (double w : core::log_space(1e-3, 1e2, 40000)) {
      const std::complex<double> s(0.0, w);
      m = std::max(m, std::abs(k * loop.load_tracking(w) / (s + k * loop.motor_tracking(w))));
    }
    return m;
  };
  EXPECT_LE(peak(kpp), 1.0 + 1e-6);
  EXPECT_GT(peak(1.02 * kpp), 1.0);
  EXPECT_GT(r.controller.position->bandwidth_load, 0.0);
  EXPECT_NEAR(r.controller.position->peak_load_tracking, peak(kpp), 1e-4);
}

TEST(Tune, PositionLoopOnAPlantWithAHigherMode) {
  // The position loop uses the first mode's two-mass realization and says so; the velocity-loop
  // indices keep the higher mode (its load side is then undefined: NaN).
  fit::PlantModel m = two_mass_model(2.5, 0.02, 2.0 * std::numbers::pi * 8.0, 0.01);
  m.modes.push_back({{2.0 * std::numbers::pi * 60.0, 0.02}, {2.0 * std::numbers::pi * 85.0, 0.03}});
  TuneOptions o;
  o.structure = Structure::kPiP;
  const TuneResult r = tune(m, o);
  ASSERT_TRUE(r.controller.kpp_normalized.has_value());
  EXPECT_GT(*r.controller.kpp_normalized, 0.0);
  EXPECT_TRUE(std::isnan(r.controller.predicted.bandwidth_load));
  const auto& notes = r.controller.notes;
  EXPECT_TRUE(std::any_of(notes.begin(), notes.end(), [](const std::string& n) { return n.find("first mode") != std::string::npos; }));
}

TEST(Tune, BadRequestsAreExplained) {
  const auto message = [](const fit::PlantModel& m, const TuneOptions& o) {
    try {
      (void)tune(m, o);
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(two_mass_model(1.2, 0.02, 100.0, 0.01), {}).find("passive"), std::string::npos);
  TuneOptions outside;
  outside.omega_star = 5.0;
  EXPECT_NE(message(two_mass_model(3.0, 0.01, 100.0, 0.01), outside).find("admissible range"), std::string::npos);
  TuneOptions tight;  // a delay of 0.3/ωz costs phase that no PI can hide within ‖S‖ <= 1.05
  tight.ms = 1.05;
  tight.hf.delay_s = 0.3 / 100.0;
  const std::string m = message(two_mass_model(3.0, 0.01, 100.0, 0.01), tight);
  EXPECT_NE(m.find("best achievable"), std::string::npos) << m;
  // Issue 25 §7: the message names the nearest limits that work, and they do.
  const std::size_t at = m.find("--ms ", m.find("nearest limits that accept it"));
  ASSERT_NE(at, std::string::npos) << m;
  std::istringstream limits(m.substr(at));
  std::string flag_ms, flag_mt;
  TuneOptions relaxed = tight;
  limits >> flag_ms >> relaxed.ms >> flag_mt >> relaxed.mt;
  EXPECT_EQ(flag_mt, "--mt");
  EXPECT_GT(relaxed.ms, tight.ms);
  EXPECT_EQ(message(two_mass_model(3.0, 0.01, 100.0, 0.01), relaxed), "no error");
  TuneOptions hinf_tight;
  hinf_tight.structure = Structure::kHinf;
  hinf_tight.ms = 1.05;
  const std::string h = message(two_mass_model(3.0, 0.01, 100.0, 0.01), hinf_tight);
  const std::size_t hinf_at = h.find("--ms ", h.find("nearest limits that accept it"));
  ASSERT_NE(hinf_at, std::string::npos) << h;
  std::istringstream hinf_limits(h.substr(hinf_at));
  TuneOptions hinf_relaxed = hinf_tight;
  hinf_limits >> flag_ms >> hinf_relaxed.ms >> flag_mt >> hinf_relaxed.mt;
  EXPECT_EQ(message(two_mass_model(3.0, 0.01, 100.0, 0.01), hinf_relaxed), "no error");
  TuneOptions bad_zeta;
  bad_zeta.zeta_star = -1.0;
  EXPECT_NE(message(two_mass_model(3.0, 0.01, 100.0, 0.01), bad_zeta).find("--zeta-star"), std::string::npos);
}

}  // namespace
}  // namespace servotwin::tuning
