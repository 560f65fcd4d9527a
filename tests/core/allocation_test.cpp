// The per-sample simulation path must not allocate (design.md: everything that runs once per
// sample is allocation-free after construction); counting: tests/malloc_counting.hpp.

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <vector>

#include "malloc_counting.hpp"
#include "servotwin/core/state_space.hpp"

namespace servotwin::core {
namespace {

using test_support::allocations;

DiscreteStateSpace two_mass_discrete() {
  // Two-mass drive of tools/reference/core_reference.py, 4 states, outputs [omega1, theta2].
  const double j1 = 1e-3, j2 = 2e-3, k = 500.0, c = 0.05;
  StateSpace s;
  s.A = Eigen::MatrixXd{{0.0, 1.0, 0.0, 0.0}, {-k / j1, -c / j1, k / j1, c / j1}, {0.0, 0.0, 0.0, 1.0}, {k / j2, c / j2, -k / j2, -c / j2}};
  s.B = Eigen::MatrixXd{{0.0}, {1.0 / j1}, {0.0}, {0.0}};
  s.C = Eigen::MatrixXd{{0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}};
  s.D = Eigen::MatrixXd::Zero(2, 1);
  return discretize_zoh(s, 1e-3);
}

TEST(Allocation, CounterSeesEigenAndStandardAllocations) {
  SKIP_WITHOUT_COUNTING();
  // Without this the tests below could not fail.
  const std::size_t before = allocations();
  {
    std::vector<double> v(100, 1.0);
    Eigen::VectorXd e = Eigen::VectorXd::Ones(100);
    EXPECT_EQ(v.size(), static_cast<std::size_t>(e.size()));
  }
  EXPECT_GE(allocations() - before, 2U);
}

TEST(Allocation, DiscreteSimulatorStepDoesNotAllocate) {
  SKIP_WITHOUT_COUNTING();
  DiscreteSimulator sim(two_mass_discrete());
  double y[2] = {0.0, 0.0};
  const std::size_t before = allocations();
  double sum = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const double u = (k / 10) % 2 == 0 ? 0.05 : -0.05;
    sim.step(std::span<const double>(&u, 1), y);
    sum += y[0] + sim.step(-u);
  }
  sim.reset();
  EXPECT_EQ(allocations() - before, 0U);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(Allocation, BatchSimulationAllocatesIndependentlyOfLength) {
  SKIP_WITHOUT_COUNTING();
  const DiscreteStateSpace d = two_mass_discrete();
  const Eigen::MatrixXd short_u = Eigen::MatrixXd::Constant(10, 1, 0.01);
  const Eigen::MatrixXd long_u = Eigen::MatrixXd::Constant(20000, 1, 0.01);
  std::size_t before = allocations();
  const Eigen::MatrixXd y_short = simulate(d, short_u);
  const std::size_t short_count = allocations() - before;
  before = allocations();
  const Eigen::MatrixXd y_long = simulate(d, long_u);
  EXPECT_EQ(allocations() - before, short_count);
  EXPECT_EQ(y_long.rows(), 20000);
  EXPECT_EQ(y_short.rows(), 10);
}

}  // namespace
}  // namespace servotwin::core
