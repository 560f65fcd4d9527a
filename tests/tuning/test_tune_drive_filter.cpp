// The tuner with the drive's filters at the controller output (issue 25 §5). References: the
// assigned pair, which the placement with the filter must put exactly among the closed-loop
// poles (closed form: the pair's roots); the design without the filter on the same plant and
// spec (the notch's gain); the spec itself, re-checked on every returned design.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/tune.hpp"

namespace servotwin::tuning {
namespace {

using test::two_mass_model;
constexpr double kTuneFilterTwoPi = 2.0 * std::numbers::pi;

DriveFilterSpec notch_spec(double f, double width, double depth) {
  DriveFilterSpec s;
  s.frequency_hz = f;
  s.width_hz = width;
  s.depth_db = depth;
  return s;
}

bool notes_contain(const Controller& c, const std::string& text) {
  for (const std::string& n : c.notes)
    if (n.find(text) != std::string::npos) return true;
  return false;
}

TEST(TuneDriveFilter, PiPlacesItsPairWithTheFilterInTheLoop) {
  // A notch and a low-pass at the PI's output: the pair s² + 2ζ*ω* s + ω*² is still a root pair
  // of the closed loop with the filters (the placement runs on plant·F), to the root finder's
  // accuracy (1e-7 relative).
  const double wz = kTuneFilterTwoPi * 40.0;
  TuneOptions o;
  o.ts = 1.0 / 8000.0;
  o.omega_star = 0.6;
  o.drive_filters = {notch_spec(200.0, 60.0, 20.0)};
  DriveFilterSpec low;
  low.type = DriveFilterType::kLowpass;
  low.frequency_hz = 900.0;
  o.drive_filters.push_back(low);
  const TuneResult r = tune(two_mass_model(2.2, 0.02, wz), o);
  const Controller& c = r.controller;
  ASSERT_EQ(c.drive_filters.size(), 2u);
  ASSERT_TRUE(c.drive_filters[0].discrete && c.drive_filters[1].discrete);
  const std::complex<double> pair = 0.6 * std::complex<double>(-0.8, std::sqrt(1.0 - 0.64));
  double nearest = 1e9;
  for (const auto& p : c.predicted.closed_loop_poles) nearest = std::min(nearest, std::abs(p - pair));
  EXPECT_LT(nearest, 1e-7) << "assigned pair missing from the closed loop with the filters";
  // The gains differ from the design without filters: the filters were designed with.
  TuneOptions plain = o;
  plain.drive_filters.clear();
  const TuneResult without = tune(two_mass_model(2.2, 0.02, wz), plain);
  EXPECT_GT(std::abs(c.normalized.kp - without.controller.normalized.kp), 1e-3 * without.controller.normalized.kp);
  // The controller's state space carries the filters: its gain at the notch centre is the PI's
  // times 10^(-20/20) times the low-pass's.
  const core::StateSpace k = controller_state_space(c);
  EXPECT_EQ(k.states(), 1 + 2 + 1);
}

TEST(TuneDriveFilter, AutomaticNotchOnTestBedTwoTakesTheFirstResonance) {
  // A6 configuration 2: r = 5.09 > sqrt(5), so the PI cannot damp the 254 rad/s (40.4 Hz)
  // resonance (C7.4); Ms = Mt = 2.5 as the dissertation's comparison, 2 kHz.
  TuneOptions o;
  o.ms = o.mt = 2.5;
  o.ts = 0.0005;
  o.hf.delay_s = 0.5 * *o.ts;
  const TuneResult without = tune(test::test_bed_2(), o);
  o.auto_notch = true;
  const TuneResult with = tune(test::test_bed_2(), o);
  const Controller& c = with.controller;
  ASSERT_EQ(c.drive_filters.size(), 1u);
  EXPECT_NEAR(c.drive_filters.front().spec.frequency_hz, 254.0 / kTuneFilterTwoPi, 0.01);
  const double b0 = without.controller.predicted.bandwidth_load, b1 = c.predicted.bandwidth_load;
  EXPECT_GE(b1, 1.2 * b0) << "load bandwidth " << b1 << " with the notch, " << b0 << " without";
  EXPECT_LE(c.predicted.peak_s, 2.5 * (1.0 + 1e-3));
  EXPECT_LE(c.predicted.peak_tl, 2.5 * (1.0 + 1e-3));
}

TEST(TuneDriveFilter, AutomaticNotchSaysWhenNoModeNeedsOne) {
  // r = 2 (C7.4's sweet spot) and no higher mode: nothing to notch; the design goes on without.
  TuneOptions o;
  o.ts = 1.0 / 8000.0;
  o.auto_notch = true;
  const TuneResult r = tune(two_mass_model(2.0, 0.02), o);
  EXPECT_TRUE(r.controller.drive_filters.empty());
  EXPECT_TRUE(notes_contain(r.controller, "no notch placed"));
}

TEST(TuneDriveFilter, RefusesFiltersItCannotDesignWith) {
  TuneOptions o;
  o.drive_filters = {notch_spec(200.0, 60.0, 20.0)};
  test::expect_input_error([&] { (void)tune(two_mass_model(2.2, 0.02), o); }, "--ts", "give --ts");
  o.ts = 1.0 / 8000.0;
  o.structure = Structure::kLqg;
  test::expect_input_error([&] { (void)tune(two_mass_model(2.2, 0.02), o); }, "--drive-filter", "LQG");
  o.structure = Structure::kHinf;
  test::expect_input_error([&] { (void)tune(two_mass_model(2.2, 0.02), o); }, "--drive-filter", "first-order lowpass");
  o.structure = Structure::kPi;
  o.drive_filters = {notch_spec(5000.0, 60.0, 20.0)};
  test::expect_input_error([&] { (void)tune(two_mass_model(2.2, 0.02), o); }, "--drive-filter", "Nyquist");
  o.drive_filters = {notch_spec(200.0, 60.0, -3.0)};
  test::expect_input_error([&] { (void)tune(two_mass_model(2.2, 0.02), o); }, "--drive-filter", "negative depth");
}

}  // namespace
}  // namespace servotwin::tuning
