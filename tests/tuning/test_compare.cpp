// The structure comparison of C7.15 (tuning/compare.hpp). References: the dissertation's printed
// conclusions (catalog C7.15 [P]): r < 1.3 nothing helps; for r > 2.3 full order wins, the PID
// tuned to r̄ = 2 gains up to +45 % and LQG/H∞ up to +100 % load bandwidth over the PI, H∞ rejects
// load disturbances best (C7.14: "H∞ rejects disturbances faster" than the LQG); each entry
// is the tuner's own design (the same numbers as `servotwin tune --structure ...`).
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/tuning/compare.hpp"

namespace servotwin::tuning {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace compare_test {

fit::PlantModel frictionless(double r) {
  fit::PlantModel m;
  m.rigid = fit::RigidKind::kIntegrator;
  m.gain = 1.0;
  m.modes = {{{1.0, 0.01}, {r, r * 0.01}}};
  return m;
}

const StructureComparison& entry(const std::vector<StructureComparison>& c, Structure s) {
  for (const StructureComparison& e : c)
    if (e.structure == s) return e;
  throw std::logic_error("structure missing");
}

double load_bandwidth(const StructureComparison& e) { return e.result->controller.predicted.bandwidth_load; }

TEST(CompareStructures, EachEntryIsTheTunersDesign) {
  const std::vector<StructureComparison> c = compare_structures(frictionless(3.0), {});
  ASSERT_EQ(c.size(), 4U);
  for (const StructureComparison& e : c) {
    ASSERT_TRUE(e.result.has_value()) << to_string(e.structure) << ": " << e.failure;
    TuneOptions o;
    o.structure = e.structure;
    o.allow_negative_kd = true;
    EXPECT_EQ(tune(frictionless(3.0), o).controller.predicted.bandwidth_load, load_bandwidth(e));
    EXPECT_LE(e.result->controller.predicted.peak_s, 1.5 * (1.0 + 1e-3));
    EXPECT_LE(e.result->controller.predicted.peak_tl, 1.5 * (1.0 + 1e-3));
  }
  EXPECT_DOUBLE_EQ(relative_to_pi(c, &LoopIndices::bandwidth_load, load_bandwidth(c.front())), 1.0);
}

TEST(CompareStructures, NotesADesignWhoseLoadStepIsFarWorseThanThePis) {
  std::vector<StructureComparison> c = compare_structures(frictionless(3.0), {});
  EXPECT_TRUE(comparison_notes(c).empty());  // every design here rejects a load step at least as well
  // The same comparison with the LQG's ITAE at 3.5 and at 2.9 times the PI's: noted only above 3.
  const double pi_itae = entry(c, Structure::kPi).result->controller.predicted.itae_load_step;
  auto& lqg = *std::find_if(c.begin(), c.end(), [](const StructureComparison& e) { return e.structure == Structure::kLqg; });
  lqg.result->controller.predicted.itae_load_step = 3.5 * pi_itae;
  const std::vector<std::string> notes = comparison_notes(c);
  ASSERT_EQ(notes.size(), 1U);
  EXPECT_EQ(notes.front().rfind("lqg: its load-step ITAE is 3.5 times the PI's", 0), 0U) << notes.front();
  lqg.result->controller.predicted.itae_load_step = 2.9 * pi_itae;
  EXPECT_TRUE(comparison_notes(c).empty());
}

TEST(CompareStructures, FullOrderWinsAboveRatio23AsThePrintedConclusionsSay) {
  for (const double r : {3.0, 4.0, 5.0, 8.0}) {
    SCOPED_TRACE(r);
    const std::vector<StructureComparison> c = compare_structures(frictionless(r), {});
    const double pi = load_bandwidth(entry(c, Structure::kPi));
    const double pid = load_bandwidth(entry(c, Structure::kPid));
    const double lqg = load_bandwidth(entry(c, Structure::kLqg));
    EXPECT_GT(pid, pi);                    // the PID gains ...
    EXPECT_LT(pid, 1.45 * pi);             // ... up to +45 %
    EXPECT_GT(lqg, 1.4 * pi);              // full order: well above the PI ...
    EXPECT_LT(lqg, 2.0 * pi);              // ... up to +100 %
    EXPECT_GT(lqg, pid);
    // H∞ (C7.14's weights and search): also up to +100 % (measured +48 % at r = 3, +73..83 % at
    // r = 4..8), and "H∞ rejects disturbances faster" than the LQG: the smallest load-disturbance
    // peak ‖ωl/Tl‖∞ of all four (C7.14, C7.15).
    const StructureComparison& hinf = entry(c, Structure::kHinf);
    ASSERT_TRUE(hinf.result.has_value()) << hinf.failure;
    EXPECT_GT(load_bandwidth(hinf), 1.4 * pi);
    EXPECT_LT(load_bandwidth(hinf), 2.0 * pi);
    const auto j2 = [&](Structure s) { return entry(c, s).result->controller.predicted.peak_load_disturbance; };
    for (const Structure other : {Structure::kPi, Structure::kPid, Structure::kLqg}) EXPECT_LT(j2(Structure::kHinf), j2(other));
  }
}

TEST(CompareStructures, AStructureThatCannotMeetTheSpecIsRecorded) {
  // r = 1.5 < r̄ = 2: the PID needs a negative Kd and no ω* keeps ‖S‖∞ <= 1.5; PI and LQG design.
  const std::vector<StructureComparison> c = compare_structures(frictionless(1.5), {});
  EXPECT_FALSE(entry(c, Structure::kPid).result.has_value());
  EXPECT_NE(entry(c, Structure::kPid).failure.find("no omega* meets"), std::string::npos);
  EXPECT_TRUE(entry(c, Structure::kPi).result.has_value());
  EXPECT_TRUE(entry(c, Structure::kLqg).result.has_value());
  EXPECT_TRUE(std::isnan(relative_to_pi({entry(c, Structure::kPid)}, &LoopIndices::bandwidth_load, 1.0)));
}

TEST(CompareStructures, WhatFailsEveryStructureIsTheCallersError) {
  // r = 1.2: nothing helps (C7.15); the tuner's message, not an empty comparison.
  test::expect_input_error([] { (void)compare_structures(frictionless(1.2), {}); }, "plant", "passive methods");
  TuneOptions o;
  o.ms = 0.5;
  test::expect_input_error([&] { (void)compare_structures(frictionless(3.0), o); }, "--ms", "> 1");
  test::expect_input_error([] { (void)compare_structures(frictionless(3.0), {}, {Structure::kPi, Structure::kPiP}); },
                           "structures", "velocity-loop");
}

TEST(CompareStructures, TestBedTwoHinfAgainstPiAsInTheDissertation) {
  // A6 configuration 2, both designs at ‖S‖∞, ‖Tl‖∞ <= 2.5 with motor feedback only (the printed
  // spec). The fit has no passive two-mass realization (ζz = 0.24 against ζp = 0.02), so the load
  // side is the exact realization's estimate and the tuner says so. The dissertation's findings:
  // H∞ "≈ 2× faster settling, much better disturbance rejection" than the PI. Measured here: load
  // bandwidth ×2.3, load settling ×1.6 faster, load-step ITAE ×0.11.
  TuneOptions o;
  o.ms = o.mt = 2.5;
  o.hf.delay_s = 0.5 * 0.0005;  // the 2 kHz EtherCAT loop's zero-order hold, as the testbed-2 preset adds it
  const std::vector<StructureComparison> c = compare_structures(test::test_bed_2(), o, {Structure::kPi, Structure::kHinf});
  const StructureComparison& pi = entry(c, Structure::kPi);
  const StructureComparison& hinf = entry(c, Structure::kHinf);
  ASSERT_TRUE(pi.result && hinf.result) << pi.failure << hinf.failure;
  for (const StructureComparison* e : {&pi, &hinf}) {
    const LoopIndices& p = e->result->controller.predicted;
    EXPECT_LE(p.peak_s, 2.5 * (1.0 + 1e-3));
    EXPECT_LE(p.peak_tl, 2.5 * (1.0 + 1e-3));
    bool estimated = false;
    for (const std::string& n : e->result->controller.notes) estimated |= n.find("load side is an estimate") != std::string::npos;
    EXPECT_TRUE(estimated) << to_string(e->structure);
  }
  const LoopIndices& p = pi.result->controller.predicted;
  const LoopIndices& h = hinf.result->controller.predicted;
  EXPECT_GT(h.bandwidth_load, 2.0 * p.bandwidth_load);
  EXPECT_LT(h.settling_time, p.settling_time / 1.4);
  EXPECT_LT(h.itae_load_step, 0.2 * p.itae_load_step);
  EXPECT_LT(h.peak_load_disturbance, p.peak_load_disturbance);
}

/// Catalog A6 configuration 1 (eq. 8.13, E37): K = 544.6, τ1 = 0.16, τ2 = 0.0038 s, modes
/// (35.3, 0.19)/(70.8, 0.02) and (114.6, 0.11)/(260.1, 0.005) rad/s (r = 2.0).
fit::PlantModel test_bed_1() {
  fit::PlantModel m = test::test_bed_2();
  m.rigid_pole_rad_s = 0.16;
  const double lag = 1.0 / 0.0038;
  m.lag_pole_rad_s = lag;
  m.gain = 544.6 * lag;
  m.modes = {{{35.3, 0.19}, {70.8, 0.02}}, {{114.6, 0.11}, {260.1, 0.005}}};
  return m;
}

TEST(CompareStructures, TestBedOneHasALoadSideOnlyAsAChain) {
  // A6 configuration 1: two modes. Without --load-side chain the tuner cannot know where the load
  // sits and maximizes the motor bandwidth (no load numbers); declared a drive-train chain, PI (on
  // the first mode, as A6) and H∞ (on the full model) are compared on the estimated load. Measured:
  // the H∞ reaches ×2.7 the PI's load bandwidth, but with a larger load overshoot (68 % against
  // 19 %): the dissertation's "similar bandwidth for all three" is not what the tuner finds at Ms =
  // Mt = 2.5 (documented in docs/controller-tuning-study.md).
  TuneOptions o;
  o.ms = o.mt = 2.5;
  o.hf.delay_s = 0.5 * 0.0005;
  const std::vector<StructureComparison> motor_only = compare_structures(test_bed_1(), o, {Structure::kPi});
  ASSERT_TRUE(motor_only.front().result.has_value());
  EXPECT_TRUE(std::isnan(motor_only.front().result->controller.predicted.bandwidth_load));
  const auto estimate_noted = [](const Controller& c) {
    bool noted = false;
    for (const std::string& n : c.notes) noted |= n.find("load side is an estimate") != std::string::npos;
    return noted;
  };
  EXPECT_FALSE(estimate_noted(motor_only.front().result->controller));  // no load numbers to qualify
  o.chain_load = true;
  const std::vector<StructureComparison> c = compare_structures(test_bed_1(), o, {Structure::kPi, Structure::kHinf});
  const StructureComparison& pi = entry(c, Structure::kPi);
  const StructureComparison& hinf = entry(c, Structure::kHinf);
  ASSERT_TRUE(pi.result && hinf.result) << pi.failure << hinf.failure;
  const LoopIndices& p = pi.result->controller.predicted;
  const LoopIndices& h = hinf.result->controller.predicted;
  for (const LoopIndices* i : {&p, &h}) {
    EXPECT_TRUE(std::isfinite(i->bandwidth_load));
    EXPECT_LE(i->peak_tl, 2.5 * (1.0 + 1e-3));
    EXPECT_LE(i->peak_s, 2.5 * (1.0 + 1e-3));
    EXPECT_TRUE(std::isnan(i->itae_load_step));  // no load-torque functions for a chain estimate
  }
  EXPECT_NE(pi.result->controller.design.omega_star_source.find("load through the chain"), std::string::npos);
  EXPECT_GT(h.bandwidth_load, 2.0 * p.bandwidth_load);
  EXPECT_GT(h.overshoot, 2.0 * p.overshoot);
  EXPECT_TRUE(estimate_noted(pi.result->controller));
  // The LQG "on the full model" (A6): designed on the first mode it is destabilized by mode 2 and
  // the lag at every kbw; with the model extended by mode 2 (C7.16) it designs, 7 states.
  o.structure = Structure::kLqg;
  o.hinf_modes = ModeHandling::kFirstMode;
  test::expect_input_error([&] { (void)tune(test_bed_1(), o); }, "--structure", "kbw");
  o.hinf_modes = ModeHandling::kActive;
  const TuneResult lqg = tune(test_bed_1(), o);
  EXPECT_TRUE(lqg.controller.predicted.closed_loop_stable);
  EXPECT_EQ(lqg.controller.full_order->compensator.A.rows(), 7);
  EXPECT_LE(lqg.controller.predicted.peak_tl, 2.5 * (1.0 + 1e-3));
  EXPECT_LE(lqg.controller.predicted.peak_s, 2.5 * (1.0 + 1e-3));
}

TEST(CompareStructures, AnAutomaticTargetRatioRecoversThePidOnALaggedPlant) {
  // Test bed 2: r̄ = 2 needs a derivative gain that the 2.2 ms lag and the hold leave no phase for
  // (load bandwidth 0.42 Hz against the PI's 6.2 Hz at Ms = Mt = 2.5); the automatic r̄ finds the
  // PID at least as good as the PI. On a frictionless plant without lags (C7.15's setting) r̄ = 2 stays
  // the choice, as the dissertation tunes it.
  TuneOptions o;
  o.ms = o.mt = 2.5;
  o.hf.delay_s = 0.5 * 0.0005;
  o.structure = Structure::kPid;
  const double fixed = tune(test::test_bed_2(), o).controller.predicted.bandwidth_load;
  o.target_r = std::nullopt;
  const TuneResult automatic = tune(test::test_bed_2(), o);
  o.structure = Structure::kPi;
  const double pi = tune(test::test_bed_2(), o).controller.predicted.bandwidth_load;
  EXPECT_LT(fixed, 0.1 * pi);
  EXPECT_GE(automatic.controller.predicted.bandwidth_load, 0.99 * pi);
  EXPECT_GT(*automatic.controller.design.r_target, 2.0);
  bool noted = false;
  for (const std::string& n : automatic.controller.notes) noted |= n.find("r-bar chosen automatically") != std::string::npos;
  EXPECT_TRUE(noted);
  TuneOptions c;
  c.structure = Structure::kPid;
  c.target_r = std::nullopt;
  EXPECT_EQ(*tune(frictionless(5.0), c).controller.design.r_target, 2.0);
}

TEST(CompareStructures, TheLqgDesignsOnANonPassiveRealization) {
  // The LQG's design model is the first mode's two-mass realization; for the test bed it has
  // negative motor friction (bm = −6.45 normalized), which the LQG used to refuse. It is an exact
  // realization of the fit, so the design proceeds (and meets the spec) with the estimate noted.
  TuneOptions o;
  o.ms = o.mt = 2.5;
  o.hf.delay_s = 0.5 * 0.0005;
  o.structure = Structure::kLqg;
  const TuneResult r = tune(test::test_bed_2(), o);
  EXPECT_TRUE(r.controller.predicted.closed_loop_stable);
  EXPECT_LE(r.controller.predicted.peak_s, 2.5 * (1.0 + 1e-3));
  EXPECT_LE(r.controller.predicted.peak_tl, 2.5 * (1.0 + 1e-3));
  ASSERT_FALSE(r.controller.notes.empty());
  bool estimated = false;
  for (const std::string& n : r.controller.notes) estimated |= n.find("bm = -6.45") != std::string::npos;
  EXPECT_TRUE(estimated);
}

}  // namespace compare_test
}  // namespace
}  // namespace servotwin::tuning
