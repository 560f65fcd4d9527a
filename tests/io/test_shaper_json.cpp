// servotwin.shaper/1 writer and reader. Expected values: the E35 shaper (printed in the catalog)
// round-trips exactly; every malformed document is rejected naming its field.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::io {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace shaper_json_test {

std::string error_of(const std::string& text) {
  try {
    (void)parse_shaper_json(text, "s.json");
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "no error";
}

nlohmann::json good() {
  return {{"format", "servotwin.shaper/1"}, {"type", "zv"},          {"freq_hz", 50.0},
          {"zeta", 0.0},                    {"times_s", {0.0, 0.01}}, {"amplitudes", {0.5, 0.5}}};
}

TEST(ShaperJson, RoundTripsTheGantryCraneShaper) {
  const shaping::Shaper s = shaping::zv4_shaper(4.22, 0.0079, {0.3, 0.5, 0.0});
  ShaperFileExtras extras;
  extras.parameters = {{"p1", 0.3}, {"p2", 0.5}, {"p3", 0.0}};
  extras.ts = 0.001;
  const nlohmann::json j = shaper_to_json(s, extras);
  EXPECT_EQ(j.at("format"), "servotwin.shaper/1");
  EXPECT_NEAR(j.at("freq_hz").get<double>(), 4.22 / (2.0 * std::numbers::pi), 1e-15);
  EXPECT_NEAR(j.at("duration_s").get<double>(), 1.7867, 5e-5);  // E35
  EXPECT_LT(j.at("residual_at_design").get<double>(), 1e-14);
  const LoadedShaper back = parse_shaper_json(j.dump(), "crane.json");
  EXPECT_EQ(back.shaper.type, "zv4");
  EXPECT_NEAR(back.shaper.omega, 4.22, 1e-14);
  EXPECT_EQ(back.shaper.zeta, 0.0079);
  EXPECT_EQ(back.shaper.times, s.times);
  EXPECT_EQ(back.shaper.amplitudes, s.amplitudes);
  EXPECT_EQ(back.extras.parameters.at("p1"), 0.3);
  EXPECT_EQ(*back.extras.ts, 0.001);
}

TEST(ShaperJson, DiscreteShapersKeepTheirGridAndDesign) {
  // A discrete shaper's file: samples consistent with times_s / ts, the continuous design beside.
  nlohmann::json j = good();
  j["times_s"] = {0.0, 0.003};
  j["ts"] = 0.001;
  j["discrete"] = true;
  j["samples"] = {0, 3};
  j["discretization"] = "round";
  j["continuous"] = {{"times_s", {0.0, 0.0031}}, {"amplitudes", {0.5, 0.5}}};
  const LoadedShaper loaded = parse_shaper_json(j.dump(), "d.json");
  ASSERT_TRUE(loaded.extras.discrete.has_value());
  EXPECT_EQ(loaded.extras.discrete->samples, (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(loaded.extras.discrete->discretization, "round");
  EXPECT_EQ(loaded.extras.discrete->continuous.times[1], 0.0031);
  const nlohmann::json back = shaper_to_json(loaded.shaper, loaded.extras);
  EXPECT_EQ(back.at("samples"), j.at("samples"));
  EXPECT_EQ(back.at("continuous"), j.at("continuous"));
  nlohmann::json off = j;
  off["samples"] = {0, 2};
  EXPECT_NE(error_of(off.dump()).find("(samples)"), std::string::npos) << error_of(off.dump());
  nlohmann::json no_ts = j;
  no_ts.erase("ts");
  EXPECT_NE(error_of(no_ts.dump()).find("(ts)"), std::string::npos);
  nlohmann::json method = j;
  method["discretization"] = "nearest";
  EXPECT_NE(error_of(method.dump()).find("(discretization)"), std::string::npos);
}

TEST(ShaperJson, RejectsBadDocumentsNamingTheField) {
  EXPECT_EQ(error_of(good().dump()), "no error");
  auto with = [](const char* key, nlohmann::json value) {
    nlohmann::json j = good();
    j[key] = std::move(value);
    return j.dump();
  };
  EXPECT_NE(error_of(with("format", "servotwin.shaper/2")).find("format"), std::string::npos);
  EXPECT_NE(error_of(with("times_s", {0.001, 0.01})).find("times_s"), std::string::npos);
  EXPECT_NE(error_of(with("times_s", {0.0, 0.0})).find("increasing"), std::string::npos);
  EXPECT_NE(error_of(with("amplitudes", {0.5, 0.6})).find("sum"), std::string::npos);
  EXPECT_NE(error_of(with("amplitudes", {0.5, 0.5, 0.0})).find("amplitudes"), std::string::npos);
  EXPECT_NE(error_of(with("amplitudes", {0.5, "x"})).find("amplitudes"), std::string::npos);
  EXPECT_NE(error_of(with("zeta", 1.0)).find("zeta"), std::string::npos);
  EXPECT_NE(error_of(with("freq_hz", 0.0)).find("freq_hz"), std::string::npos);
  EXPECT_NE(error_of(with("duration_s", 0.02)).find("duration_s"), std::string::npos);
  EXPECT_NE(error_of(with("frequency", 1.0)).find("frequency"), std::string::npos);  // unknown member
  nlohmann::json missing = good();
  missing.erase("amplitudes");
  EXPECT_NE(error_of(missing.dump()).find("amplitudes"), std::string::npos);
  EXPECT_NE(error_of("{\"format\": ").find("s.json"), std::string::npos);
  // Within 1e-9 the sum is accepted.
  EXPECT_EQ(error_of(with("amplitudes", {0.5, 0.5 + 5e-10})), "no error");
}

}  // namespace shaper_json_test
}  // namespace
}  // namespace servotwin::io
