// `servotwin shaper design`: JSON output (servotwin.shaper/1) against the catalog's printed E35
// shaper and the closed-form MZV; the discrete shaper of --ts and how `apply` uses it; the
// firmware exports (Klipper's [input_shaper] keys, RepRapFirmware's M593 P"custom" H/T in 3.5 and
// 3.6 semantics, io/firmware_shaper.hpp); bad input gives exit status 3 naming the value.
#include <nlohmann/json.hpp>

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>

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
  // With --ts the file holds the discrete shaper (issue 25 §6) and the continuous design (E35).
  const std::vector<double> t = j.at("continuous").at("times_s"), a = j.at("continuous").at("amplitudes");
  const std::vector<double> t_expected = {0.0, 0.5956, 1.1912, 1.7867}, a_expected = {0.1424, 0.3654, 0.3582, 0.1341};
  ASSERT_EQ(t.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(t[i], t_expected[i], 1e-4);
    EXPECT_NEAR(a[i], a_expected[i], 5e-5);
  }
  // Exact vector decomposition: impulses on the 1 ms grid, zero residual kept (C6.5).
  EXPECT_EQ(j.at("discrete"), true);
  EXPECT_EQ(j.at("discretization"), "exact");
  const std::vector<double> td = j.at("times_s");
  const std::vector<std::size_t> samples = j.at("samples");
  ASSERT_EQ(td.size(), samples.size());
  for (std::size_t i = 0; i < td.size(); ++i) EXPECT_NEAR(td[i], 0.001 * static_cast<double>(samples[i]), 1e-15);
  EXPECT_GT(td.size(), 4u);  // off-grid impulses split in two
  EXPECT_LT(j.at("residual_at_design").get<double>(), 1e-12);
  EXPECT_EQ(j.at("ts"), 0.001);
  EXPECT_EQ(j.at("parameters").at("p1"), 0.3);
}

TEST_F(ShaperDesign, DiscreteShapersAreAppliedAsTheyAre) {
  ASSERT_EQ(run("shaper design --type zvd --freq-hz 30.3 --zeta 0.05 --ts 0.001 -o zvd.json").status, 0);
  ASSERT_EQ(run("shaper design --type zvd --freq-hz 30.3 --zeta 0.05 --ts 0.001 --method round -o zvd_round.json").status, 0);
  write("trajectory.csv", "t,x_cmd\n0,0\n0.001,0\n0.002,1\n0.003,2\n0.004,3\n0.005,3\n0.006,3\n0.007,3\n");
  Result r = run("shaper apply zvd.json trajectory.csv -o shaped.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, testing::HasSubstr("(exact discretization, as designed)"));
  r = run("shaper apply zvd_round.json trajectory.csv -o shaped_round.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, testing::HasSubstr("(round discretization, as designed)"));
  // Another grid, or a second discretization, is refused.
  write("slow.csv", "t,x_cmd\n0,0\n0.002,0\n0.004,1\n0.006,2\n");
  r = run("shaper apply zvd.json slow.csv -o s.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, testing::HasSubstr("discrete at ts = 0.001 s but the trajectory's period is 0.002 s"));
  r = run("shaper apply zvd.json trajectory.csv --method round -o s.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, testing::HasSubstr("discrete shaper already"));
  r = run("shaper design --type zvd --freq-hz 30 --zeta 0.05 --method round");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, testing::HasSubstr("--ts"));
}

TEST_F(ShaperDesign, ExportsForFirmwares) {
  Result r = run("shaper design --type mzv --freq-hz 42 --zeta 0.1 --export klipper --export-axis y");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "[input_shaper]\nshaper_type_y: mzv\nshaper_freq_y: 42\ndamping_ratio_y: 0.1\n");
  r = run("shaper design --type zvd --freq-hz 100 --zeta 0 --export rrf -o m593.g");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(slurp(path("m593.g")), testing::HasSubstr("M593 P\"custom\" H0.250000:0.750000 T0.0050000:0.0050000\n"));
  r = run("shaper design --type zvd --freq-hz 100 --zeta 0 --export rrf --rrf-version 3.6");
  EXPECT_THAT(r.out, testing::HasSubstr("H0.250000:0.500000 T0.0050000:0.0100000"));
  r = run("shaper design --type zv4 --preset 2hei5 --freq-hz 42 --zeta 0.05 --export klipper");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, testing::HasSubstr("Klipper has no 'zv4' shaper"));
  r = run("shaper design --type zv --freq-hz 42 --zeta 0.05 --export table --json");
  EXPECT_EQ(r.status, 3);
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
