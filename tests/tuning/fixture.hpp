#pragma once
// Test helpers for module tuning: the fixture written by tools/reference/tuning_reference.py and
// small comparisons.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "json_fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::tuning::test {

inline constexpr double kSqrtHalf = std::numbers::sqrt2 / 2.0;

/// A velocity model K (s² + 2ζz ωz s + ωz²)/(s (s² + 2ζ ωn s + ωn²)) with ωn = r ωz, ζ = r ζz
/// (frictionless two-mass), K = 1/Im; by default a 40 Hz antiresonance and Im = 4e-3.
inline fit::PlantModel two_mass_model(double r, double zeta_z, double omega_z = 2.0 * std::numbers::pi * 40.0,
                                      double im = 4e-3) {
  fit::PlantModel m;
  m.rigid = fit::RigidKind::kIntegrator;
  m.gain = 1.0 / im;
  m.modes = {{{omega_z, zeta_z}, {r * omega_z, r * zeta_z}}};
  return m;
}

/// Catalog A6 configuration 2 (eq. 8.14, E37): (K/(s + τ1))(s² + 2ξz1 ωz1 s + ωz1²)/(s² + 2ξ1 ω1 s +
/// ω1²)·1/(τ2 s + 1) with K = 454.5, τ1 = 0.15, τ2 = 0.0022 s (the lag's time constant, as the
/// testbed-2 preset reads it), ξz1 = 0.24, ωz1 = 49.9, ξ1 = 0.02, ω1 = 254 rad/s (r = 5.09).
inline fit::PlantModel test_bed_2() {
  fit::PlantModel m;
  m.rigid = fit::RigidKind::kRealPole;
  m.rigid_pole_rad_s = 0.15;
  const double lag = 1.0 / 0.0022;
  m.lag_pole_rad_s = lag;
  m.gain = 454.5 * lag;
  m.modes = {{{49.9, 0.24}, {254.0, 0.02}}};
  return m;
}

/// tests/data/tuning/tuning_reference.json (parsed once).
inline const nlohmann::json& reference() {
  static const nlohmann::json j =
      test_support::read_json_fixture("tuning/tuning_reference.json", "tuning_reference.py");
  return j;
}

/// Relative difference with an absolute floor of 1 (for values that may be ~0).
inline double rel_diff(double a, double b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1.0}); }

/// A [re, im] pair from the fixture.
inline std::complex<double> root_of(const nlohmann::json& pair) { return {pair.at(0).get<double>(), pair.at(1).get<double>()}; }

/// Roots sorted by (modulus, real part, imaginary part descending) for pairwise comparison.
inline std::vector<std::complex<double>> sorted_roots(std::vector<std::complex<double>> v) {
  std::sort(v.begin(), v.end(), [](std::complex<double> x, std::complex<double> y) {
    if (std::abs(std::abs(x) - std::abs(y)) > 1e-9 * std::max(std::abs(x), 1.0)) return std::abs(x) < std::abs(y);
    return x.imag() > y.imag();
  });
  return v;
}

/// Minimum damping -Re/|.| over the roots of a polynomial, and the root where it occurs.
inline std::pair<double, std::complex<double>> min_damping(const core::Polynomial& c) {
  double best = 2.0;
  std::complex<double> at;
  for (const std::complex<double>& x : c.roots()) {
    const double z = -x.real() / std::abs(x);
    if (z < best) {
      best = z;
      at = x;
    }
  }
  return {best, at};
}

/// The normalized frictionless two-mass TF (1/s)(s² + 2ζz s + 1)/(s² + 2ζz r² s + r²) written out
/// here (catalog §0), independently of NormalizedPlant::motor().
inline core::TransferFunction frictionless_tf(double r, double zeta_z) {
  return {core::Polynomial{1.0, 2.0 * zeta_z, 1.0},
          core::Polynomial{1.0, 0.0} * core::Polynomial{1.0, 2.0 * zeta_z * r * r, r * r}};
}

/// The closed loop of a plant p (inputs [Tm, Tl], outputs [motor, load], no feedthrough) and a
/// compensator k (inputs [reference, measurement], output Tm) measuring output `measured` of p,
/// written out here independently of the transfer-function route of VelocityLoop: inputs
/// [reference, Tl], outputs p's.
inline core::StateSpace closed_loop_ss(const core::StateSpace& p, const core::StateSpace& k, Eigen::Index measured) {
  const Eigen::Index n = p.A.rows(), m = k.A.rows();
  const Eigen::MatrixXd bu = p.B.col(0), bt = p.B.col(1), cm = p.C.row(measured);
  core::StateSpace cl;
  cl.A.resize(n + m, n + m);
  cl.A << p.A + bu * k.D(0, 1) * cm, bu * k.C, k.B.col(1) * cm, k.A;
  cl.B.resize(n + m, 2);
  cl.B << bu * k.D(0, 0), bt, k.B.col(0), Eigen::MatrixXd::Zero(m, 1);
  cl.C = Eigen::MatrixXd::Zero(p.C.rows(), n + m);
  cl.C.leftCols(n) = p.C;
  cl.D = Eigen::MatrixXd::Zero(p.C.rows(), 2);
  return cl;
}

/// The same for a compensator measuring both outputs of p (inputs [reference, ωm, ωl], C7.17's
/// LQG): u = Cc xc + D [reference, ωm, ωl]; inputs [reference, Tl], outputs p's.
inline core::StateSpace two_measurement_closed_loop_ss(const core::StateSpace& p, const core::StateSpace& k) {
  const Eigen::Index n = p.A.rows(), q = k.A.rows();
  core::StateSpace cl;
  cl.A.resize(n + q, n + q);
  cl.A << p.A + p.B.col(0) * k.D.rightCols(2) * p.C, p.B.col(0) * k.C, k.B.rightCols(2) * p.C, k.A;
  cl.B.resize(n + q, 2);
  cl.B << p.B.col(0) * k.D(0, 0), p.B.col(1), k.B.col(0), Eigen::MatrixXd::Zero(q, 1);
  cl.C = Eigen::MatrixXd::Zero(p.C.rows(), n + q);
  cl.C.leftCols(n) = p.C;
  cl.D = Eigen::MatrixXd::Zero(p.C.rows(), 2);
  return cl;
}

/// The position plant p (outputs [φm, φl]) under a position compensator (inputs [φ*, φm]).
inline core::StateSpace position_closed_loop_ss(const core::StateSpace& p, const core::StateSpace& k) {
  return closed_loop_ss(p, k, 0);
}

/// f() must throw core::InputError naming `field`, with `text` in its reason.
inline void expect_input_error(const std::function<void()>& f, const std::string& field, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no InputError, expected one containing: " << text;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, field);
    EXPECT_NE(e.reason().find(text), std::string::npos) << e.reason();
  }
}

}  // namespace servotwin::tuning::test
