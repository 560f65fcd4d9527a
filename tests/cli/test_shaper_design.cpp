// `servotwin shaper design`: JSON output (servotwin.shaper/1) against the catalog's printed E35
// shaper and the closed-form MZV; bad input gives exit status 3 naming the value.
#include <nlohmann/json.hpp>

#include <cmath>
#include <numbers>

#include "cli_support.hpp"

namespace servotwin::cli_test {
namespace {

using ShaperDesign = Cli;

TEST_F(ShaperDesign, Zv4GantryCraneJson) {
  // E35 is printed for ωn = 4.22 rad/s: pass it as Hz = 4.22/(2π).
  const double f = 4.22 / (2.0 * std::numbers::pi);
  const Result r = run("shaper design --type zv4 --freq-hz " + std::to_string(f) +
                       " --zeta 0.0079 --p1 0.3 --p2 0.5 --ts 0.001 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("format"), "servotwin.shaper/1");
  EXPECT_EQ(j.at("type"), "zv4");
  const std::vector<double> t = j.at("times_s"), a = j.at("amplitudes");
  const std::vector<double> t_expected = {0.0, 0.5956, 1.1912, 1.7867}, a_expected = {0.1424, 0.3654, 0.3582, 0.1341};
  ASSERT_EQ(t.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(t[i], t_expected[i], 1e-4);
    EXPECT_NEAR(a[i], a_expected[i], 5e-5);
  }
  EXPECT_LT(j.at("residual_at_design").get<double>(), 1e-12);
  EXPECT_EQ(j.at("ts"), 0.001);
  EXPECT_EQ(j.at("parameters").at("p1"), 0.3);
}

TEST_F(ShaperDesign, MzvMatchesClosedForm) {
  const Result r = run("shaper design --type mzv --freq-hz 50 --zeta 0.1 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const double df = std::sqrt(1.0 - 0.01);
  const double k = std::exp(-0.75 * 0.1 * std::numbers::pi / df);
  const double a1 = 1.0 - 1.0 / std::sqrt(2.0), a2 = (std::sqrt(2.0) - 1.0) * k, a3 = a1 * k * k;
  const double sum = a1 + a2 + a3;
  EXPECT_NEAR(j.at("amplitudes")[0].get<double>(), a1 / sum, 1e-12);
  EXPECT_NEAR(j.at("amplitudes")[1].get<double>(), a2 / sum, 1e-12);
  EXPECT_NEAR(j.at("times_s")[2].get<double>(), 0.75 / (50.0 * df), 1e-12);
  EXPECT_NEAR(j.at("duration_s").get<double>(), 0.75 / (50.0 * df), 1e-12);
  EXPECT_TRUE(j.at("robustness").contains("smoothing"));
}

TEST_F(ShaperDesign, EveryTypeAndTextOutput) {
  for (const char* type : {"zv", "zvd", "zvdd", "ei", "2hump_ei", "3hump_ei"}) {
    const Result r = run(std::string("shaper design --type ") + type + " --freq-hz 50 --zeta 0.1 --json");
    ASSERT_EQ(r.status, 0) << type << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out).at("type"), type);
  }
  const Result text = run("shaper design --type zv4 --preset zvd --freq-hz 10 --zeta 0.05");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("3 impulses"), std::string::npos);
  const Result file = run("shaper design --type zv --freq-hz 10 --zeta 0 -o s.json");
  ASSERT_EQ(file.status, 0) << file.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(path("s.json"))).at("amplitudes")[0], 0.5);
}

TEST_F(ShaperDesign, BadInputNamesTheValue) {
  const auto expect_bad = [&](const std::string& args, const std::string& needle) {
    const Result r = run("shaper design " + args);
    EXPECT_EQ(r.status, 3) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  };
  expect_bad("--type zv --freq-hz 500 --zeta 0.1 --ts 0.001", "Nyquist");
  expect_bad("--type zv --freq-hz 600 --zeta 0.1 --ts 0.001", "--freq-hz");
  expect_bad("--type zv --freq-hz 50 --zeta 1.2", "1.2");
  expect_bad("--type zv --freq-hz 50 --zeta -0.1", "--zeta");
  expect_bad("--type zv4 --freq-hz 50 --zeta 0.1 --p1 1.5", "p1");
  expect_bad("--type zv4 --freq-hz 50 --zeta 0.1 --p2 1", "p2");
  expect_bad("--type zv4 --freq-hz 50 --zeta 0.1 --p1 0.3 --p3 0.2", "p3");
  expect_bad("--type mzv --freq-hz 50 --zeta 0.1 --p1 0.3", "--p1");
  expect_bad("--type zz --freq-hz 50 --zeta 0.1", "zz");
  EXPECT_EQ(run("shaper design --type zv --zeta 0.1").status, 2);  // missing --freq-hz: usage error
}

}  // namespace
}  // namespace servotwin::cli_test
