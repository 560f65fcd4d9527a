// End-to-end tests of `servotwin frf estimate`: the FdiTools multisine recording (README numbers),
// an H1 run on a generated file, --force, and bad input (exit status 3 naming file and column,
// nothing written) or bad usage (status 2).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include "cli_support.hpp"
#include "servotwin/io/frf_csv.hpp"

namespace {

using servotwin::cli_test::Cli;
using servotwin::cli_test::slurp;
using ::testing::HasSubstr;

const std::string kFdiTools = std::string(SERVOTWIN_REPO_DATA_DIR) + "/twomass-motor-bench-fditools/";

class FrfEstimate : public Cli {};

TEST_F(FrfEstimate, MultisineOnTheFdiToolsRecording) {
  const auto r = run("frf estimate '" + kFdiTools +
                     "MultisineTypeA.csv' --input iq_adx --response theta_mx --method multisine --periods 20 "
                     "--skip-periods 1 -o frf.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("50000 samples at 2500 Hz (from time_us)"));
  EXPECT_THAT(r.err, HasSubstr("period 2500 samples, 19 periods used (1 skipped"));
  EXPECT_THAT(r.err, HasSubstr("240 excited lines"));
  EXPECT_THAT(r.out, HasSubstr("frf: 240 points, 11 ... 250 Hz"));
  const std::string text = slurp(path("frf.csv"));
  EXPECT_EQ(text.rfind("# format: servotwin.frf/1\n# quality: coherence\n# duration_s: 20\n", 0), 0u) << text.substr(0, 200);
  const auto frf = servotwin::io::read_frf_file(path("frf.csv").string());
  ASSERT_EQ(frf.size(), 240u);
  EXPECT_EQ(frf.points.front().freq_hz, 11.0);
  EXPECT_EQ(*frf.duration_s, 20.0);
  // README: motor-side antiresonance ≈ 53 Hz.
  double min_mag = 1e300, at = 0.0;
  for (const auto& p : frf.points)
    if (p.freq_hz > 40.0 && p.freq_hz < 65.0 && std::abs(p.value) < min_mag) {
      min_mag = std::abs(p.value);
      at = p.freq_hz;
    }
  EXPECT_EQ(at, 53.0);

  // The file exists now: refused without --force (nothing changed), replaced with it.
  const auto again = run("frf estimate '" + kFdiTools +
                         "MultisineTypeB.csv' --input iq_adx --response theta_mx --method multisine --periods 20 -o frf.csv");
  EXPECT_EQ(again.status, 3);
  EXPECT_THAT(again.err, HasSubstr("frf.csv"));
  EXPECT_EQ(slurp(path("frf.csv")), text);
  const auto forced = run("frf estimate '" + kFdiTools +
                          "MultisineTypeB.csv' --input iq_adx --response theta_mx --method multisine --periods 20 "
                          "--skip-periods 1 -o frf.csv -f -q");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_EQ(forced.err, "");  // --quiet
  EXPECT_EQ(servotwin::io::read_frf_file(path("frf.csv").string()).size(), 60u);
}

/// White noise through y[n] = 0.5 x[n] + 0.5 x[n−1] (+ small noise), no time column.
std::string noise_record(std::size_t n) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> gauss;
  std::ostringstream out;
  out << "u,y\n";
  double previous = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double u = gauss(rng);
    out << u << ',' << 0.5 * u + 0.5 * previous + 0.01 * gauss(rng) << '\n';
    previous = u;
  }
  return out.str();
}

TEST_F(FrfEstimate, H1WithSampleRateOption) {
  write("rec.csv", noise_record(8192));
  const auto r = run("frf estimate rec.csv --fs 1000 --input u --response y --segment 512 --fmax-hz 400 -o h1.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("(--fs)"));
  EXPECT_THAT(r.err, HasSubstr("31 segments of 512 samples"));
  const auto frf = servotwin::io::read_frf_file(path("h1.csv").string());
  ASSERT_EQ(frf.size(), 204u);  // lines 1 … 204 of 512 at 1.953125 Hz are <= 400 Hz
  for (const auto& p : frf.points) {
    // Closed form: H(f) = 0.5 + 0.5 e^{−j2πf/fs}.
    const std::complex<double> truth =
        0.5 + 0.5 * std::exp(std::complex<double>(0.0, -2.0 * std::numbers::pi * p.freq_hz / 1000.0));
    EXPECT_LT(std::abs(p.value - truth), 5.0 * p.std_dev + 1e-3) << p.freq_hz;
  }
  EXPECT_THAT(slurp(path("h1.csv")), HasSubstr("# method: h1 (Welch), segment 512 samples, hann window"));
}

TEST_F(FrfEstimate, BadInputExitsWithThreeAndNamesWhere) {
  write("rec.csv", "t,u,y,c\n0,1,2,5\n0.001,2,1,5\n0.002,0,3,5\n0.0035,1,1,5\n0.004,2,2,5\n");
  auto r = run("frf estimate rec.csv --input iq --response y -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("rec.csv:1 (iq): missing column 'iq' (columns: t, u, y, c)"));
  r = run("frf estimate rec.csv --input u --response y -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("rec.csv:5 (t): non-uniform sampling"));

  write("even.csv", "t,u,y,c\n0,1,2,5\n0.001,2,1,5\n0.002,0,3,5\n0.003,1,1,5\n");
  r = run("frf estimate even.csv --input c --response y -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("column 'c' is constant"));
  r = run("frf estimate even.csv --input u --response y -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("even.csv (u): at least 16 samples"));

  write("nan.csv", "t,u,y\n0,1,2\n0.001,nan,1\n");
  r = run("frf estimate nan.csv --input u --response y -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("nan.csv:3:7: column 'u'"));

  write("rec2.csv", noise_record(400));
  r = run("frf estimate rec2.csv --fs 100 --input u --response y --method multisine -o out.csv");
  EXPECT_EQ(r.status, 3);
  // White noise has no period to detect (the periodic estimator needs one).
  EXPECT_THAT(r.err, HasSubstr("(--period): no period found in the input"));
  r = run("frf estimate rec2.csv --fs 100 --input u --response y --method multisine --periods 4 -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--periods): the input does not repeat every 100 samples"));
  r = run("frf estimate rec2.csv --fs 100 --input u --response y --segment 8 -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--segment)"));
  EXPECT_FALSE(std::filesystem::exists(path("out.csv")));

  // Usage errors: unknown method, missing required option, missing sub-subcommand.
  EXPECT_EQ(run("frf estimate rec2.csv --fs 100 --input u --response y --method h2 -o out.csv").status, 2);
  EXPECT_EQ(run("frf estimate rec2.csv --fs 100 --input u -o out.csv").status, 2);
  EXPECT_EQ(run("frf").status, 2);
  // Issue 25 §7: -o/--output names only files; the response column moved to --response, and an
  // old invocation (--output COL beside -o FILE) is refused with a pointer to it.
  r = run("frf estimate rec2.csv --fs 100 --input u --output y -o out.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("use --response COL"));
  r = run("frf estimate rec2.csv --fs 100 --input u --response y --segment 64 --fmax 40 --output h1b.csv");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("note: --fmax is now spelled --fmax-hz"));
  EXPECT_TRUE(std::filesystem::exists(path("h1b.csv")));
}

}  // namespace

namespace {

/// r white, u = 2 (r − y_m), y_m = P u + v with P = (0.05 z⁻¹ + 0.02 z⁻²)/(1 − 1.6 z⁻¹ + 0.9 z⁻²):
/// the loop of tests/frf/test_offline_closed_loop.cpp, as a drive would log it.
std::string closed_loop_record(std::size_t n) {
  std::mt19937 rng(4);
  std::normal_distribution<double> white(0.0, 1.0);
  std::ostringstream text;
  text.precision(17);
  text << "t,r,u,y\n";
  double u1 = 0, u2 = 0, y1 = 0, y2 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double r = white(rng);
    const double y = 0.05 * u1 + 0.02 * u2 + 1.6 * y1 - 0.9 * y2;
    const double measured = y + 0.3 * white(rng);
    const double u = 2.0 * (r - measured);
    text << static_cast<double>(k) * 1e-3 << ',' << r << ',' << u << ',' << measured << '\n';
    u2 = u1;
    u1 = u;
    y2 = y1;
    y1 = y;
  }
  return text.str();
}

TEST_F(FrfEstimate, ClosedLoopIndirectMethod) {
  write("loop.csv", closed_loop_record(65536));
  auto r = run("frf estimate loop.csv --closed-loop --reference r --input u --response y --segment 1024 -o cl.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = slurp(path("cl.csv"));
  EXPECT_THAT(text, HasSubstr("reference: r (closed loop, indirect method)"));
  EXPECT_THAT(text, HasSubstr("method: closed loop, indirect S_ry/S_ru (Welch)"));
  const auto closed = servotwin::io::read_frf_file(path("cl.csv").string());
  // Near DC the plant is P(1) = 0.07/0.3 = 0.2333 (the loop keeps |S| = 0.68 there).
  EXPECT_NEAR(std::abs(closed.points[1].value), 0.2333, 0.02);
  // A closed-loop record without its reference is bad input (exit 3); --reference alone is a
  // usage error (exit 2).
  r = run("frf estimate loop.csv --closed-loop --input u --response y -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--reference): a closed-loop estimate needs the excited reference column"));
  EXPECT_FALSE(std::filesystem::exists(path("x.csv")));
  EXPECT_EQ(run("frf estimate loop.csv --reference r --input u --response y -o x.csv").status, 2);
  r = run("frf estimate loop.csv --closed-loop --reference nope --input u --response y -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("missing column 'nope'"));
}

}  // namespace
