// Rapid identification end to end (thesis sections 3.4.1, 4.3.1 and 4.3.2): identify the
// closed-loop axis model from a Table 3.2-style capture of each virtual machine preset and compare
// it with the machine's true sampled loop (machine::discrete_tracking_tf, derived independently of
// the identification) and with captures of other programs; then the same on the measured EMPS
// axis. docs/rapid-identification-study.md reports these numbers (run test_validation to print them).
#include <gtest/gtest.h>

#include <cstdio>

#include "servotwin/io/capture_csv.hpp"
#include "validation_support.hpp"

namespace servotwin::validation {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace rapid_identification_test {

/// Expected agreement per preset. PPI and PID meet the thesis's 10 % prediction target. The
/// sliding-mode loop's tracking error (6.6 um RMS) is a discrete-time effect of its feed-forward
/// that a continuous third-order model cannot follow: 17 % even on the ideal machine without
/// friction or quantization. The ZPETC loop's tracking error (3.5 um RMS) is of the order of its
/// 1.25 um encoder quantum (noise floor q / sqrt(12) = 0.36 um = 10 %); with an ideal encoder the
/// prediction is within 10 % (ZpetcWithIdealEncoder below).
struct Case {
  const char* machine;
  double frf_tolerance;         // largest relative tracking-FRF deviation, 0.5 to 30 Hz
  double prediction_tolerance;  // RMS(predicted - actual tracking error) / RMS(actual)
};

struct Outcome {
  vcnc::AxisIdentification identification;
  double frf_error = 0.0;
  double prediction_same_kind = 0.0;  // another Table 3.2 program (seed 11)
  double prediction_high_set = 0.0;   // a Table 4.4 high-speed program
};

Outcome run_case(const machine::MachineConfig& machine, const vcnc::IdentificationSettings& settings) {
  Outcome out;
  out.identification = vcnc::identify_axis({thesis_capture(machine, 7)}, {}, "x", settings);
  const int shift = out.identification.regressors.command_shift;
  const rapid::AxisModel model(out.identification.coefficients(), machine.ts);
  out.frf_error = tracking_frf_error(model, machine.axes.front(), machine.ts, shift, 0.5, 30.0);
  out.prediction_same_kind = prediction_error_ratio(model, *thesis_capture(machine, 11).capture.find("x"), shift);
  out.prediction_high_set =
      prediction_error_ratio(model, *thesis_capture(machine, 5, motion::IdentificationSet::High).capture.find("x"), shift);
  return out;
}

vcnc::IdentificationSettings searched_shift() {
  vcnc::IdentificationSettings s;
  s.shift_search = vcnc::ShiftSearch{};
  return s;
}

/// The study's table: identified and true coefficients, poles, FRF at a few frequencies.
void print(const machine::MachineConfig& m, const Outcome& o) {
  const auto& s = o.identification.solution;
  const auto& c = s.coefficients;
  const auto truth = machine::equivalent_closed_loop(m.axes.front(), m.ts);
  const auto& t = truth.coefficients;
  const int shift = o.identification.regressors.command_shift;
  std::printf("%s (%s, shift %d): wn %.2f Hz zeta %.3f p %.2f Hz, case %s\n", m.name.c_str(), rapid::method_name(s.method),
              shift, s.wn / kTwoPi, s.zeta, s.p / kTwoPi, s.kkt_case.c_str());
  std::printf("  identified a1 %.2f a2 %.2f a3 %.2f b0 %.3f b1 %.2f b2 %.2f d0 %.1f d1 %.1f\n", c.a1, c.a2, c.a3, c.b0,
              c.b1, c.b2, c.d0, c.d1);
  std::printf("  %s a1 %.2f a2 %.2f a3 %.2f b0 %.3f b1 %.2f b2 %.2f d0 %.1f d1 %.1f\n",
              truth.exact ? "true      " : "equivalent", t.a1, t.a2, t.a3, t.b0, t.b1, t.b2, t.d0, t.d1);
  const auto disc = machine::discrete_tracking_tf(m.axes.front(), m.ts);
  const rapid::AxisModel model(c, m.ts);
  for (double f : {1.0, 5.0, 10.0, 20.0, 30.0}) {
    const auto g = shifted_tracking_response(model, kTwoPi * f, shift, m.ts);
    const auto h = disc.frequency_response(kTwoPi * f);
    std::printf("    %4.0f Hz: identified %.3f dB %.1f deg, true %.3f dB %.1f deg, rel err %.4f\n", f,
                20 * std::log10(std::abs(g)), std::arg(g) * 180 / std::numbers::pi, 20 * std::log10(std::abs(h)),
                std::arg(h) * 180 / std::numbers::pi, std::abs(g - h) / std::abs(h));
  }
  std::printf("  fit nrmse %.4f; FRF error 0.5-30 Hz %.4f; prediction error: other seed %.4f, high set %.4f\n",
              o.identification.fit->nrmse, o.frf_error, o.prediction_same_kind, o.prediction_high_set);
}

class PresetIdentification : public ::testing::TestWithParam<Case> {};

TEST_P(PresetIdentification, StableModelThatPredictsTrackingOfOtherPrograms) {
  const Case c = GetParam();
  const machine::MachineConfig machine = machine::preset(c.machine);
  const Outcome o = run_case(machine, searched_shift());
  print(machine, o);
  const rapid::AxisModel model(o.identification.solution.coefficients, machine.ts);
  EXPECT_TRUE(model.is_stable());
  EXPECT_TRUE(o.identification.solution.feasible);
  EXPECT_TRUE(o.identification.solution.certified);
  EXPECT_LT(o.frf_error, c.frf_tolerance);
  EXPECT_LT(o.prediction_same_kind, c.prediction_tolerance);
  EXPECT_LT(o.prediction_high_set, c.prediction_tolerance);
}

TEST_P(PresetIdentification, SearchedShiftPredictsAtLeastAsWellAsTheControllersPreview) {
  // The shift chosen by the fit on the identification data against the one the controller's
  // structure suggests (1 for central-difference feed-forward, 2 for the ZPETC).
  const machine::MachineConfig machine = machine::preset(GetParam().machine);
  vcnc::IdentificationSettings preview;
  preview.regressors.command_shift = machine::command_preview(machine.axes.front());
  const Outcome fixed = run_case(machine, preview);
  const Outcome searched = run_case(machine, searched_shift());
  EXPECT_LE(searched.prediction_same_kind, fixed.prediction_same_kind * 1.001);
  EXPECT_LE(searched.identification.fit->nrmse, fixed.identification.fit->nrmse);
  ASSERT_EQ(searched.identification.shift_trials.size(), 7u);
}

TEST_P(PresetIdentification, StoppedShiftCandidatesChangeNoChoice) {
  // Issue 26: the shift search stops a candidate's simulation once it can no longer be chosen.
  // Reference: every shift identified on its own with its complete fit, and choose_shift's rule
  // (identification.cpp) applied by hand: the stable models, those within 2 % of the best nrmse,
  // the smallest |shift| among them (ties: the lower nrmse).
  const machine::MachineConfig machine = machine::preset(GetParam().machine);
  const vcnc::NamedCapture capture = thesis_capture(machine, 7);
  const auto searched = vcnc::identify_axis({capture}, {}, "x", searched_shift());
  std::vector<vcnc::AxisIdentification> each;
  for (int shift = -3; shift <= 3; ++shift) {
    vcnc::IdentificationSettings fixed;
    fixed.regressors.command_shift = shift;
    each.push_back(vcnc::identify_axis({capture}, {}, "x", fixed));
  }
  double best = std::numeric_limits<double>::infinity();
  bool any_stable = false;
  for (const auto& e : each) any_stable = any_stable || rapid::AxisModel(e.coefficients(), e.ts).is_stable();
  for (const auto& e : each)
    if (rapid::AxisModel(e.coefficients(), e.ts).is_stable() == any_stable) best = std::min(best, e.fit->nrmse);
  const vcnc::AxisIdentification* chosen = nullptr;
  for (const auto& e : each) {
    if (rapid::AxisModel(e.coefficients(), e.ts).is_stable() != any_stable || e.fit->nrmse > best * 1.02) continue;
    const int s = e.regressors.command_shift;
    if (chosen == nullptr || std::abs(s) < std::abs(chosen->regressors.command_shift) ||
        (std::abs(s) == std::abs(chosen->regressors.command_shift) && e.fit->nrmse < chosen->fit->nrmse))
      chosen = &e;
  }
  ASSERT_NE(chosen, nullptr);
  EXPECT_EQ(searched.regressors.command_shift, chosen->regressors.command_shift);
  EXPECT_EQ(searched.coefficients().a1, chosen->coefficients().a1);
  EXPECT_EQ(searched.coefficients().d1, chosen->coefficients().d1);
  EXPECT_EQ(searched.fit->nrmse, chosen->fit->nrmse);
  // The candidates are solved on every core (IdentificationSettings::workers = 0): one thread
  // gives the same numbers.
  vcnc::IdentificationSettings one_thread = searched_shift();
  one_thread.workers = 1;
  const auto sequential = vcnc::identify_axis({capture}, {}, "x", one_thread);
  EXPECT_EQ(sequential.coefficients().a1, searched.coefficients().a1);
  EXPECT_EQ(sequential.coefficients().b2, searched.coefficients().b2);
  ASSERT_EQ(sequential.shift_trials.size(), searched.shift_trials.size());
  for (std::size_t i = 0; i < searched.shift_trials.size(); ++i)
    EXPECT_EQ(sequential.shift_trials[i].nrmse, searched.shift_trials[i].nrmse);
  ASSERT_EQ(searched.shift_trials.size(), each.size());
  for (std::size_t i = 0; i < each.size(); ++i) {
    const vcnc::ShiftTrial& t = searched.shift_trials[i];
    if (t.complete) {
      EXPECT_EQ(t.nrmse, each[i].fit->nrmse) << t.shift;
    } else {
      EXPECT_LE(t.nrmse, each[i].fit->nrmse) << t.shift;       // a lower bound
      EXPECT_GT(each[i].fit->nrmse, best * 1.02) << t.shift;  // and rightly out of the running
    }
  }
}

TEST_P(PresetIdentification, FastSimulationEqualsTheEventSearchOnEverySample) {
  // Issue 26: the certified single-step samples of AxisModel::simulate against the reference that
  // runs the series event search on every sample, on each virtual machine's identified model and
  // another program of the identification kind (seed 11); bound 1e-9 of the tracking error's RMS.
  const machine::MachineConfig machine = machine::preset(GetParam().machine);
  const auto identified = vcnc::identify_axis({thesis_capture(machine, 7)}, {}, "x", searched_shift());
  const rapid::AxisModel model(identified.coefficients(), machine.ts);
  const vcnc::NamedCapture other = thesis_capture(machine, 11);
  const core::AxisTrace& trace = *other.capture.find("x");
  rapid::ModelSimulationOptions fast, reference;
  fast.command_shift = reference.command_shift = identified.regressors.command_shift;
  reference.event_search_every_sample = true;
  const rapid::ModelResponse a = model.simulate(trace.cmd, fast);
  const rapid::ModelResponse b = model.simulate(trace.cmd, reference);
  double rms = 0.0;
  for (double e : b.tracking_error) rms += e * e;
  rms = std::sqrt(rms / static_cast<double>(b.tracking_error.size()));
  ASSERT_GT(rms, 0.0);
  double worst = 0.0;
  for (std::size_t k = 0; k < a.tracking_error.size(); ++k) worst = std::max(worst, std::abs(a.tracking_error[k] - b.tracking_error[k]));
  EXPECT_LE(worst, 1e-9 * rms);
  EXPECT_EQ(a.events.reversals, b.events.reversals);
  EXPECT_EQ(a.events.sticks, b.events.sticks);
  EXPECT_GT(a.events.reversals, 0u);
}

INSTANTIATE_TEST_SUITE_P(Presets, PresetIdentification,
                         ::testing::Values(Case{"fadal-ppi", 0.08, 0.10}, Case{"fadal-pid", 0.03, 0.10},
                                           Case{"fadal-smc", 0.05, 0.23}, Case{"ballscrew-zpetc", 0.01, 0.30}),
                         [](const auto& param_info) {
                           std::string n = param_info.param.machine;
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

/// With the output-error refinement (rapid/refine.hpp) on the identification data. The bound is
/// the 10 %, or, where even a perfect prediction cannot reach it, the best any prediction
/// driven by the command can do: the machine itself run again without its encoder quantum
/// (quantum_free_machine_ratio). The ZPETC loop's 3.5 um RMS error is of the order of its 1.25 um
/// encoder quantum (the thesis's ball-screw drive, section 3.4.2): that machine scores 13.9 % and
/// 14.2 % against the reading, and 9.3 % / 9.6 % against its own true table position, because
/// the loop reacts to its quantized feedback in a way no command-driven model can follow. The
/// refined model scores 14.1 / 14.6 % and 9.7 / 10.2 %. The size of the error (its RMS level) is
/// predicted within 10 % on every preset.
struct RefinedCase {
  const char* machine;
  double to_reading;  // prediction error vs the encoder's reading, both other programs
  double to_truth;    // vs the true table position
};

class RefinedIdentification : public ::testing::TestWithParam<RefinedCase> {};

TEST_P(RefinedIdentification, PredictsTrackingOfOtherProgramsWithinTenPercent) {
  const machine::MachineConfig machine = machine::preset(GetParam().machine);
  vcnc::IdentificationSettings settings = searched_shift();
  const Outcome exact = run_case(machine, settings);
  settings.refine = true;
  const Outcome o = run_case(machine, settings);
  const auto& id = o.identification;
  ASSERT_TRUE(id.refinement.has_value());
  const rapid::Refinement& f = *id.refinement;
  const int shift = id.regressors.command_shift;
  const rapid::AxisModel model(id.coefficients(), machine.ts);
  const core::AxisTrace other = *thesis_capture(machine, 11).capture.find("x");
  const core::AxisTrace high = *thesis_capture(machine, 5, motion::IdentificationSet::High).capture.find("x");
  const double truth_other = prediction_error_ratio_to_truth(model, machine, other, shift);
  const double truth_high = prediction_error_ratio_to_truth(model, machine, high, shift);
  std::printf("%s refined (shift %d): wn %.2f Hz zeta %.3f p %.2f Hz; fit nrmse %.4f -> %.4f in %d iterations, %d "
              "simulations, %.0f ms (%s)\n",
              machine.name.c_str(), shift, f.wn / kTwoPi, f.zeta, f.p / kTwoPi, id.solver_fit->nrmse, id.fit->nrmse,
              f.iterations, f.simulations, f.time_ms, f.stop_reason.c_str());
  std::printf("  FRF error 0.5-30 Hz %.4f (exact %.4f); prediction error vs reading: other seed %.4f, high set %.4f "
              "(exact %.4f, %.4f); vs true position %.4f, %.4f\n",
              o.frf_error, exact.frf_error, o.prediction_same_kind, o.prediction_high_set, exact.prediction_same_kind,
              exact.prediction_high_set, truth_other, truth_high);
  EXPECT_TRUE(model.is_stable());
  EXPECT_LE(f.cost, f.initial_cost);
  EXPECT_LT(id.fit->nrmse, id.solver_fit->nrmse);
  // Better than the equation-error model on programs it was not fitted on.
  EXPECT_LT(o.prediction_same_kind, exact.prediction_same_kind);
  EXPECT_LT(o.prediction_high_set, exact.prediction_high_set);
  EXPECT_LT(o.prediction_same_kind, GetParam().to_reading);
  EXPECT_LT(o.prediction_high_set, GetParam().to_reading);
  EXPECT_LT(truth_other, GetParam().to_truth);
  EXPECT_LT(truth_high, GetParam().to_truth);
  // The 10 %, or within 5 % of the floor no command-driven prediction can beat.
  const double floor_other = quantum_free_machine_ratio(machine, other);
  const double floor_high = quantum_free_machine_ratio(machine, high);
  const double level_other = rms_level_error(model, other, shift);
  const double level_high = rms_level_error(model, high, shift);
  std::printf("  the machine without its encoder quantum vs reading: %.4f, %.4f; RMS level error %.4f, %.4f\n",
              floor_other, floor_high, level_other, level_high);
  EXPECT_LT(o.prediction_same_kind, std::max(0.10, 1.05 * floor_other));
  EXPECT_LT(o.prediction_high_set, std::max(0.10, 1.05 * floor_high));
  EXPECT_LT(level_other, 0.10);
  EXPECT_LT(level_high, 0.10);
}

INSTANTIATE_TEST_SUITE_P(Presets, RefinedIdentification,
                         ::testing::Values(RefinedCase{"fadal-ppi", 0.01, 0.01}, RefinedCase{"fadal-pid", 0.02, 0.02},
                                           RefinedCase{"fadal-smc", 0.10, 0.10},
                                           RefinedCase{"ballscrew-zpetc", 0.16, 0.11}),
                         [](const auto& param_info) {
                           std::string n = param_info.param.machine;
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

TEST(PresetIdentification, ZpetcWithIdealEncoderPredictsWithinTenPercent) {
  machine::MachineConfig machine = machine::preset("ballscrew-zpetc");
  machine.axes.front().nonlinear.encoder_resolution = 0.0;
  machine.axes.front().nonlinear.dac_bits = 0;
  const Outcome o = run_case(machine, searched_shift());
  print(machine, o);
  EXPECT_LT(o.prediction_same_kind, 0.10);
  // Refined, the same loop without encoder quantization is predicted to about 1 %: on the real
  // preset the remaining 14 % (9.7-10.2 % against the true position) is the encoder's.
  vcnc::IdentificationSettings refine = searched_shift();
  refine.refine = true;
  const Outcome r = run_case(machine, refine);
  std::printf("ballscrew-zpetc, ideal encoder, refined: fit %.4f; prediction other seed %.4f, high set %.4f\n",
              r.identification.fit->nrmse, r.prediction_same_kind, r.prediction_high_set);
  EXPECT_LT(r.prediction_same_kind, 0.5 * o.prediction_same_kind);
  EXPECT_LT(r.prediction_high_set, 0.5 * o.prediction_high_set);
}

TEST(PresetIdentification, GeneticAlgorithmIsNeverBetterThanExact) {
  // The thesis's comparison (section 4.3): its GA came within 2-3 % of the optimum in minutes.
  const machine::MachineConfig machine = machine::preset("fadal-pid");
  vcnc::IdentificationSettings s;
  s.regressors.command_shift = 0;
  s.bounds.zeta_min = 0.6;  // make a bound active, so that the GA has to find the boundary optimum
  const auto exact = vcnc::identify_axis({thesis_capture(machine, 7)}, {}, "x", s);
  s.method = rapid::Method::Ga;
  s.solve.ga.generations = 100;
  const auto ga = vcnc::identify_axis({thesis_capture(machine, 7)}, {}, "x", s);
  std::printf("fadal-pid, zeta >= 0.6: exact f = %.6g (%s, %.2f ms), ga f = %.6g (+%.3g %%, %.0f ms)\n",
              exact.solution.objective, exact.solution.kkt_case.c_str(), exact.solution.time_ms, ga.solution.objective,
              100.0 * (ga.solution.objective / exact.solution.objective - 1.0), ga.solution.time_ms);
  EXPECT_EQ(exact.solution.kkt_case, "2: zeta = zeta_min");
  EXPECT_GE(ga.solution.objective, exact.solution.lower_bound);
  EXPECT_LE(ga.solution.objective, exact.solution.objective * 1.03);
}

// --- measured data: the EMPS ball-screw axis (data/emps/README.md) ---------------------------

core::Capture read_emps(const char* file, double scale) {
  io::CaptureReadOptions o;
  o.map = {{"x_cmd", "qg"}, {"x_act", "qm"}};
  o.scale = scale;
  return io::read_capture_file(std::string(SERVOTWIN_REPO_DATA_DIR) + "/emps/" + file, o);
}

/// Samples [from, to) of a capture.
vcnc::NamedCapture part(const core::Capture& c, std::size_t from, std::size_t to, const char* name) {
  core::Capture out = c;
  out.t0 = c.time(from);
  for (auto& axis : out.axes) {
    axis.cmd.assign(axis.cmd.begin() + static_cast<std::ptrdiff_t>(from), axis.cmd.begin() + static_cast<std::ptrdiff_t>(to));
    axis.act.assign(axis.act.begin() + static_cast<std::ptrdiff_t>(from), axis.act.begin() + static_cast<std::ptrdiff_t>(to));
    axis.u.clear();
  }
  return {name, out};
}

TEST(EmpsIdentification, BoundedModelIsStableAndPredictsOtherData) {
  const core::Capture data = read_emps("DATA_EMPS.csv", 1000.0);
  const std::size_t half = data.size() / 2;
  const vcnc::NamedCapture first = part(data, 0, half, "EMPS first half");
  const vcnc::NamedCapture second = part(data, half, data.size(), "EMPS second half");
  const vcnc::NamedCapture pulses{"EMPS pulses", read_emps("DATA_EMPS_PULSES.csv", 1000.0)};

  vcnc::IdentificationSettings ls;
  ls.method = rapid::Method::Ls;
  const auto unconstrained = vcnc::identify_axis({first}, {}, "x", ls);
  vcnc::IdentificationSettings exact;
  const auto bounded = vcnc::identify_axis({first}, {second}, "x", exact);
  const auto bounded_pulses = vcnc::identify_axis({first}, {pulses}, "x", exact);
  const auto& s = bounded.solution;
  std::printf("EMPS ls: p %.4f Hz (feasible %d, stable %d)\n", unconstrained.solution.p / kTwoPi,
              unconstrained.solution.feasible,
              rapid::AxisModel(unconstrained.solution.coefficients, data.ts).is_stable());
  std::printf("EMPS exact: wn %.3f Hz zeta %.4f p %.3f Hz, %s; fit %.4f, second half %.4f, pulses %.4f; %.2f ms\n",
              s.wn / kTwoPi, s.zeta, s.p / kTwoPi, s.kkt_case.c_str(), bounded.fit->nrmse, bounded.validation->nrmse,
              bounded_pulses.validation->nrmse, s.time_ms);
  // Unconstrained least squares puts the slow real pole in the right half plane.
  EXPECT_FALSE(unconstrained.solution.feasible);
  EXPECT_FALSE(rapid::AxisModel(unconstrained.solution.coefficients, data.ts).is_stable());
  // The bounded model is stable, holds p at its lower bound with a positive multiplier, and
  // predicts the tracking error of data it has not seen.
  EXPECT_TRUE(rapid::AxisModel(s.coefficients, data.ts).is_stable());
  EXPECT_TRUE(s.certified);
  ASSERT_EQ(s.active.size(), 1u);
  EXPECT_EQ(s.active.front().name, "p_min");
  EXPECT_GT(s.active.front().multiplier, 0.0);
  EXPECT_LT(bounded.fit->nrmse, 0.05);
  EXPECT_LT(bounded.validation->nrmse, 0.10);
  EXPECT_LT(bounded_pulses.validation->nrmse, 0.25);

  // Output-error refinement on measured data: it fits the identification half five times better,
  // but predicts the second half worse than the equation-error model (structure, not noise: the
  // measured axis is not exactly Eq. 3.3), which is why it is an option to be checked with
  // --validate rather than the default.
  exact.refine = true;
  const auto refined = vcnc::identify_axis({first}, {second, pulses}, "x", exact);
  const auto only_second = vcnc::identify_axis({first}, {second}, "x", exact);
  std::printf("EMPS refined: wn %.3f Hz zeta %.4f p %.3f Hz; fit %.4f; second half %.4f (exact %.4f); both %.4f\n",
              refined.refinement->wn / kTwoPi, refined.refinement->zeta, refined.refinement->p / kTwoPi,
              refined.fit->nrmse, only_second.validation->nrmse, only_second.solver_validation->nrmse,
              refined.validation->nrmse);
  EXPECT_LT(refined.fit->nrmse, 0.25 * bounded.fit->nrmse);
  EXPECT_TRUE(rapid::AxisModel(refined.coefficients(), data.ts).is_stable());
  ASSERT_EQ(refined.refinement->active.size(), 1u);
  EXPECT_EQ(refined.refinement->active.front().name, "p_min");
  EXPECT_GT(only_second.validation->nrmse, only_second.solver_validation->nrmse);
  EXPECT_LT(only_second.validation->nrmse, 0.15);
}

TEST(EmpsIdentification, SameModelInMetresAndMillimetres) {
  const core::Capture mm = read_emps("DATA_EMPS.csv", 1000.0);
  const core::Capture m = read_emps("DATA_EMPS.csv", 1.0);
  const auto a = vcnc::identify_axis({{"mm", mm}}, {}, "x", {});
  const auto b = vcnc::identify_axis({{"m", m}}, {}, "x", {});
  EXPECT_EQ(a.solution.kkt_case, b.solution.kkt_case);
  EXPECT_NEAR(a.solution.wn, b.solution.wn, 1e-8 * a.solution.wn);
  EXPECT_NEAR(a.solution.zeta, b.solution.zeta, 1e-8);
  EXPECT_NEAR(a.solution.p, b.solution.p, 1e-8 * a.solution.p);
  // Friction is a force per mass (length / s^2): it scales with the unit; the rest does not.
  EXPECT_NEAR(a.solution.coefficients.b2, b.solution.coefficients.b2, 1e-8 * std::abs(a.solution.coefficients.b2));
  EXPECT_NEAR(a.solution.coefficients.d0, 1000.0 * b.solution.coefficients.d0, 1e-8 * std::abs(a.solution.coefficients.d0));
  EXPECT_NEAR(a.fit->nrmse, b.fit->nrmse, 1e-8);
}

}  // namespace rapid_identification_test
}  // namespace
}  // namespace servotwin::validation
