// Pole placement + Kalman filter + ZPETC design against scipy (tools/reference/
// machine_reference.py: place_poles, solve_discrete_are, cont2discrete) and against the thesis's
// printed Table 4.2 values.

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "machine_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/machine/pole_placement.hpp"
#include "servotwin/machine/presets.hpp"

namespace servotwin::machine {
namespace {

using test::reference;

const AxisConfig& ballscrew_axis() {
  static const AxisConfig axis = preset("ballscrew-zpetc").axes[0];
  return axis;
}

PolePlacementDesign design(int delay) {
  const AxisConfig& a = ballscrew_axis();
  return design_pole_placement(a.plant, std::get<PolePlacementController>(a.controller), 1e-3, delay);
}

void expect_vector_near(const Eigen::VectorXd& got, const nlohmann::json& want, double rel, const char* what) {
  ASSERT_EQ(static_cast<std::size_t>(got.size()), want.size()) << what;
  double scale = 0.0;
  for (const auto& w : want) scale = std::max(scale, std::abs(w.get<double>()));
  for (Eigen::Index i = 0; i < got.size(); ++i)
    EXPECT_NEAR(got(i), want[static_cast<std::size_t>(i)].get<double>(), rel * std::max(scale, 1e-300))
        << what << "[" << i << "]";
}

TEST(PolePlacement, BallscrewPlantReproducesTheThesisZero) {
  // Preset B/J solved from Table 4.2's z1 = -0.99937; scipy's cont2discrete model agrees.
  const auto& ref = reference()["ballscrew"]["delay0"];
  const double bj = ballscrew_axis().plant.damping / ballscrew_axis().plant.inertia;
  EXPECT_NEAR(bj, ref["damping_over_inertia"].get<double>(), 1e-9 * bj);
  const PolePlacementDesign d = design(0);
  EXPECT_NEAR(d.plant_zero, -0.99937, 1e-12);
  EXPECT_NEAR(d.plant_zero, ref["plant_zero"].get<double>(), 1e-12);
}

TEST(PolePlacement, PlacesTheThesisPoles) {
  for (int delay : {0, 1}) {
    const PolePlacementDesign d = design(delay);
    // Table 4.2: p1,2 = 0.86846 +- j0.11762 (wn = 30 Hz, zeta = 0.7 at ts = 1 ms).
    int found = 0;
    for (const auto& p : d.controller_poles) {
      if (std::abs(p - std::complex<double>(0.86846, 0.11762)) < 0.5e-5) ++found;
      if (std::abs(p - std::complex<double>(0.86846, -0.11762)) < 0.5e-5) ++found;
      if (delay == 1 && std::abs(p) < 1e-6) ++found;
    }
    EXPECT_EQ(found, 2 + delay);
    const auto& ref = reference()["ballscrew"][delay == 0 ? "delay0" : "delay1"];
    expect_vector_near(d.feedback.transpose(), ref["feedback"], 1e-8, "L");
    EXPECT_NEAR(d.reference_gain / ref["reference_gain"].get<double>(), 1.0, 1e-8);
    expect_vector_near(Eigen::Map<const Eigen::VectorXd>(d.closed_loop_den.data(),
                                                         static_cast<Eigen::Index>(d.closed_loop_den.size())),
                       ref["closed_loop_den"], 1e-12, "A(z)");
  }
}

TEST(PolePlacement, KalmanFilterMatchesScipyDare) {
  for (int delay : {0, 1}) {
    const PolePlacementDesign d = design(delay);
    const auto& ref = reference()["ballscrew"][delay == 0 ? "delay0" : "delay1"];
    expect_vector_near(d.kalman_gain, ref["kalman_gain"], 1e-8, "M");
    const auto& p_ref = ref["covariance"];
    for (Eigen::Index i = 0; i < d.covariance.rows(); ++i) {
      for (Eigen::Index j = 0; j < d.covariance.cols(); ++j) {
        const double want = p_ref[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)].get<double>();
        const double scale = std::sqrt(std::abs(d.covariance(i, i) * d.covariance(j, j)));
        EXPECT_NEAR(d.covariance(i, j), want, 1e-7 * scale + 1e-300) << i << "," << j;
      }
    }
    std::vector<double> radii;
    for (const auto& p : d.observer_poles) radii.push_back(std::abs(p));
    std::sort(radii.begin(), radii.end());
    const auto want = test::to_vector(ref["observer_poles_abs"]);
    ASSERT_EQ(radii.size(), want.size());
    for (std::size_t i = 0; i < radii.size(); ++i) EXPECT_NEAR(radii[i], want[i], 1e-7);
    EXPECT_GT(d.riccati_iterations, 0);
    EXPECT_LT(d.riccati_iterations, 40);  // doubling: quadratic convergence
  }
}

TEST(PolePlacement, ZpetcTapsMatchReference) {
  for (int delay : {0, 1}) {
    const PolePlacementDesign d = design(delay);
    const auto& ref = reference()["ballscrew"][delay == 0 ? "delay0" : "delay1"];
    EXPECT_EQ(d.preview, ref["preview"].get<int>());
    EXPECT_EQ(d.preview, 2 + delay);  // thesis: preview 2 (relative degree 1 + one zero near -1)
    expect_vector_near(Eigen::Map<const Eigen::VectorXd>(d.zpetc_taps.data(),
                                                         static_cast<Eigen::Index>(d.zpetc_taps.size())),
                       ref["zpetc_taps"], 1e-8, "taps");
    double sum = 0.0;
    for (double t : d.zpetc_taps) sum += t;
    EXPECT_NEAR(sum * d.reference_gain * d.plant_numerator_gain * (1 - d.plant_zero), [&] {
      double a1 = 0.0;
      for (double c : d.closed_loop_den) a1 += c;
      return a1;
    }(), 1e-12);  // unit DC gain: F(1) N n(1) = A(1)
  }
}

TEST(PolePlacement, RiccatiSolverSolvesTheEquation) {
  // A small textbook case with a known closed form: scalar random walk observed in noise,
  // P = (q + sqrt(q^2 + 4 q r)) / 2 for A = C = 1.
  for (double q : {1e-6, 1.0, 1e4}) {
    const double r = 1.0;
    const RiccatiSolution s = solve_filter_riccati(Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1),
                                                   Eigen::MatrixXd::Constant(1, 1, q), Eigen::MatrixXd::Ones(1, 1));
    EXPECT_NEAR(s.P(0, 0), 0.5 * (q + std::sqrt(q * q + 4 * q * r)), 1e-12 * s.P(0, 0)) << q;
    EXPECT_LT(s.residual, 1e-12);
  }
  // An unstable mode that is not observed has no stabilizing solution.
  Eigen::MatrixXd a(2, 2);
  a << 1.5, 0.0, 0.0, 0.5;
  Eigen::MatrixXd c(1, 2);
  c << 0.0, 1.0;
  EXPECT_THROW(solve_filter_riccati(a, c, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Ones(1, 1)),
               core::InputError);
}

TEST(PolePlacement, DesignDoesNotDependOnTheLengthUnit) {
  // Same drive in metres: J [N s^2/m] = 1000 J [N s^2/mm]; gains per metre = 1000 x per mm.
  const AxisConfig& mm = ballscrew_axis();
  RigidPlant m = mm.plant;
  m.inertia *= 1000.0;
  m.damping *= 1000.0;
  PolePlacementController c = std::get<PolePlacementController>(mm.controller);
  c.kalman_process_noise *= 1e-6;      // (mm/s^2)^2/s -> (m/s^2)^2/s
  c.kalman_measurement_noise *= 1e-6;  // mm^2 -> m^2
  const PolePlacementDesign a = design(0);
  const PolePlacementDesign b = design_pole_placement(m, c, 1e-3, 0);
  EXPECT_NEAR(b.feedback(0) / (1000.0 * a.feedback(0)), 1.0, 1e-10);
  EXPECT_NEAR(b.feedback(1) / (1000.0 * a.feedback(1)), 1.0, 1e-10);
  EXPECT_NEAR(b.reference_gain / (1000.0 * a.reference_gain), 1.0, 1e-10);
  for (Eigen::Index i = 0; i < a.kalman_gain.size(); ++i)
    EXPECT_NEAR(b.kalman_gain(i) / a.kalman_gain(i), 1.0, 1e-8) << i;  // dimensionless per state
  EXPECT_NEAR(b.disturbance_gain / (1000.0 * a.disturbance_gain), 1.0, 1e-12);
}

}  // namespace
}  // namespace servotwin::machine
