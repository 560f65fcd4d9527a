// E35 (dissertation sec. 8.1, catalog A1/E35) closed by simulation: the gantry-crane plant of the
// machine module (sway angle over cart velocity, ωn = 4.22 rad/s, ξ = 0.0079, 10 ms) driven by a
// trapezoidal cart-velocity move, unshaped and through the E35 ZV4 shaper (p1 = 0.3, p2 = 0.5)
// running in the real-time shaper.
//
// Independent reference: for a linear plant with a zero-order hold, shaping the sampled command
// with pulses on the sample grid is the continuous shaper with impulses at d_j·Ts applied to the
// held command, so after the move the residual sway is exactly V(discrete shaper) times the
// unshaped residual sway (catalog C6.3's definition of V). The exact discretization (C6.5, E18) has
// V = 0, the rounded one the residual `discretize` reports (referred to a common time): both are
// checked against the simulated sway.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/machine/flexible_presets.hpp"
#include "servotwin/shaping/discretization.hpp"
#include "servotwin/shaping/realtime_shaper.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin {
namespace {

constexpr double kOmega = 4.22, kZeta = 0.0079, kTs = 0.01;

// Cart velocity [m/s]: 0.5 s ramp to 0.5 m/s, 2 s cruise, 0.5 s ramp down, then rest.
std::vector<double> trapezoid_velocity(std::size_t samples) {
  std::vector<double> v(samples, 0.0);
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * kTs;
    if (t < 0.5) v[k] = t;
    else if (t < 2.5) v[k] = 0.5;
    else if (t < 3.0) v[k] = 0.5 - (t - 2.5);
  }
  return v;
}

std::vector<double> simulate_sway(const std::vector<double>& velocity) {
  machine::FlexiblePlant crane(machine::flexible_preset("gantry-crane"));
  std::vector<double> sway;
  sway.reserve(velocity.size());
  for (double v : velocity) sway.push_back(crane.step(v).y_exact);
  return sway;
}

std::vector<double> shaped(const std::vector<double>& velocity, const shaping::DiscreteShaper& discrete) {
  shaping::RealtimeShaper shaper(discrete);
  std::vector<double> out(velocity.size());
  shaper.process(velocity, out);
  return out;
}

// Amplitude of the free sway at time t_ref: after the move the output is exactly
// e^{-σt}(a cos ω_d t + b sin ω_d t) (one mode), fitted by least squares over [t_begin, t_end].
double free_amplitude(const std::vector<double>& sway, double t_begin, double t_end, double t_ref) {
  const double sigma = kZeta * kOmega, omega_d = kOmega * std::sqrt(1.0 - kZeta * kZeta);
  const auto k0 = static_cast<std::size_t>(std::ceil(t_begin / kTs));
  const auto k1 = static_cast<std::size_t>(std::floor(t_end / kTs));
  Eigen::MatrixXd basis(static_cast<Eigen::Index>(k1 - k0), 2);
  Eigen::VectorXd y(basis.rows());
  for (std::size_t k = k0; k < k1; ++k) {
    // sway[k] is the output at (k + 1) Ts.
    const double t = static_cast<double>(k + 1) * kTs - t_ref;
    const auto row = static_cast<Eigen::Index>(k - k0);
    basis(row, 0) = std::exp(-sigma * t) * std::cos(omega_d * t);
    basis(row, 1) = std::exp(-sigma * t) * std::sin(omega_d * t);
    y(row) = sway[k];
  }
  const Eigen::Vector2d ab = basis.colPivHouseholderQr().solve(y);
  return ab.norm();
}

class GantryCraneShaping : public ::testing::Test {
 protected:
  static constexpr std::size_t kSamples = 3000;  // 30 s
  std::vector<double> velocity = trapezoid_velocity(kSamples);
  shaping::Shaper e35 = shaping::zv4_shaper(kOmega, kZeta, {0.3, 0.5, 0.0});
  // After the longest shaped move (3 s + 1.79 s) has ended; 10 s window, amplitude referred to 10 s.
  double unshaped_amplitude = free_amplitude(simulate_sway(velocity), 6.0, 16.0, 10.0);
};

TEST_F(GantryCraneShaping, ExactDiscretizationLeavesNoResidualSway) {
  const shaping::DiscreteShaper exact = shaping::discretize(e35, kTs, shaping::DiscretizationMethod::Exact);
  const double amplitude = free_amplitude(simulate_sway(shaped(velocity, exact)), 6.0, 16.0, 10.0);
  ASSERT_GT(unshaped_amplitude, 0.01);  // the unshaped move leaves > 0.6 degree of sway
  EXPECT_LT(amplitude / unshaped_amplitude, 1e-9);
  // The shaped move still reaches the same cart position (the shaper has unit gain).
  double unshaped_travel = 0.0, shaped_travel = 0.0;
  for (double v : velocity) unshaped_travel += v * kTs;
  for (double v : shaped(velocity, exact)) shaped_travel += v * kTs;
  EXPECT_NEAR(shaped_travel, unshaped_travel, 1e-12);
}

TEST_F(GantryCraneShaping, RoundedDiscretizationLeavesItsReportedResidual) {
  const shaping::DiscreteShaper rounded = shaping::discretize(e35, kTs, shaping::DiscretizationMethod::Round);
  ASSERT_GT(rounded.residual, 1e-4);  // 10 ms rounding of impulses 0.6 s apart is not exact
  const double amplitude = free_amplitude(simulate_sway(shaped(velocity, rounded)), 6.0, 16.0, 10.0);
  // V compares the vibration after the last impulse (t_n) with the unshaped vibration at the first
  // (t = 0); at one common time the shaped sway is smaller than the unshaped by V e^{ζω t_n} (the
  // unshaped sway has decayed over t_n too). 1e-5 relative: least-squares amplitude of a noise-free
  // sampled mode.
  const double expected = rounded.residual * std::exp(kZeta * kOmega * rounded.duration());
  EXPECT_NEAR(amplitude / unshaped_amplitude, expected, 1e-5 * expected);
}

}  // namespace
}  // namespace servotwin
