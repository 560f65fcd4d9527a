// plant_model.json (io/plant_model_json.hpp): round trip of a fitted report and the reader's
// error messages. The round trip's reference is the written model itself (the file must mean the
// same plant: responses compared on a grid); the fitted plant is the catalog's E10 table plant.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/io/plant_model_json.hpp"

namespace servotwin::io {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace plant_model_json_test {

fit::FitReport e10_report(bool lag) {
  fit::PlantModel truth;
  truth.gain = 0.5;
  truth.rigid_pole_rad_s = 0.2;
  truth.modes = {fit::Mode{{1.0, 0.06}, {3.0, 0.15}}};
  if (lag) truth.lag_pole_rad_s = 40.0;
  core::FrequencyResponse r;
  for (double w : core::log_space(0.05, 60.0, 40)) {
    core::FrequencyPoint p;
    p.freq_hz = w / (2.0 * std::numbers::pi);
    // 1 % deterministic ripple so that the covariance is finite and non-zero.
    p.value = truth.response(w) * (1.0 + 0.01 * std::sin(7.0 * w));
    r.points.push_back(p);
  }
  fit::FitOptions o;
  o.output = fit::OutputChoice::kVelocity;
  o.lag = lag;
  return fit::fit_plant(r, {}, o);
}

TEST(PlantModelJson, RoundTripKeepsThePlant) {
  for (bool lag : {false, true}) {
    const fit::FitReport report = e10_report(lag);
    const nlohmann::json j = plant_model_to_json(report);
    EXPECT_EQ(j["format"], "servotwin.plant-model/1");
    EXPECT_EQ(j["model"]["type"], "two-mass");
    EXPECT_EQ(j["modes"].size(), 2u);
    EXPECT_EQ(j["modes"][0]["kind"], "antiresonance");
    EXPECT_GT(j["modes"][1]["freq_hz_std"].get<double>(), 0.0);
    ASSERT_FALSE(j["physical"].is_null());
    // Im = 1/K' (C3.12), K' the mechanics' high-frequency gain: with a lag 1/(s + τ2) the model's
    // gain also carries the lag's τ2, K' = K/τ2. Reference: the plant the data were made from
    // (K = 0.5, τ2 = 40 rad/s: Im = 80, else 2), within what the 1 % ripple moves the fitted gain.
    const double im_true = lag ? 40.0 / 0.5 : 1.0 / 0.5;
    EXPECT_NEAR(j["physical"]["motor_inertia"].get<double>(), im_true, 0.02 * im_true);
    if (lag) {
      // Its std is that of ln K − ln τ2 (delta method on θ's covariance), read here from the
      // written covariance by name.
      const auto& names = report.result.parameter_names;
      const auto at = [&](const char* n) { return std::find(names.begin(), names.end(), n) - names.begin(); };
      const auto g = at("ln_gain"), p = at("ln_lag_pole");
      ASSERT_LT(static_cast<std::size_t>(p), names.size());
      const Eigen::MatrixXd& c = report.result.covariance;
      const double var = c(g, g) + c(p, p) - 2.0 * c(g, p);
      const fit::Estimate& im = report.result.physical.parameters->motor_inertia;
      EXPECT_NEAR(im.std, im.value * std::sqrt(var), 1e-9 * im.std);
      // Not the std of ln K alone: the gain and the lag pole are strongly correlated here.
      EXPECT_GT(std::abs(im.std - im.value * std::sqrt(c(g, g))), 0.05 * im.std);
    }
    EXPECT_EQ(j["fit"]["points"], 40);
    EXPECT_EQ(j["selection"]["method"], "fixed");
    const LoadedPlantModel back = parse_plant_model_json(j.dump(), "model.json");
    const fit::PlantModel& a = report.result.model;
    const fit::PlantModel& b = back.model;
    EXPECT_EQ(b.lag_pole_rad_s.has_value(), lag);
    for (double w : core::log_space(0.01, 100.0, 30))
      EXPECT_LT(std::abs(a.response(w) - b.response(w)), 1e-12 * std::abs(a.response(w))) << w;
    ASSERT_TRUE(back.physical);
    EXPECT_NEAR(back.physical->stiffness.value, report.result.physical.parameters->stiffness.value, 1e-12);
  }
}

std::string error_of(const std::string& text) {
  try {
    parse_plant_model_json(text, "m.json");
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PlantModelJson, ErrorsNameTheField) {
  nlohmann::json j = plant_model_to_json(e10_report(false));
  auto with = [&](auto edit) {
    nlohmann::json copy = j;
    edit(copy);
    return error_of(copy.dump());
  };
  EXPECT_NE(with([](auto& c) { c["format"] = "servotwin.plant-model/2"; }).find("unsupported version"), std::string::npos);
  EXPECT_NE(with([](auto& c) { c["model"].erase("gain"); }).find("model.gain"), std::string::npos);
  EXPECT_NE(with([](auto& c) { c["modes"][1]["kind"] = "resonanse"; }).find("modes[1].kind"), std::string::npos);
  EXPECT_NE(with([](auto& c) { c["modes"][0]["zeta"] = -0.1; }).find("modes[0].zeta"), std::string::npos);
  EXPECT_NE(with([](auto& c) { c["model"]["output"] = "torque"; }).find("model.output"), std::string::npos);
  EXPECT_NE(with([](auto& c) { c["model"]["numerator"][0] = 7.0; }).find("model.numerator"), std::string::npos);
  EXPECT_NE(with([](auto& c) { c["model"]["extra"] = 1; }).find("unknown field"), std::string::npos);
  EXPECT_NE(error_of("{\"format\": ").find("m.json"), std::string::npos);
  EXPECT_THROW(load_plant_model("/nonexistent/plant.json"), core::InputError);
}

}  // namespace plant_model_json_test
}  // namespace
}  // namespace servotwin::io
