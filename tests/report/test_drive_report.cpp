// The closed-loop simulation report: the charts carry the run's own samples (plant and linear part
// side by side), the metrics table the run's own metrics, and the torque limit is drawn when set.
#include <gtest/gtest.h>

#include <string>

#include "report_test_support.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/report/drive_report.hpp"
#include "servotwin/tuning/tune.hpp"

namespace servotwin::report {
namespace {

vcnc::DriveSimulation run(tuning::Structure structure, vcnc::DriveTest test, std::optional<double> limit) {
  machine::PlantConfig plant;
  plant.model = machine::two_mass(1.0, 3.0, 3.0, 0.12);
  auto& chain = std::get<machine::MassChain>(plant.model);
  chain.friction = {machine::KarnoppFriction{}, machine::KarnoppFriction{0.02, 0.03, 1e-3}};
  plant.settings.ts = 5e-3;
  tuning::TuneOptions o;
  o.structure = structure;
  const auto tf = machine::mass_chain_transfer_function(chain, machine::PlantOutput::MotorVelocity);
  const auto result = tuning::tune(fit::plant_model_from_transfer_function(tf), o);
  vcnc::DriveSimulationSettings s;
  s.test = test;
  s.torque_limit = limit;
  s.duration_s = 20.0;
  return vcnc::simulate_drive(plant, result.controller, s);
}

TEST(DriveReport, ChartsCarryTheRunsSamplesAndTheLimit) {
  const auto sim = run(tuning::Structure::kPi, vcnc::DriveTest::kSetpointStep, 0.4);
  const Document doc = drive_report(sim, {"plant.json", "pi.json"});
  ASSERT_EQ(doc.sections.size(), 1U);
  const Section& s = doc.sections.front();
  ASSERT_EQ(s.charts.size(), 4U);  // load velocity, motor velocity, torque, measured
  const Chart& controlled = s.charts[0];
  ASSERT_EQ(controlled.series.size(), 3U);  // plant, linear part, reference
  EXPECT_EQ(controlled.series[0].y.size(), sim.samples.size());
  EXPECT_EQ(controlled.series[0].y[100], sim.samples[100].load_velocity);
  EXPECT_EQ(controlled.series[1].y[100], sim.linear_samples[100].load_velocity);
  const Chart& torque = s.charts[2];
  ASSERT_EQ(torque.series.size(), 4U);  // plant, linear, ±limit
  EXPECT_EQ(torque.series[2].y.front(), 0.4);
  ASSERT_EQ(s.tables.size(), 2U);
  EXPECT_EQ(s.tables[1].title, "Metrics");
  EXPECT_EQ(s.tables[1].rows[1][0], "overshoot [%]");
  EXPECT_NEAR(std::stod(s.tables[1].rows[1][1]), 100.0 * sim.metrics.overshoot, 1e-3 * (1.0 + 100.0 * sim.metrics.overshoot));
  const std::string html = testing::render(doc);
  EXPECT_EQ(chart_count(doc), 4U);
  EXPECT_NE(html.find("plant.json"), std::string::npos);
}

TEST(DriveReport, PositionLoadStepNamesThePositionAndHasNoReferenceSeries) {
  const auto sim = run(tuning::Structure::kPiP, vcnc::DriveTest::kLoadStep, std::nullopt);
  const Section s = drive_section(sim, "Load step");
  EXPECT_EQ(s.charts[0].series.size(), 2U);
  EXPECT_NE(s.charts[0].title.find("load position"), std::string::npos);
  EXPECT_EQ(s.charts[0].series[0].y[200], sim.samples[200].load_position);
  EXPECT_EQ(s.charts[2].series.size(), 2U);  // no limit lines
}

}  // namespace
}  // namespace servotwin::report
