// hinf_norm, peak_on_grid and bandwidth.
//
// Expected values: closed forms (second-order resonance peak 1/(2 zeta sqrt(1 - zeta^2)) at
// omega_n sqrt(1 - 2 zeta^2); first-order bandwidth), and tests/data/core/control_reference.json
// from tools/reference/core_control_reference.py, where the H-infinity norms and the delay-loop
// peak/bandwidth come from a dense frequency grid with bounded scalar refinement (scipy), a method
// independent of the Hamiltonian iteration.

#include "servotwin/core/norms.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/reference_data.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace servotwin::core {
namespace {

using Complex = std::complex<double>;
using test::control_reference;
using test::reference_system;
using test::system_from;
using test::to_matrix;
using test::kInf;

double sigma_max_at(const StateSpace& s, double omega) {
  return Eigen::JacobiSVD<Eigen::MatrixXcd>(frequency_response(s, omega)).singularValues()(0);
}

StateSpace second_order(double wn, double zeta) {
  return to_state_space(TransferFunction(Polynomial{wn * wn}, Polynomial{1.0, 2.0 * zeta * wn, wn * wn}));
}

double resonance_peak(double zeta) { return 1.0 / (2.0 * zeta * std::sqrt(1.0 - zeta * zeta)); }

// ---- hinf_norm -----------------------------------------------------------------------------------

TEST(HinfNorm, MatchesDenseGridReference) {
  for (const auto& c : control_reference().at("hinf")) {
    const std::string name = c.at("system");
    SCOPED_TRACE(name);
    const StateSpace sys = reference_system(name);
    const double expected = c.at("value").get<double>();
    const PeakResult r = hinf_norm(sys);
    // gamma_lb <= norm < (1 + rel_tol) gamma_lb, and the reference is the grid-refined sup.
    EXPECT_LE(std::abs(r.value - expected), 1e-6 * expected);
    if (c.at("omega").is_string()) {
      EXPECT_EQ(r.omega_rad_s, kInf);
    } else {
      const double w = c.at("omega").get<double>();
      if (w == 0.0) {
        EXPECT_EQ(r.omega_rad_s, 0.0);
      } else {
        EXPECT_NEAR(r.omega_rad_s, w, 1e-3 * w);
      }
      // The value is attained at the reported frequency.
      EXPECT_NEAR(sigma_max_at(sys, r.omega_rad_s), r.value, 1e-12 * r.value);
    }
  }
}

TEST(HinfNormBelow, DecidesTheGridReferenceNormAndTheClosedForm) {
  // The bounded-real test must agree with the grid-refined norms of the reference (scipy) just
  // above and just below them, and with the resonance peak's closed form, including peaks far
  // from any pole frequency's probe (lightly damped pairs) and a peak at infinity.
  for (const auto& c : control_reference().at("hinf")) {
    const std::string name = c.at("system");
    SCOPED_TRACE(name);
    const StateSpace sys = reference_system(name);
    const double norm = c.at("value").get<double>();
    EXPECT_TRUE(hinf_norm_below(sys, norm * (1.0 + 1e-5)));
    EXPECT_FALSE(hinf_norm_below(sys, norm * (1.0 - 1e-5)));
  }
  for (const double zeta : {0.001, 0.05, 0.6}) {
    const StateSpace sys = second_order(866.0, zeta);
    EXPECT_TRUE(hinf_norm_below(sys, resonance_peak(zeta) * (1.0 + 1e-8))) << zeta;
    EXPECT_FALSE(hinf_norm_below(sys, resonance_peak(zeta) * (1.0 - 1e-8))) << zeta;
  }
  // Random stable systems against hinf_norm itself (1e-9).
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 30; ++trial) {
    StateSpace sys;
    const Eigen::Index n = 2 + trial % 5;
    sys.A = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(rng); });
    const double shift = sys.A.eigenvalues().real().maxCoeff() + 0.1 + 0.5 * std::abs(normal(rng));
    sys.A -= shift * Eigen::MatrixXd::Identity(n, n);
    sys.B = Eigen::MatrixXd::NullaryExpr(n, 2, [&] { return normal(rng); });
    sys.C = Eigen::MatrixXd::NullaryExpr(2, n, [&] { return normal(rng); });
    sys.D = 0.1 * Eigen::MatrixXd::NullaryExpr(2, 2, [&] { return normal(rng); });
    const double norm = hinf_norm(sys, 1e-9).value;
    EXPECT_TRUE(hinf_norm_below(sys, norm * (1.0 + 1e-6))) << trial;
    EXPECT_FALSE(hinf_norm_below(sys, norm * (1.0 - 1e-6))) << trial;
  }
  // Below sigma_max(D) it cannot be; an unstable system and a gamma <= 0 are errors.
  StateSpace feedthrough = second_order(1.0, 0.5);
  feedthrough.D(0, 0) = 2.0;
  EXPECT_FALSE(hinf_norm_below(feedthrough, 1.99));
  StateSpace unstable = second_order(1.0, 0.5);
  unstable.A = -unstable.A;
  EXPECT_THROW((void)hinf_norm_below(unstable, 10.0), std::invalid_argument);
  EXPECT_THROW((void)hinf_norm_below(second_order(1.0, 0.5), 0.0), std::invalid_argument);
}

TEST(HinfNorm, SecondOrderResonanceClosedForm) {
  for (const double wn : {1e-2, 1.0, 866.0, 1e4}) {
    for (const double zeta : {0.001, 0.01, 0.05, 0.3, 0.6}) {
      SCOPED_TRACE("wn " + std::to_string(wn) + " zeta " + std::to_string(zeta));
      const PeakResult r = hinf_norm(second_order(wn, zeta), 1e-9);
      const double expected = resonance_peak(zeta);
      EXPECT_LE(r.value, expected * (1.0 + 1e-12));
      EXPECT_GE(r.value, expected * (1.0 - 1e-9));
      const double w_peak = wn * std::sqrt(1.0 - 2.0 * zeta * zeta);
      // sigma(w) is flat at the peak: 1e-9 in value is ~ sqrt(1e-9) zeta in frequency.
      EXPECT_NEAR(r.omega_rad_s, w_peak, 1e-4 * zeta * w_peak + 1e-12 * wn);
    }
    // zeta >= 1/sqrt(2): no resonance, the peak is the DC gain 1.
    const PeakResult flat = hinf_norm(second_order(wn, 0.8));
    EXPECT_NEAR(flat.value, 1.0, 1e-14);
    EXPECT_EQ(flat.omega_rad_s, 0.0);
  }
}

TEST(HinfNorm, DefaultToleranceIsRespected) {
  const double zeta = 0.02;
  const double expected = resonance_peak(zeta);
  for (const double tol : {1e-3, 1e-6}) {
    const PeakResult r = hinf_norm(second_order(50.0, zeta), tol);
    EXPECT_LE(r.value, expected * (1.0 + 1e-12)) << tol;
    EXPECT_GE(r.value * (1.0 + tol), expected) << tol;
  }
}

TEST(HinfNorm, InvariantToStateUnitsAndScalesWithSignals) {
  const StateSpace sys = reference_system("mimo_resonant");
  const PeakResult reference = hinf_norm(sys, 1e-10);
  Eigen::VectorXd scales = Eigen::VectorXd::LinSpaced(sys.states(), -4.0, 4.0);
  scales = scales.unaryExpr([](double e) { return std::pow(10.0, e); });
  StateSpace rescaled{scales.asDiagonal() * sys.A * scales.cwiseInverse().asDiagonal(), scales.asDiagonal() * sys.B,
                      sys.C * scales.cwiseInverse().asDiagonal(), sys.D};
  EXPECT_NEAR(hinf_norm(rescaled, 1e-10).value, reference.value, 1e-9 * reference.value);
  // Output in mm instead of m: the norm scales by 1e3.
  StateSpace mm = sys;
  mm.C *= 1e3;
  mm.D *= 1e3;
  EXPECT_NEAR(hinf_norm(mm, 1e-10).value, 1e3 * reference.value, 1e-9 * 1e3 * reference.value);
  // Time in ms: A, B scale by 1e-3 and the peak frequency by 1e-3, the norm stays.
  StateSpace slow = sys;
  slow.A *= 1e-3;
  slow.B *= 1e-3;
  const PeakResult r = hinf_norm(slow, 1e-10);
  EXPECT_NEAR(r.value, reference.value, 1e-9 * reference.value);
  EXPECT_NEAR(r.omega_rad_s, 1e-3 * reference.omega_rad_s, 1e-6 * reference.omega_rad_s);
}

TEST(HinfNorm, PeakNotNearAnyPoleFrequencyIsFound) {
  // Two well-separated lightly damped modes of opposite sign in parallel: the initial candidates
  // (pole frequencies) are near both resonances, but between them the responses interfere; the
  // global peak must still come out right. Reference: dense grid (brute force, here in C++).
  const StateSpace a = second_order(1.0, 0.02), b = second_order(1.3, 0.02);
  StateSpace sum = parallel(a, b);
  sum.C.rightCols(b.states()) *= -1.0;
  sum.D = a.D - b.D;
  double grid_peak = 0.0;  // grid spacing 7e-6 relative: within ~1e-8 of the true peak
  for (int k = 0; k <= 200000; ++k) {
    const double w = 0.5 * std::pow(4.0, k / 200000.0);
    grid_peak = std::max(grid_peak, sigma_max_at(sum, w));
  }
  for (const double tol : {1e-6, 1e-10}) {
    const PeakResult r = hinf_norm(sum, tol);
    EXPECT_GE(r.value * (1.0 + tol), grid_peak) << tol;
    EXPECT_LE(r.value, grid_peak * (1.0 + 1e-7)) << tol;
  }
}

/// Random stable system: modes with damping log-uniform over [0.003, 0.7] and frequencies over
/// [0.1, 100] rad/s (plus a real pole when n is odd), hidden by a random well-conditioned
/// similarity; random B, C and (every other system) D.
StateSpace random_lightly_damped(std::mt19937_64& rng, int n, int p, int m, bool with_d) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd modal = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i + 1 < n; i += 2) {
    const double w = std::pow(10.0, -1.0 + 3.0 * unit(rng)), z = std::pow(10.0, -2.5 + 2.35 * unit(rng));
    modal(i, i) = modal(i + 1, i + 1) = -z * w;
    modal(i, i + 1) = w * std::sqrt(1.0 - z * z);
    modal(i + 1, i) = -modal(i, i + 1);
  }
  if (n % 2 == 1) modal(n - 1, n - 1) = -std::pow(10.0, -1.0 + 3.0 * unit(rng));
  const Eigen::MatrixXd v = Eigen::MatrixXd::Identity(n, n) + 0.3 * Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(rng); });
  StateSpace s{v * modal * v.inverse(), Eigen::MatrixXd::NullaryExpr(n, m, [&] { return normal(rng); }),
               Eigen::MatrixXd::NullaryExpr(p, n, [&] { return normal(rng); }), Eigen::MatrixXd::Zero(p, m)};
  if (with_d) s.D = 0.5 * Eigen::MatrixXd::NullaryExpr(p, m, [&] { return normal(rng); });
  return s;
}

TEST(HinfNorm, RandomMimoSystemsAgainstGridSearch) {
  // Reference: sup of sigma_max on a 4000-point log grid widened by the pole frequencies (so no
  // resonance is stepped over), each local maximum refined by golden section (peak_on_grid), plus
  // sigma_max(D) at infinity: a search without the Hamiltonian.
  std::mt19937_64 rng(424242);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 2 + trial % 11, p = 1 + trial % 3, m = 1 + (trial / 3) % 3;
    const StateSpace sys = random_lightly_damped(rng, n, p, m, trial % 2 == 0);
    SCOPED_TRACE("trial " + std::to_string(trial) + " n " + std::to_string(n) + " " + std::to_string(p) + "x" + std::to_string(m));
    const Eigen::VectorXcd poles = sys.A.eigenvalues();
    std::vector<double> grid = log_space(1e-4, 1e5, 4000);
    for (Eigen::Index i = 0; i < poles.size(); ++i) {
      grid.push_back(std::abs(poles(i)));
      if (poles(i).imag() > 0.0) grid.push_back(poles(i).imag());
    }
    grid.push_back(0.0);
    std::sort(grid.begin(), grid.end());
    grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
    FrequencyResponseEvaluator evaluator(sys);
    const auto sigma = [&](double w) { return Complex(Eigen::JacobiSVD<Eigen::MatrixXcd>(evaluator(Complex(0.0, w))).singularValues()(0), 0.0); };
    const double reference = std::max(peak_on_grid(sigma, grid, 1e-8).value, Eigen::JacobiSVD<Eigen::MatrixXd>(sys.D).singularValues()(0));
    const PeakResult r = hinf_norm(sys);
    EXPECT_GE(r.value * (1.0 + 1e-6), reference);
    EXPECT_LE(r.value, reference * (1.0 + 1e-9));
  }
}

TEST(HinfNorm, DegenerateSystems) {
  // Zero transfer matrix.
  StateSpace zero = second_order(3.0, 0.1);
  zero.C.setZero();
  const PeakResult z = hinf_norm(zero);
  EXPECT_EQ(z.value, 0.0);
  EXPECT_EQ(z.omega_rad_s, 0.0);
  // Static gain (no states): sigma_max(D), attained everywhere (reported at 0).
  const StateSpace gain{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 2), Eigen::MatrixXd(2, 0), Eigen::MatrixXd{{3.0, 4.0}, {0.0, 0.0}}};
  EXPECT_NEAR(hinf_norm(gain).value, 5.0, 1e-15);
  // D dominant with a dip: (s^2 + 0.1 s + 1)/(s^2 + s + 1) is <= 1, equal to 1 at 0 and infinity.
  const PeakResult notch = hinf_norm(to_state_space(TransferFunction(Polynomial{1.0, 0.1, 1.0}, Polynomial{1.0, 1.0, 1.0})));
  EXPECT_NEAR(notch.value, 1.0, 1e-14);
  EXPECT_EQ(notch.omega_rad_s, 0.0);  // the finite candidate wins a tie
}

TEST(HinfNorm, RejectsUnstableSystemsAndBadTolerances) {
  EXPECT_THROW((void)hinf_norm(to_state_space(TransferFunction(Polynomial{1.0}, Polynomial{1.0, -0.1, 4.0}))), std::invalid_argument);
  EXPECT_THROW((void)hinf_norm(to_state_space(TransferFunction(Polynomial{1.0}, Polynomial{1.0, 1.0, 0.0}))), std::invalid_argument);
  EXPECT_THROW((void)hinf_norm(to_state_space(TransferFunction(Polynomial{1.0}, Polynomial{1.0, 0.0, 4.0}))), std::invalid_argument);
  EXPECT_THROW((void)hinf_norm(second_order(1.0, 0.1), 0.0), std::invalid_argument);
  EXPECT_THROW((void)hinf_norm(second_order(1.0, 0.1), 0.5), std::invalid_argument);
  StateSpace bad = second_order(1.0, 0.1);
  bad.D = Eigen::MatrixXd::Zero(2, 2);
  EXPECT_THROW((void)hinf_norm(bad), std::invalid_argument);
}

// ---- peak_on_grid ------------------------------------------------------------------------------

TEST(PeakOnGrid, SecondOrderClosedFormOnCoarseGrid) {
  for (const double zeta : {0.01, 0.1, 0.4}) {
    const double wn = 25.0;
    const TransferFunction g(Polynomial{wn * wn}, Polynomial{1.0, 2.0 * zeta * wn, wn * wn});
    const std::vector<double> grid = log_space(1e-3 * wn, 1e3 * wn, 2000);
    const PeakResult r = peak_on_grid([&](double w) { return g.frequency_response(w); }, grid);
    const double expected = resonance_peak(zeta);
    EXPECT_NEAR(r.value, expected, 1e-9 * expected) << zeta;
    const double w_peak = wn * std::sqrt(1.0 - 2.0 * zeta * zeta);
    EXPECT_NEAR(r.omega_rad_s, w_peak, 2e-6 * w_peak) << zeta;
  }
}

TEST(PeakOnGrid, DelayLoopSensitivityMatchesScipy) {
  const auto& c = control_reference().at("peak_delay");
  const auto& p = c.at("params");
  const Polynomial num(p.at("num").get<std::vector<double>>()), den(p.at("den").get<std::vector<double>>());
  const double delay = p.at("delay").get<double>();
  const auto loop = [&](double w) { return num(Complex(0.0, w)) / den(Complex(0.0, w)) * std::exp(Complex(0.0, -w * delay)); };
  const auto sensitivity = [&](double w) { return 1.0 / (1.0 + loop(w)); };
  const auto complementary = [&](double w) { return loop(w) / (1.0 + loop(w)); };
  const std::vector<double> grid = log_space(c.at("grid_first").get<double>(), 1e3, 2000);
  const PeakResult r = peak_on_grid(sensitivity, grid);
  const double expected = c.at("peak_S").get<double>();
  EXPECT_NEAR(r.value, expected, 1e-10 * expected);
  EXPECT_NEAR(r.omega_rad_s, c.at("peak_S_omega").get<double>(), 1e-4 * c.at("peak_S_omega").get<double>());
  const std::optional<double> bw = bandwidth(complementary, grid);
  ASSERT_TRUE(bw.has_value());
  const double expected_bw = c.at("bandwidth_T").get<double>();
  EXPECT_NEAR(*bw, expected_bw, 2e-9 * expected_bw);
}

TEST(PeakOnGrid, EndPointsPolesAndErrors) {
  // Peak at DC with a grid starting at 0 (linear refinement of the first bracket).
  const auto low_pass = [](double w) { return 1.0 / Complex(1.0, w); };
  const std::vector<double> with_zero{0.0, 0.5, 1.0, 2.0};
  const PeakResult dc = peak_on_grid(low_pass, with_zero);
  EXPECT_EQ(dc.value, 1.0);
  EXPECT_EQ(dc.omega_rad_s, 0.0);
  // Rising to the last grid point.
  const PeakResult end = peak_on_grid([](double w) { return Complex(w, 1.0); }, std::vector<double>{1.0, 2.0, 3.0});
  EXPECT_EQ(end.value, std::abs(Complex(3.0, 1.0)));
  // A pole on a grid point: infinite peak.
  const PeakResult pole = peak_on_grid([](double w) { return 1.0 / Complex(0.0, w - 2.0); }, std::vector<double>{1.0, 2.0, 3.0});
  EXPECT_EQ(pole.value, kInf);
  EXPECT_EQ(pole.omega_rad_s, 2.0);
  // Single point.
  EXPECT_EQ(peak_on_grid(low_pass, std::vector<double>{1.0}).value, std::abs(low_pass(1.0)));
  const auto nan = [](double) { return Complex(std::numeric_limits<double>::quiet_NaN(), 0.0); };
  EXPECT_THROW((void)peak_on_grid(nan, with_zero), std::invalid_argument);
  EXPECT_THROW((void)peak_on_grid(low_pass, std::vector<double>{}), std::invalid_argument);
  EXPECT_THROW((void)peak_on_grid(low_pass, std::vector<double>{1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW((void)peak_on_grid(low_pass, std::vector<double>{-1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW((void)peak_on_grid(low_pass, with_zero, 0.0), std::invalid_argument);
}

// ---- bandwidth -----------------------------------------------------------------------------------

TEST(Bandwidth, FirstOrderClosedForms) {
  const auto g = [](double w) { return 1.0 / Complex(1.0, w); };
  const std::vector<double> grid = log_space(1e-4, 1e4, 800);
  // |1/(1 + j w)| = 1/sqrt(2) exactly at w = 1 (-3.0103 dB).
  std::vector<double> with_zero{0.0};
  with_zero.insert(with_zero.end(), grid.begin(), grid.end());
  const double half_power_db = -20.0 * std::log10(std::sqrt(2.0));
  const std::optional<double> half_power = bandwidth(g, with_zero, half_power_db);
  ASSERT_TRUE(half_power.has_value());
  EXPECT_NEAR(*half_power, 1.0, 1e-9);
  // Reference |G(j grid[0])| = 1/sqrt(1 + 1e-8) when the grid starts at 1e-4: the level is
  // r 10^(L/20) and |G(j w)| = level at w = sqrt(1/level^2 - 1), 1e-8 above the DC-referenced value.
  for (const double level_db : {half_power_db, -3.0}) {
    const double level = std::pow(10.0, level_db / 20.0) / std::sqrt(1.0 + 1e-8);
    const double expected = std::sqrt(1.0 / (level * level) - 1.0);
    EXPECT_NEAR(*bandwidth(g, grid, level_db), expected, 1e-9 * expected) << level_db;
  }
  // Grid starting at 0: the reference is the exact DC gain (rapid::AxisModel::bandwidth_hz); the
  // -3 dB point (MATLAB's bandwidth) of 1/(s + 1) is sqrt(10^(3/10) - 1).
  EXPECT_NEAR(*bandwidth(g, with_zero), std::sqrt(std::pow(10.0, 0.3) - 1.0), 1e-9);
  // A level crossed inside the very first interval [0, grid[1]] is bisected linearly from 0.
  EXPECT_NEAR(*bandwidth(g, std::vector<double>{0.0, 1e3}), std::sqrt(std::pow(10.0, 0.3) - 1.0), 1e-9);
  // -20 dB: sqrt(99).
  EXPECT_NEAR(*bandwidth(g, with_zero, -20.0), std::sqrt(99.0), 1e-9 * std::sqrt(99.0));
}

TEST(Bandwidth, NeverFallingAndErrors) {
  const auto all_pass = [](double w) { return Complex(1.0, -w) / Complex(1.0, w); };
  EXPECT_FALSE(bandwidth(all_pass, log_space(1e-3, 1e3, 100)).has_value());
  const auto g = [](double w) { return 1.0 / Complex(1.0, w); };
  const std::vector<double> grid = log_space(1e-3, 1e3, 100);
  EXPECT_THROW((void)bandwidth(g, grid, 0.0), std::invalid_argument);
  EXPECT_THROW((void)bandwidth(g, grid, 3.0), std::invalid_argument);
  EXPECT_THROW((void)bandwidth(g, std::vector<double>{1.0}), std::invalid_argument);
  EXPECT_THROW((void)bandwidth(g, std::vector<double>{2.0, 1.0}), std::invalid_argument);
  // A differentiator has no DC reference.
  EXPECT_THROW((void)bandwidth([](double w) { return Complex(0.0, w); }, std::vector<double>{0.0, 1.0}), std::domain_error);
}

}  // namespace
}  // namespace servotwin::core
