// Statistics and model files of rapid identification: exact round trips, adding files up, and
// errors that name the file and field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>

#include <filesystem>
#include <fstream>

#include "servotwin/core/error.hpp"
#include "servotwin/io/rapid_json.hpp"

namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace rapid_json_test {

using servotwin::core::InputError;
using ::testing::HasSubstr;
namespace rapid = servotwin::rapid;
namespace io = servotwin::io;

// A well-posed problem: 8 regressors of a small synthetic data set (the numbers themselves are
// arbitrary; the tests check exact transport, not identification).
rapid::NormalEquations sample_equations(double ts = 0.001) {
  Eigen::Matrix<double, 40, 9> data;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 9; ++j) data(i, j) = std::sin(0.37 * i * (j + 1) + 0.1 * j) + (i == j ? 2.0 : 0.0);
  const Eigen::Matrix<double, 40, 8> phi = data.leftCols<8>();
  const Eigen::Matrix<double, 40, 1> y = data.col(8);
  rapid::NormalEquations ne;
  ne.P = phi.transpose() * phi;
  ne.R = phi.transpose() * y;
  ne.gamma = y.squaredNorm();
  ne.n = 40;
  ne.ts = ts;
  return ne;
}

std::string error_of(const std::string& text) {
  try {
    io::parse_normal_equations_json(text, "s.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(RapidJson, NormalEquationsRoundTripExactlyInTheIssuesShape) {
  const rapid::NormalEquations ne = sample_equations();
  const nlohmann::json j = io::normal_equations_to_json(ne, "x", {"capture.csv"});
  EXPECT_EQ(j["format"], "servotwin.normal-equations/1");
  EXPECT_EQ(j["regressors"], nlohmann::json({"e_i", "-xdot", "-xddot", "x_r", "xdot_r", "xddot_r", "-PV", "-NV"}));
  EXPECT_EQ(j["P"].size(), 8U);
  EXPECT_EQ(j["P"][0].size(), 8U);
  std::string axis;
  const rapid::NormalEquations back = io::parse_normal_equations_json(j.dump(), "s.json", &axis);
  EXPECT_EQ(axis, "x");
  EXPECT_EQ(back.P, ne.P);
  EXPECT_EQ(back.R, ne.R);
  EXPECT_EQ(back.gamma, ne.gamma);
  EXPECT_EQ(back.n, ne.n);
  EXPECT_EQ(back.ts, ne.ts);
}

TEST(RapidJson, StatisticsFilesAddUp) {
  const auto dir = std::filesystem::temp_directory_path() / ("servotwin-stats-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const rapid::NormalEquations a = sample_equations();
  rapid::NormalEquations b = sample_equations();
  b.P *= 2.0;
  b.R *= 2.0;
  b.gamma *= 2.0;
  std::ofstream(dir / "a.json") << io::normal_equations_to_json(a, "x").dump();
  std::ofstream(dir / "b.json") << io::normal_equations_to_json(b, "x").dump();
  const io::LoadedStatistics sum = io::load_statistics({(dir / "a.json").string(), (dir / "b.json").string()});
  const rapid::NormalEquations total = sum.problem.normal_equations();
  EXPECT_EQ(sum.axis, "x");
  EXPECT_EQ(total.n, 80U);
  // Sum of the two: 3x the first (relative rounding of the factor round trip).
  EXPECT_LT((total.P - 3.0 * a.P).norm(), 1e-11 * a.P.norm());
  EXPECT_LT((total.R - 3.0 * a.R).norm(), 1e-11 * a.R.norm());
  EXPECT_NEAR(total.gamma, 3.0 * a.gamma, 1e-11 * a.gamma);

  std::ofstream(dir / "c.json") << io::normal_equations_to_json(sample_equations(0.002), "x").dump();
  try {
    io::load_statistics({(dir / "a.json").string(), (dir / "c.json").string()});
    ADD_FAILURE() << "different Ts accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("c.json"));
  }
  std::ofstream(dir / "y.json") << io::normal_equations_to_json(a, "y").dump();
  try {
    io::load_statistics({(dir / "a.json").string(), (dir / "y.json").string()});
    ADD_FAILURE() << "different axes accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("axis 'y'"));
  }
  std::filesystem::remove_all(dir);
}

TEST(RapidJson, StatisticsErrorsNameTheField) {
  nlohmann::json j = io::normal_equations_to_json(sample_equations());
  auto broken = j;
  broken["regressors"][3] = "xr";
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("s.json (regressors[3]): expected \"x_r\""));
  broken = j;
  broken["P"][2].erase(1);
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("(P[2]): expected an array of 8 elements"));
  broken = j;
  broken["P"][2][5] = "x";
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("(P[2][5]): expected a number"));
  broken = j;
  broken["N"] = 2.5;
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("(N)"));
  broken = j;
  broken["Ts"] = 0;
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("(Ts)"));
  broken = j;
  broken.erase("Gamma");
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("(Gamma): missing required field"));
  broken = j;
  broken["format"] = "servotwin.normal-equations/2";
  EXPECT_THAT(error_of(broken.dump()), HasSubstr("unsupported version"));
}

/// An exact identification with thesis Table 3.4's "Estimated" Y coefficients, 1 kHz.
servotwin::vcnc::AxisIdentification table34_identification(const std::string& axis) {
  servotwin::vcnc::AxisIdentification r;
  r.axis = axis;
  r.ts = 0.001;
  r.bounds = rapid::default_bounds(r.ts);
  r.solution.coefficients = {123.02, 40099.88, 146558.19, -0.08, 123.16, 40089.20, 478.0, -428.0};
  r.solution.theta = rapid::theta_from_coefficients(r.solution.coefficients);
  r.solution.method = rapid::Method::Exact;
  return r;
}

TEST(RapidJson, ModelFileRoundTripsTheCoefficients) {
  servotwin::vcnc::AxisIdentification r = table34_identification("y");
  r.fit = rapid::FitMetrics{1.0, 0.9, 0.1, 0.3, 0.1};
  const nlohmann::json j = io::axis_model_to_json(r);
  EXPECT_EQ(j["format"], "servotwin.axis-model/1");
  for (const char* key : {"model", "search", "poles", "zeros", "bounds", "active_constraints", "objective", "fit", "solver"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["solver"]["method"], "exact");
  EXPECT_TRUE(j["fit"].contains("rms"));
  EXPECT_TRUE(j["fit"].contains("nrmse"));
  const io::LoadedAxisModel back = io::parse_axis_model_json(j.dump(), "m.json");
  EXPECT_EQ(back.axis, "y");
  EXPECT_EQ(back.model.ts(), 0.001);
  EXPECT_EQ(back.model.coefficients().a3, 146558.19);
  EXPECT_EQ(back.model.coefficients().d1, -428.0);
  EXPECT_EQ(back.method, "exact");
}

TEST(RapidJson, RefinedModelFileHoldsTheRefinedModelAndTheSolversBeside) {
  servotwin::vcnc::AxisIdentification r = table34_identification("x");
  rapid::Refinement f;
  f.coefficients = {130.0, 41000.0, 150000.0, -0.05, 128.0, 41010.0, 470.0, -420.0};
  f.p = 3.7;
  f.wn = 200.0;
  f.zeta = 0.3;
  f.initial_cost = 2.0;
  f.cost = 0.5;
  f.iterations = 7;
  f.simulations = 70;
  f.converged = true;
  f.stop_reason = "relative cost reduction below tolerance";
  f.active = {{"zeta_min", 0.25}};
  r.refinement = f;
  r.solver_fit = rapid::FitMetrics{1.0, 0.9, 0.2, 0.3, 0.2};
  r.fit = rapid::FitMetrics{1.0, 0.95, 0.1, 0.2, 0.1};
  const nlohmann::json j = io::axis_model_to_json(r);
  EXPECT_EQ(j["model"]["a2"], 41000.0);  // what predict simulates: the refined model
  EXPECT_NEAR(j["search"]["wn_hz"].get<double>(), 200.0 / (2.0 * std::numbers::pi), 1e-12);
  EXPECT_NEAR(j["theta"]["alpha_2"].get<double>(), 1.0 / 41000.0, 1e-18);
  const auto& refinement = j["refinement"];
  EXPECT_EQ(refinement["method"], "output-error");
  EXPECT_EQ(refinement["solver_model"]["a2"], 40099.88);
  EXPECT_EQ(refinement["iterations"], 7);
  EXPECT_EQ(refinement["active_constraints"][0]["name"], "zeta_min");
  EXPECT_EQ(refinement["solver_fit"]["nrmse"], 0.2);
  EXPECT_EQ(j["fit"]["nrmse"], 0.1);
  const io::LoadedAxisModel back = io::parse_axis_model_json(j.dump(), "m.json");
  EXPECT_EQ(back.model.coefficients().a2, 41000.0);
  EXPECT_EQ(back.model.coefficients().d1, -420.0);
}

TEST(RapidJson, ModelFileErrors) {
  const auto err = [](const std::string& text) {
    try {
      io::parse_axis_model_json(text, "m.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": "x", "ts": 0.001, "model": {"a1": 1}})"),
              HasSubstr("(model.a2): missing required field"));
  EXPECT_THAT(err(R"({"format": "servotwin.machine/1"})"), HasSubstr("expected \"servotwin.axis-model/1\""));
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": "x", "ts": -1,
                     "model": {"a1": 1, "a2": 1, "a3": 1, "b0": 0, "b1": 0, "b2": 1, "d0": 0, "d1": 0}})"),
              HasSubstr("(ts)"));
  // Issue 27 §3.15: unknown members, axes that are none of the machine's, and a member given twice
  // (nlohmann keeps the last) are errors.
  const std::string coefficients = R"("model": {"a1": 1, "a2": 1, "a3": 1, "b0": 0, "b1": 0, "b2": 1, "d0": 0, "d1": 0})";
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": "x", "ts": 0.001, "colour": 1, )" + coefficients + "}"),
              HasSubstr("m.json (colour): unknown field"));
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": "q", "ts": 0.001, )" + coefficients + "}"),
              HasSubstr("m.json (axis): expected an axis name x, y, z, a, b or c, found \"q\""));
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": ")" + std::string(1000000, 'x') + R"(", "ts": 0.001, )" +
                  coefficients + "}"),
              HasSubstr("(1000000 characters)"));
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": "x", "ts": 0.001, )" + coefficients + R"(, "ts": 0.002})"),
              HasSubstr("m.json (ts): the member is given twice"));
  EXPECT_THAT(err(R"({"format": "servotwin.axis-model/1", "axis": "x", "ts": 0.001,
                     "model": {"a1": 1, "a2": 1, "a3": 1, "b0": 0, "b1": 0, "b2": 1, "d0": 0, "d1": 0, "a1": 2}})"),
              HasSubstr("m.json (model.a1): the member is given twice"));
  // The same key in two objects is no duplicate.
  EXPECT_EQ(err(R"({"format": "servotwin.axis-model/1", "axis": "x", "ts": 0.001, "fit": {"rms": 1},
                   "validation": {"rms": 2}, )" + coefficients + "}"),
            "no error");
}

}  // namespace rapid_json_test
}  // namespace
