// The virtual frequency-response experiment end to end: the real-time block measures a simulated
// two-mass servo bench with friction, current-loop lag, quantization and noise, and the two-mass fit
// of the latched points recovers its resonance and antiresonance (issue: "a simulated two-mass plant
// with friction and noise, 1-500 Hz: resonance and antiresonance within 0.5 %, their damping within
// 20 %, experiment time at most 30 s"). Expected values: the plant's own parameters through the
// closed forms of C3.12 (machine::two_mass_parameters), not anything the experiment computed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/fit/fit.hpp"
#include "servotwin/machine/flexible_presets.hpp"
#include "servotwin/vcnc/frf_experiment.hpp"

namespace {

using namespace servotwin;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

struct TrueModes {
  double fz_hz, zeta_z, fn_hz, zeta_n;
};

TrueModes true_modes(const machine::PlantConfig& config) {
  const auto& chain = std::get<machine::MassChain>(config.model);
  const auto p = machine::two_mass_parameters(chain.inertia[0], chain.inertia[1], chain.stiffness[0], chain.damping_of(0));
  return {p.omega_z / kTwoPi, p.zeta_z, p.omega_n / kTwoPi, p.zeta};
}

// The block measures the sampled loop (hold, current loop): a delay term absorbs both.
fit::FitOptions fit_options() {
  fit::FitOptions o;
  o.delay = true;
  return o;
}

TEST(FrfExperiment, MotorBenchOneToFiveHundredHertzGivesTheModesWithinTheIssueTolerances) {
  const machine::PlantConfig config = machine::flexible_preset("motor-bench");
  machine::FlexiblePlant plant(config);
  vcnc::FrfExperimentSettings settings;  // defaults: 1-500 Hz, 30 listed points
  const auto parameters = vcnc::experiment_parameters(plant, settings);
  const bool debug = std::getenv("SERVOTWIN_DEBUG_FRF") != nullptr;
  const auto experiment = vcnc::run_frf_experiment(plant, parameters, settings.max_time_s, debug, vcnc::dc_hold_gain(plant, settings));
  if (debug)
    for (std::size_t k = 0; k < experiment.trace.size() && k < 80000; k += 400)
      std::printf("t=%.3f mv=%.3f pv=%.3f A=%.4f thd=%.4f state=%d\n", experiment.trace[k].t, experiment.trace[k].mv,
                  experiment.trace[k].pv, experiment.trace[k].amplitude, experiment.trace[k].thd,
                  static_cast<int>(experiment.trace[k].state));
  ASSERT_EQ(experiment.final_state, frf::RfidState::kDone) << vcnc::outcome_text(experiment);
  if (std::getenv("SERVOTWIN_DEBUG_FRF"))
    for (const auto& p : experiment.points)
      std::printf("%8.3f Hz t=%7.3f |P|=%.4g thd=%.3f A=%.4g %s %s\n", p.omega / kTwoPi, p.time_s, std::abs(p.response), p.thd,
                  p.amplitude, vcnc::point_kind_name(p.kind).c_str(), p.settled ? "" : "UNSETTLED");
  ASSERT_TRUE(experiment.response.duration_s.has_value());
  EXPECT_LE(*experiment.response.duration_s, 30.0);
  EXPECT_GE(experiment.response.size(), settings.points);

  const fit::FitReport report = fit::fit_plant(experiment.response, {fit::ModelRequest::Kind::kTwoMass, 1}, fit_options());
  ASSERT_TRUE(report.result.converged) << report.result.message;
  ASSERT_EQ(report.result.model.modes.size(), 1u);
  const auto& mode = report.result.model.modes.front();
  const TrueModes truth = true_modes(config);
  EXPECT_NEAR(mode.antiresonance.omega_rad_s / kTwoPi / truth.fz_hz, 1.0, 0.005);
  EXPECT_NEAR(mode.resonance.omega_rad_s / kTwoPi / truth.fn_hz, 1.0, 0.005);
  EXPECT_NEAR(mode.antiresonance.zeta / truth.zeta_z, 1.0, 0.2);
  EXPECT_NEAR(mode.resonance.zeta / truth.zeta_n, 1.0, 0.2);
}

TEST(FrfExperiment, RequestsTheSampledPlantCannotMeasureAreNamed) {
  machine::FlexiblePlant plant(machine::flexible_preset("motor-bench"));  // 8 kHz: fs/10 = 800 Hz
  vcnc::FrfExperimentSettings s;
  s.f_end_hz = 900.0;
  try {
    (void)vcnc::experiment_parameters(plant, s);
    FAIL() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--range-hz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fs/10"), std::string::npos) << e.what();
  }
  s = {};
  s.points = 1;
  EXPECT_THROW((void)vcnc::experiment_parameters(plant, s), core::InputError);
  s = {};
  s.amplitude = 1.0;
  s.max_amplitude = 0.5;
  EXPECT_THROW((void)vcnc::experiment_parameters(plant, s), core::InputError);
}

}  // namespace
