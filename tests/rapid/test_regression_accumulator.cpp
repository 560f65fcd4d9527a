// The streaming accumulator on realistic captures (random trapezoidal moves driving the closed
// loop of thesis Eq. 3.3 with friction and an encoder): independence of the chunking, the factor
// against a dense QR of the same rows, merging against stacking, invariance to the length unit,
// the physics of the columns (the simulated axis's own parameters are recovered), and per-axis
// problems of a capture.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/rapid/regression.hpp"
#include "test_regression_support.hpp"

namespace servotwin::rapid {
namespace {

/// 22 s at 1 kHz (the thesis's experiment), 0.1 um encoder: built once.
const test::SyntheticCapture& thesis_capture() {
  static const test::SyntheticCapture capture = [] {
    test::CaptureSettings s;
    s.resolution = 1e-4;
    return test::simulate_capture(s);
  }();
  return capture;
}

RegressionProblem streamed(const test::SyntheticCapture& c, const RegressorOptions& o, std::size_t chunk,
                           RegressionDiagnostics* diag = nullptr) {
  RegressorAccumulator acc(c.ts, o);
  for (std::size_t i = 0; i < c.command.size(); i += chunk) {
    const std::size_t n = std::min(chunk, c.command.size() - i);
    acc.add(std::span(c.command).subspan(i, n), std::span(c.actual).subspan(i, n));
  }
  RegressionProblem p = acc.finish();
  if (diag != nullptr) *diag = acc.diagnostics();
  return p;
}

TEST(RegressionAccumulator, ChunkSizeDoesNotChangeTheResult) {
  const test::SyntheticCapture& c = thesis_capture();
  RegressorOptions o;  // automatic deadband: its estimation window must not depend on chunks either
  o.command_shift = 2;
  o.trim_start = 50;
  o.trim_end = 30;
  RegressionDiagnostics reference_diag;
  const RegressionProblem reference = streamed(c, o, c.command.size(), &reference_diag);
  EXPECT_EQ(reference.samples(), 22'000u - 2u - 4u - 80u);
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{256}, std::size_t{4099}}) {
    RegressionDiagnostics diag;
    const RegressionProblem p = streamed(c, o, chunk, &diag);
    EXPECT_EQ(p.factor(), reference.factor()) << "chunk " << chunk;  // bit-identical
    EXPECT_EQ(p.samples(), reference.samples());
    EXPECT_EQ(diag.positive_rows, reference_diag.positive_rows);
    EXPECT_EQ(diag.negative_rows, reference_diag.negative_rows);
    EXPECT_EQ(diag.velocity_deadband, reference_diag.velocity_deadband);
  }
}

TEST(RegressionAccumulator, FactorMatchesADenseQrOfTheRows) {
  const test::SyntheticCapture& c = thesis_capture();
  RegressionDiagnostics diag;
  const RegressionProblem p = build_problem(c.command, c.actual, c.ts, {}, &diag);
  const Eigen::MatrixXd rows = regressor_matrix(c.command, c.actual, c.ts);
  ASSERT_EQ(static_cast<std::uint64_t>(rows.rows()), p.samples());
  // Canonical factors (diagonal >= 0) of a full-rank matrix are unique: compare row by row
  // relative to each row's diagonal.
  const Matrix9 expected = test::dense_factor(rows);
  for (int i = 0; i <= kParameterCount; ++i) {
    EXPECT_LT((p.factor().row(i) - expected.row(i)).norm(), 1e-9 * expected.row(i).norm()) << "row " << i;
  }
  const Eigen::MatrixXd gram = rows.transpose() * rows;
  EXPECT_LT(test::gram_difference(p.normal_equations(), gram), 1e-12);
  // Realistic data exercise everything: both directions, a deadband from the encoder.
  EXPECT_GT(diag.positive_rows, 5000u);
  EXPECT_GT(diag.negative_rows, 5000u);
  EXPECT_TRUE(diag.warnings.empty());
}

TEST(RegressionAccumulator, MergeEqualsStackedRowsWithTheIntegralRestartedPerCapture) {
  test::CaptureSettings slow;
  slow.samples = 5000;
  slow.v_max = 50.0;
  slow.resolution = 1e-4;
  test::CaptureSettings fast = slow;
  fast.samples = 7000;
  fast.v_max = 200.0;
  fast.seed = 99;
  const test::SyntheticCapture a = test::simulate_capture(slow);
  const test::SyntheticCapture b = test::simulate_capture(fast);
  RegressionProblem merged = build_problem(a.command, a.actual, a.ts);
  merged.merge(build_problem(b.command, b.actual, b.ts));

  const Eigen::MatrixXd rows_a = regressor_matrix(a.command, a.actual, a.ts);
  const Eigen::MatrixXd rows_b = regressor_matrix(b.command, b.actual, b.ts);
  Eigen::MatrixXd stacked(rows_a.rows() + rows_b.rows(), kParameterCount + 1);
  stacked << rows_a, rows_b;
  EXPECT_EQ(merged.samples(), static_cast<std::uint64_t>(stacked.rows()));
  EXPECT_LT(test::gram_difference(merged.normal_equations(), stacked.transpose() * stacked), 1e-12);
  // The second capture's integral starts from its own first sample (pairs 0..2 at its first row).
  const double ei_b = b.ts * ((b.command[0] - b.actual[0]) + (b.command[1] - b.actual[1]) + (b.command[2] - b.actual[2]));
  EXPECT_NEAR(rows_b(0, 0), ei_b, 1e-15);

  // Not the same as one capture of the concatenated samples (e_i and stencils cross the seam).
  std::vector<double> cmd = a.command, act = a.actual;
  cmd.insert(cmd.end(), b.command.begin(), b.command.end());
  act.insert(act.end(), b.actual.begin(), b.actual.end());
  const RegressionProblem joined = build_problem(cmd, act, a.ts);
  EXPECT_GT(test::gram_difference(joined.normal_equations(), stacked.transpose() * stacked), 1e-6);
}

TEST(RegressionAccumulator, ExportedStatisticsRoundTripAndAddUp) {
  // The exchange format keeps P, R, Gamma only; re-factoring them must give the same model. The
  // equilibrated regressors have a condition number of a few hundred here, so the Gram route
  // loses about 5 digits of the 16: 1e-9 is a safe bound.
  const test::SyntheticCapture& c = thesis_capture();
  const RegressionProblem direct = build_problem(c.command, c.actual, c.ts);
  const RegressionProblem imported = RegressionProblem::from_normal_equations(direct.normal_equations());
  const Vector8 a = test::least_squares(direct);
  const Vector8 b = test::least_squares(imported);
  for (int j = 0; j < kParameterCount; ++j) EXPECT_NEAR(b(j), a(j), 1e-9 * std::abs(a(j))) << j;
  EXPECT_NEAR(imported.objective(a), direct.objective(a), 1e-9 * direct.objective(a));

  // Statistics of two captures add up (what concatenating exported files does) to the merge.
  test::CaptureSettings s;
  s.samples = 6000;
  s.seed = 3;
  s.resolution = 1e-4;
  const test::SyntheticCapture other = test::simulate_capture(s);
  const RegressionProblem second = build_problem(other.command, other.actual, other.ts);
  NormalEquations sum = direct.normal_equations();
  const NormalEquations add = second.normal_equations();
  sum.P += add.P;
  sum.R += add.R;
  sum.gamma += add.gamma;
  sum.n += add.n;
  RegressionProblem merged = direct;
  merged.merge(second);
  const Vector8 from_sum = test::least_squares(RegressionProblem::from_normal_equations(sum));
  const Vector8 from_merge = test::least_squares(merged);
  for (int j = 0; j < kParameterCount; ++j) EXPECT_NEAR(from_sum(j), from_merge(j), 1e-9 * std::abs(from_merge(j))) << j;
  EXPECT_EQ(merged.samples(), sum.n);
}

TEST(RegressionAccumulator, SameModelInMetresMillimetresAndMicrometres) {
  const test::SyntheticCapture& c = thesis_capture();
  RegressorOptions o;
  o.command_shift = 1;
  RegressionDiagnostics d_mm, d_m, d_um;
  const Vector8 mm = test::least_squares(build_problem(c.command, c.actual, c.ts, o, &d_mm));
  const Vector8 m = test::least_squares(
      build_problem(test::scaled(c.command, 1e-3), test::scaled(c.actual, 1e-3), c.ts, o, &d_m));
  const Vector8 um = test::least_squares(
      build_problem(test::scaled(c.command, 1e3), test::scaled(c.actual, 1e3), c.ts, o, &d_um));
  EXPECT_EQ(d_m.positive_rows, d_mm.positive_rows);
  EXPECT_EQ(d_um.positive_rows, d_mm.positive_rows);
  EXPECT_EQ(d_m.negative_rows, d_mm.negative_rows);
  EXPECT_EQ(d_um.negative_rows, d_mm.negative_rows);
  EXPECT_NEAR(d_m.velocity_deadband, 1e-3 * d_mm.velocity_deadband, 1e-12 * d_mm.velocity_deadband);
  // alpha and beta are unit-free; the friction offsets delta are lengths.
  const double unit_of[kParameterCount] = {1, 1, 1, 1, 1, 1, 1e-3, 1e-3};
  for (int j = 0; j < kParameterCount; ++j) {
    const std::string name(kRegressorNames[static_cast<std::size_t>(j)]);
    EXPECT_NEAR(m(j), unit_of[j] * mm(j), 1e-8 * std::abs(unit_of[j] * mm(j))) << name;
    EXPECT_NEAR(um(j), mm(j) / unit_of[j], 1e-8 * std::abs(mm(j) / unit_of[j])) << name;
  }
}

TEST(RegressionAccumulator, RecoversTheParametersOfASimulatedAxis) {
  // Without friction and at 10 kHz, Eq. 3.9 holds up to the O(ts) of the rectangle-rule
  // integral and the O(ts^2) of the stencils: the least-squares parameters must be those of
  // the simulated axis (a wrong sign or column order would be off by 100 % or more).
  test::CaptureSettings s;
  s.ts = 1e-4;
  s.samples = 100'000;
  s.substeps = 4;
  s.axis.d0 = s.axis.d1 = 0.0;
  const test::SyntheticCapture c = test::simulate_capture(s);
  const Vector8 theta = test::least_squares(build_problem(c.command, c.actual, c.ts));
  const Vector8 truth = s.axis.theta();
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(theta(j), truth(j), 5e-3 * std::abs(truth(j))) << kRegressorNames[static_cast<std::size_t>(j)];
  }
  EXPECT_LT(std::abs(theta(6)), 1e-4);
  EXPECT_LT(std::abs(theta(7)), 1e-4);

  // With Coulomb friction (and a 1 kHz, 0.1 um encoder capture) the friction offsets come out
  // with the right sign and size (the friction model's stick-slip is not in Eq. 3.3: ~10 %).
  const Vector8 with_friction = test::least_squares(build_problem(thesis_capture().command,
                                                                  thesis_capture().actual, thesis_capture().ts));
  const Vector8 truth_friction = test::pid_axis().theta();
  EXPECT_NEAR(with_friction(6), truth_friction(6), 0.2 * std::abs(truth_friction(6)));
  EXPECT_NEAR(with_friction(7), truth_friction(7), 0.2 * std::abs(truth_friction(7)));
}

TEST(RegressionAccumulator, EveryAxisOfACaptureIndependently) {
  test::CaptureSettings sx;
  sx.samples = 3000;
  sx.resolution = 1e-4;
  test::CaptureSettings sy = sx;
  sy.seed = 5;
  sy.range = 4.0;
  const test::SyntheticCapture x = test::simulate_capture(sx);
  const test::SyntheticCapture y = test::simulate_capture(sy);
  core::Capture capture;
  capture.ts = 1e-3;
  capture.axes.push_back({"x", x.command, x.actual, {}});
  capture.axes.push_back({"y", y.command, y.actual, {}});
  RegressorOptions o;
  o.command_shift = 2;
  const std::vector<AxisProblem> problems = build_problems(capture, o);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].axis, "x");
  EXPECT_EQ(problems[1].axis, "y");
  RegressionDiagnostics dy;
  EXPECT_EQ(problems[0].problem.factor(), build_problem(x.command, x.actual, 1e-3, o).factor());
  EXPECT_EQ(problems[1].problem.factor(), build_problem(y.command, y.actual, 1e-3, o, &dy).factor());
  EXPECT_EQ(problems[1].diagnostics.positive_rows, dy.positive_rows);
  EXPECT_NE(problems[0].diagnostics.velocity_deadband, 0.0);

  capture.axes[1].act[17] = NAN;
  try {
    (void)build_problems(capture, o);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "y_act");
    EXPECT_THAT(e.what(), ::testing::HasSubstr("axis y: sample 17 is not finite"));
  }
}

}  // namespace
}  // namespace servotwin::rapid
