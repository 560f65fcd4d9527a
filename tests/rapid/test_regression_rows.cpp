// Regressor rows: columns against a direct dense construction written from the documented
// conventions (exact on dyadic data), command shift and trim semantics, the integrated error,
// direction flags and the automatic deadband on quantized and noisy data, warnings, bad input.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/regression.hpp"
#include "test_regression_support.hpp"

namespace servotwin::rapid {
namespace {

using ::testing::HasSubstr;

/// The rows of thesis Eq. 3.9-3.11 built the obvious way, straight from the header's conventions.
Eigen::MatrixXd direct_rows(const std::vector<double>& cmd, const std::vector<double>& act, double ts, int shift,
                            std::size_t trim_start, std::size_t trim_end, double deadband) {
  std::vector<double> r, x;
  const auto n = static_cast<long long>(cmd.size());
  for (long long k = 0; k < n; ++k) {
    const long long j = k + shift;
    if (j < 0 || j >= n) continue;
    r.push_back(cmd[static_cast<std::size_t>(j)]);
    x.push_back(act[static_cast<std::size_t>(k)]);
  }
  const std::size_t m = x.size();
  std::vector<double> ei(m);
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    sum += r[k] - x[k];
    ei[k] = ts * sum;
  }
  auto vel = [ts](const std::vector<double>& s, std::size_t k) { return (s[k + 1] - s[k - 1]) / (2.0 * ts); };
  std::vector<std::vector<double>> rows;
  for (std::size_t k = 2; k + 2 < m; ++k) {
    const double xd = vel(x, k);
    const double xdd = (vel(x, k + 1) - vel(x, k - 1)) / (2.0 * ts);
    const double rd = vel(r, k);
    const double rdd = (vel(r, k + 1) - vel(r, k - 1)) / (2.0 * ts);
    const double band = deadband * (1.0 + 1e-9);  // velocities within 1e-9 of the deadband are inside it
    rows.push_back({ei[k], -xd, -xdd, r[k], rd, rdd, xd > band ? -1.0 : 0.0, xd < -band ? -1.0 : 0.0, x[k]});
  }
  const std::size_t begin = std::min(trim_start, rows.size());
  const std::size_t end = rows.size() - std::min(trim_end, rows.size() - begin);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(end - begin), kParameterCount + 1);
  for (std::size_t i = begin; i < end; ++i) {
    for (int j = 0; j <= kParameterCount; ++j) {
      out(static_cast<Eigen::Index>(i - begin), j) = rows[i][static_cast<std::size_t>(j)];
    }
  }
  return out;
}

/// Positions on a dyadic grid (integers * 2^-12) and ts = 2^-10: every difference, stencil,
/// product with 1/(2 ts) and partial sum is exact, so any correct construction agrees bit for bit.
struct DyadicCapture {
  double ts = std::ldexp(1.0, -10);
  std::vector<double> cmd, act;
};

DyadicCapture dyadic_capture(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> step(-40, 40);
  std::uniform_int_distribution<int> lag(-6, 6);
  DyadicCapture c;
  long long r = 0;
  for (std::size_t k = 0; k < n; ++k) {
    r += step(rng);
    c.cmd.push_back(std::ldexp(static_cast<double>(r), -12));
    c.act.push_back(std::ldexp(static_cast<double>(r + lag(rng)), -12));
  }
  return c;
}

TEST(RegressionRows, ColumnsEqualTheDirectConstructionExactly) {
  const DyadicCapture c = dyadic_capture(300, 1);
  RegressorOptions o;
  o.velocity_deadband = 3.0;
  const Eigen::MatrixXd rows = regressor_matrix(c.cmd, c.act, c.ts, o);
  const Eigen::MatrixXd expected = direct_rows(c.cmd, c.act, c.ts, 0, 0, 0, 3.0);
  ASSERT_EQ(rows.rows(), 296);  // 2 rows lost at each end
  EXPECT_EQ(rows, expected);
  // Both directions occur, so the friction columns are exercised.
  EXPECT_GT((rows.col(6).array() != 0.0).count(), 10);
  EXPECT_GT((rows.col(7).array() != 0.0).count(), 10);
}

TEST(RegressionRows, ColumnsEqualTheDirectConstructionOnRealisticData) {
  // ts = 1 ms is not dyadic: the library multiplies by 1/(2 ts), the direct code divides; the
  // integrated error is compensated in the library. Agreement to a few ulp of each column.
  test::CaptureSettings s;
  s.samples = 3000;
  s.resolution = 1e-4;
  const test::SyntheticCapture c = test::simulate_capture(s);
  RegressorOptions o;
  o.velocity_deadband = 0.3;
  const Eigen::MatrixXd rows = regressor_matrix(c.command, c.actual, c.ts, o);
  const Eigen::MatrixXd expected = direct_rows(c.command, c.actual, c.ts, 0, 0, 0, 0.3);
  ASSERT_EQ(rows.rows(), expected.rows());
  for (int j = 0; j <= kParameterCount; ++j) {
    const double scale = expected.col(j).cwiseAbs().maxCoeff();
    EXPECT_LE((rows.col(j) - expected.col(j)).cwiseAbs().maxCoeff(), 1e-13 * scale) << "column " << j;
  }
}

TEST(RegressionRows, IntegratedErrorStartsAtTheFirstSampleAndIncludesTheCurrentOne) {
  // x_r - x = 1 at every sample: e_i,k = ts (k + 1) for pair k; the first row is pair 2.
  std::vector<double> cmd(20, 1.0), act(20, 0.0);
  const double ts = 0.25;
  RegressorOptions o;
  o.velocity_deadband = 0.0;
  const Eigen::MatrixXd rows = regressor_matrix(cmd, act, ts, o);
  ASSERT_EQ(rows.rows(), 16);
  for (Eigen::Index i = 0; i < rows.rows(); ++i) EXPECT_EQ(rows(i, 0), ts * static_cast<double>(i + 3));
  // Trims drop rows but do not restart the integral.
  o.trim_start = 4;
  const Eigen::MatrixXd trimmed = regressor_matrix(cmd, act, ts, o);
  EXPECT_EQ(trimmed(0, 0), ts * 7.0);
}

TEST(RegressionRows, CommandShiftPairsLaterCommandSamples) {
  const DyadicCapture c = dyadic_capture(200, 2);
  RegressorOptions o;
  o.velocity_deadband = 3.0;
  for (const int shift : {2, 5, -3}) {
    o.command_shift = shift;
    const Eigen::MatrixXd rows = regressor_matrix(c.cmd, c.act, c.ts, o);
    EXPECT_EQ(rows, direct_rows(c.cmd, c.act, c.ts, shift, 0, 0, 3.0)) << "shift " << shift;
    ASSERT_EQ(rows.rows(), 200 - std::abs(shift) - 4);
    // First row: pair 2 = (cmd[2 + shift], act[2]) for shift >= 0, (cmd[2], act[2 - shift]) otherwise.
    const std::size_t cmd_index = shift >= 0 ? static_cast<std::size_t>(2 + shift) : 2;
    const std::size_t act_index = shift >= 0 ? 2 : static_cast<std::size_t>(2 - shift);
    EXPECT_EQ(rows(0, 3), c.cmd[cmd_index]);
    EXPECT_EQ(rows(0, kParameterCount), c.act[act_index]);
  }
}

TEST(RegressionRows, TrimsDropRowsAtBothEnds) {
  const DyadicCapture c = dyadic_capture(200, 3);
  RegressorOptions o;
  o.velocity_deadband = 3.0;
  o.command_shift = 2;
  const Eigen::MatrixXd all = regressor_matrix(c.cmd, c.act, c.ts, o);
  o.trim_start = 17;
  o.trim_end = 9;
  const Eigen::MatrixXd trimmed = regressor_matrix(c.cmd, c.act, c.ts, o);
  ASSERT_EQ(trimmed.rows(), all.rows() - 26);
  EXPECT_EQ(trimmed, all.middleRows(17, all.rows() - 26));
  EXPECT_EQ(trimmed, direct_rows(c.cmd, c.act, c.ts, 2, 17, 9, 3.0));
}

TEST(RegressionRows, FactorOfTheRowsIsTheProblem) {
  const DyadicCapture c = dyadic_capture(1000, 4);
  RegressorOptions o;
  o.velocity_deadband = 3.0;
  const RegressionProblem problem = build_problem(c.cmd, c.act, c.ts, o);
  const Eigen::MatrixXd rows = regressor_matrix(c.cmd, c.act, c.ts, o);
  const Matrix9 expected = test::dense_factor(rows);
  EXPECT_LT((problem.factor() - expected).norm(), 1e-13 * expected.norm());
  EXPECT_EQ(problem.samples(), 996u);
}

// ------------------------------------------------------------------------------------------
// Direction flags and the deadband
// ------------------------------------------------------------------------------------------

/// Encoder counts: a standstill, a positive ramp (one single count, then `counts_per_sample`), a
/// standstill, a negative ramp, a standstill; with `toggle`, the standstills flicker between two
/// adjacent counts (the typical encoder jitter). The command follows without jitter.
struct QuantizedProfile {
  std::vector<double> cmd, act;
};

QuantizedProfile quantized_profile(double q, int counts_per_sample, bool toggle, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> flicker(0, 1);
  QuantizedProfile p;
  long long level = 1000;
  auto standstill = [&](int n) {
    for (int i = 0; i < n; ++i) {
      p.cmd.push_back(q * static_cast<double>(level));
      p.act.push_back(q * static_cast<double>(level + (toggle ? flicker(rng) : 0)));
    }
  };
  auto ramp = [&](int n, int direction) {
    for (int i = 0; i < n; ++i) {
      level += direction * (i == 0 ? 1 : counts_per_sample);
      p.cmd.push_back(q * static_cast<double>(level));
      p.act.push_back(q * static_cast<double>(level));
    }
  };
  standstill(300);
  ramp(200, +1);
  standstill(300);
  ramp(200, -1);
  standstill(300);
  return p;
}

// Dyadic q and ts keep the direct construction bit-exact.
constexpr double kCount = 1.0 / 8192.0;  // about 0.12 um in mm
constexpr double kDyadicTs = 1.0 / 1024.0;

TEST(RegressionRows, AutomaticDeadbandFromTheEncoderResolution) {
  const double q = kCount;
  const double ts = kDyadicTs;
  // Exact standstills (no noise): the deadband is 1.25 q / ts, between 2 and 3 counts over the
  // stencil. A ramp of 1 count per sample (2 counts over the stencil) is not motion ...
  QuantizedProfile slow = quantized_profile(q, 1, false, 5);
  RegressionDiagnostics diag;
  Eigen::MatrixXd rows = regressor_matrix(slow.cmd, slow.act, ts, {}, &diag);
  EXPECT_TRUE(diag.deadband_automatic);
  EXPECT_NEAR(diag.position_resolution, q, 1e-12 * q);
  EXPECT_EQ(diag.velocity_noise, 0.0);
  EXPECT_NEAR(diag.velocity_deadband, 1.25 * q / ts, 1e-9 * q / ts);
  EXPECT_EQ(diag.positive_rows + diag.negative_rows, 0u);
  // ... 2 counts per sample are: over the stencil, a ramp's first row sees 1 + 2 counts, its
  // inner rows 4, its last row 2 (and the standstill row before it 1): 199 rows per ramp.
  QuantizedProfile fast = quantized_profile(q, 2, false, 5);
  rows = regressor_matrix(fast.cmd, fast.act, ts, {}, &diag);
  EXPECT_EQ(diag.position_resolution, q);
  EXPECT_EQ(diag.velocity_deadband, 1.25 * q / ts);
  EXPECT_EQ(rows, direct_rows(fast.cmd, fast.act, ts, 0, 0, 0, diag.velocity_deadband));
  EXPECT_EQ(diag.positive_rows, 199u);
  EXPECT_EQ(diag.negative_rows, 199u);
}

TEST(RegressionRows, AutomaticDeadbandSuppressesEncoderJitter) {
  const double q = kCount;
  const double ts = kDyadicTs;
  // Standstills flicker between two counts: second differences 0, q, 2q with probabilities
  // 1/4, 1/2, 1/4, so the median is q and sigma_v = 1.4826 q / (sqrt(12) ts); the deadband
  // 4 sigma_v = 1.71 q / ts exceeds 1.25 q / ts.
  const QuantizedProfile p = quantized_profile(q, 2, true, 6);
  RegressionDiagnostics diag;
  const Eigen::MatrixXd rows = regressor_matrix(p.cmd, p.act, ts, {}, &diag);
  EXPECT_NEAR(diag.position_resolution, q, 1e-12 * q);
  const double sigma_v = 1.4826 * q / (std::sqrt(12.0) * ts);
  EXPECT_NEAR(diag.velocity_noise, sigma_v, 1e-9 * sigma_v);
  EXPECT_NEAR(diag.velocity_deadband, 4.0 * sigma_v, 1e-9 * sigma_v);
  EXPECT_EQ(rows, direct_rows(p.cmd, p.act, ts, 0, 0, 0, diag.velocity_deadband));
  // Only ramp rows are flagged (4 counts over the stencil; 2 to 4 at a ramp's ends, depending on
  // the flicker), never a standstill row.
  EXPECT_NEAR(static_cast<double>(diag.positive_rows), 199.0, 1.0);
  EXPECT_NEAR(static_cast<double>(diag.negative_rows), 199.0, 1.0);
  // Without a deadband the flicker flags many standstill rows.
  RegressorOptions none;
  none.velocity_deadband = 0.0;
  RegressionDiagnostics raw;
  (void)build_problem(p.cmd, p.act, ts, none, &raw);
  EXPECT_GT(raw.positive_rows, 400u);
  EXPECT_FALSE(raw.deadband_automatic);
  EXPECT_EQ(raw.velocity_deadband, 0.0);
}

TEST(RegressionRows, DeadbandWindowStartsAtTheFirstMotion) {
  const double q = 1e-3;
  const double ts = 1e-3;
  // 500 samples at rest (exactly constant), then moves in steps of 1 count: the window starts
  // at the motion, so q is found although the first 500 samples show no step at all.
  std::vector<double> act(500, 2.0);
  for (int i = 1; i <= 200; ++i) act.push_back(2.0 + q * i);
  const std::vector<double> cmd(act.size(), 2.0);
  RegressorOptions o;
  o.deadband_window = 64;
  RegressionDiagnostics diag;
  (void)build_problem(cmd, act, ts, o, &diag);
  EXPECT_NEAR(diag.position_resolution, q, 1e-12);
  // The window is the first 64 pairs from the motion: steps of 5 counts there, single counts
  // only later, so q is 5 counts.
  std::vector<double> act2(100, 0.0);
  for (int i = 1; i <= 100; ++i) act2.push_back(5.0 * q * i);
  for (int i = 1; i <= 100; ++i) act2.push_back(act2.back() + q);
  const std::vector<double> cmd2(act2.size(), 0.0);
  (void)build_problem(cmd2, act2, ts, o, &diag);
  EXPECT_NEAR(diag.position_resolution, 5.0 * q, 1e-12);
  EXPECT_NEAR(diag.velocity_deadband, 1.25 * 5.0 * q / ts, 1e-9);
}

TEST(RegressionRows, AutomaticDeadbandFromVelocityNoise) {
  // Unquantized white noise sigma_x at standstill: velocity noise sigma_x / (sqrt(2) ts).
  const double ts = 1e-3;
  const double sigma = 2e-4;
  std::mt19937_64 rng(6);
  std::normal_distribution<double> normal(0.0, sigma);
  std::vector<double> cmd, act;
  for (int k = 0; k < 3000; ++k) {
    cmd.push_back(5.0);
    act.push_back(5.0 + normal(rng));
  }
  for (int k = 1; k <= 500; ++k) {  // then a move at 20 mm/s
    cmd.push_back(5.0 + 0.02 * k);
    act.push_back(5.0 + 0.02 * k + normal(rng));
  }
  RegressionDiagnostics diag;
  (void)build_problem(cmd, act, ts, {}, &diag);
  const double sigma_v = sigma / (std::sqrt(2.0) * ts);
  EXPECT_NEAR(diag.velocity_noise, sigma_v, 0.06 * sigma_v);  // MAD of ~4000 samples: ~2 % error
  EXPECT_NEAR(diag.velocity_deadband, 4.0 * diag.velocity_noise, 1e-12);
  // The 498 rows of the move (and perhaps the one at its start) are flagged; standstill rows
  // only with probability P(|N(0,1)| > 4) = 6e-5 each.
  EXPECT_GE(diag.positive_rows, 498u);
  EXPECT_LE(diag.positive_rows + diag.negative_rows, 499u + 2u);
}

TEST(RegressionRows, ExplicitDeadbandIsUsed) {
  const QuantizedProfile p = quantized_profile(kCount, 2, true, 7);
  RegressorOptions o;
  o.velocity_deadband = 2.1 * kCount / kDyadicTs;  // 4.2 counts over the stencil: the ramps (4) are not motion
  RegressionDiagnostics diag;
  (void)build_problem(p.cmd, p.act, kDyadicTs, o, &diag);
  EXPECT_FALSE(diag.deadband_automatic);
  EXPECT_EQ(diag.velocity_deadband, *o.velocity_deadband);
  EXPECT_EQ(diag.positive_rows, 0u);
  EXPECT_EQ(diag.negative_rows, 0u);
}

// ------------------------------------------------------------------------------------------
// Diagnostics and warnings
// ------------------------------------------------------------------------------------------

TEST(RegressionRows, WarnsWhenADirectionNeverOccurs) {
  std::vector<double> cmd, act;
  for (int k = 0; k < 200; ++k) {
    cmd.push_back(0.01 * k);
    act.push_back(0.01 * k - 0.001);
  }
  RegressorOptions o;
  o.velocity_deadband = 0.5;
  RegressionDiagnostics diag;
  (void)build_problem(cmd, act, 1e-3, o, &diag);
  EXPECT_EQ(diag.negative_rows, 0u);
  EXPECT_EQ(diag.positive_rows, 196u);
  EXPECT_THAT(diag.warnings, ::testing::ElementsAre("no motion in the negative direction: delta- not identifiable"));
  EXPECT_EQ(diag.samples, 200u);
  EXPECT_NEAR(diag.command_range, 1.99, 1e-12);
  EXPECT_NEAR(diag.actual_range, 1.99, 1e-12);

  for (double& v : cmd) v = -v;
  for (double& v : act) v = -v;
  (void)build_problem(cmd, act, 1e-3, o, &diag);
  EXPECT_THAT(diag.warnings, ::testing::ElementsAre("no motion in the positive direction: delta+ not identifiable"));
}

TEST(RegressionRows, WarnsAboutNoMotionAndConstantCommand) {
  const std::vector<double> still(100, 3.0);
  RegressionDiagnostics diag;
  (void)build_problem(still, still, 1e-3, {}, &diag);
  EXPECT_THAT(diag.warnings, ::testing::ElementsAre(HasSubstr("no motion at all"), HasSubstr("command is constant")));

  // Motion smaller than the deadband only.
  std::vector<double> creep;
  for (int k = 0; k < 100; ++k) creep.push_back(1e-6 * k);
  RegressorOptions o;
  o.velocity_deadband = 0.01;
  (void)build_problem(creep, creep, 1e-3, o, &diag);
  EXPECT_THAT(diag.warnings, ::testing::ElementsAre(HasSubstr("no motion beyond the velocity deadband")));
  EXPECT_TRUE(diag.warnings.size() == 1);
}

TEST(RegressionRows, AccumulatorDiagnosticsAreAvailableWhileStreaming) {
  const DyadicCapture c = dyadic_capture(2000, 8);
  RegressorOptions o;
  o.velocity_deadband = 3.0;
  RegressorAccumulator acc(c.ts, o);
  acc.add(std::span(c.cmd).first(1000), std::span(c.act).first(1000));
  EXPECT_EQ(acc.diagnostics().rows, 996u);  // row k needs sample k + 2: rows 2..997 so far
  acc.add(std::span(c.cmd).subspan(1000), std::span(c.act).subspan(1000));
  const RegressionProblem p = acc.finish();
  EXPECT_EQ(acc.diagnostics().rows, 1996u);
  EXPECT_EQ(p.samples(), 1996u);
}

// ------------------------------------------------------------------------------------------
// Bad input
// ------------------------------------------------------------------------------------------

template <typename F>
core::InputError expect_input_error(F&& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected core::InputError";
  return core::InputError("none");
}

TEST(RegressionRows, NonFiniteSamplesNameTheirIndex) {
  DyadicCapture c = dyadic_capture(500, 9);
  c.act[123] = std::numeric_limits<double>::quiet_NaN();
  core::InputError e = expect_input_error([&] { (void)build_problem(c.cmd, c.act, c.ts); });
  EXPECT_EQ(e.where().field, "actual");
  EXPECT_THAT(e.what(), HasSubstr("sample 123 is not finite"));

  // Index within the whole capture, not the chunk; the bad chunk is not added.
  c = dyadic_capture(500, 9);
  std::vector<double> bad_cmd(c.cmd.begin() + 200, c.cmd.begin() + 300);
  bad_cmd[5] = std::numeric_limits<double>::infinity();
  RegressorOptions o;
  o.velocity_deadband = 3.0;
  RegressorAccumulator acc(c.ts, o);
  acc.add(std::span(c.cmd).first(200), std::span(c.act).first(200));
  e = expect_input_error([&] { acc.add(bad_cmd, std::span(c.act).subspan(200, 100)); });
  EXPECT_EQ(e.where().field, "command");
  EXPECT_THAT(e.what(), HasSubstr("sample 205 is not finite"));
  acc.add(std::span(c.cmd).subspan(200), std::span(c.act).subspan(200));
  EXPECT_EQ(acc.finish().factor(), build_problem(c.cmd, c.act, c.ts, o).factor());
}

TEST(RegressionRows, RejectsUnequalLengthsAndBadPeriods) {
  const DyadicCapture c = dyadic_capture(50, 10);
  core::InputError e =
      expect_input_error([&] { (void)build_problem(c.cmd, std::span(c.act).first(49), c.ts); });
  EXPECT_THAT(e.what(), HasSubstr("equal lengths"));
  for (const double ts : {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    e = expect_input_error([&] { (void)build_problem(c.cmd, c.act, ts); });
    EXPECT_EQ(e.where().field, "Ts");
  }
}

TEST(RegressionRows, TooFewRowsIsAnError) {
  const DyadicCapture c = dyadic_capture(40, 11);
  auto run = [&](std::size_t n, RegressorOptions o) {
    return build_problem(std::span(c.cmd).first(n), std::span(c.act).first(n), c.ts, o);
  };
  RegressorOptions o;
  EXPECT_EQ(run(14, o).samples(), 10u);
  core::InputError e = expect_input_error([&] { (void)run(13, o); });
  EXPECT_THAT(e.what(), HasSubstr("capture too short: 13 samples give 9 regressor rows"));
  EXPECT_THAT(e.what(), HasSubstr("at least 10"));
  o.command_shift = -2;
  EXPECT_EQ(run(16, o).samples(), 10u);
  EXPECT_THROW((void)run(15, o), core::InputError);
  o.trim_start = 3;
  o.trim_end = 4;
  EXPECT_EQ(run(23, o).samples(), 10u);
  EXPECT_THROW((void)run(22, o), core::InputError);
  EXPECT_THROW((void)run(0, o), core::InputError);
  o.trim_start = std::numeric_limits<std::size_t>::max();  // trims everything, no overflow
  EXPECT_THROW((void)run(40, o), core::InputError);
}

TEST(RegressionRows, RejectsInvalidOptions) {
  auto field_of = [](const RegressorOptions& o) {
    return expect_input_error([&] { RegressorAccumulator acc(1e-3, o); }).where().field;
  };
  RegressorOptions o;
  o.velocity_deadband = -1.0;
  EXPECT_EQ(field_of(o), "velocity_deadband");
  o.velocity_deadband = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(field_of(o), "velocity_deadband");
  o = {};
  o.deadband_window = 8;
  EXPECT_EQ(field_of(o), "deadband_window");
  o = {};
  o.trim_end = kMaxDelay + 1;
  EXPECT_EQ(field_of(o), "trim_end");
  o = {};
  o.command_shift = -static_cast<int>(kMaxDelay) - 1;
  EXPECT_EQ(field_of(o), "command_shift");
}

TEST(RegressionRows, UseAfterFinishIsALogicError) {
  const DyadicCapture c = dyadic_capture(50, 12);
  RegressorAccumulator acc(c.ts, {});
  acc.add(c.cmd, c.act);
  (void)acc.finish();
  EXPECT_THROW(acc.add(c.cmd, c.act), std::logic_error);
  EXPECT_THROW((void)acc.finish(), std::logic_error);
}

}  // namespace
}  // namespace servotwin::rapid
