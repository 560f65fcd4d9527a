// The flexible-frame four-mass model (catalog C7.18-C7.19). References: the dissertation's printed
// transfer function (eq. 7.172, coded separately in flexible_frame_transfer_function from the
// state space written from Newton's law), its printed frequencies (eq. 7.176), and closed forms of
// the two-mass load velocity and of the limit k1 -> infinity.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <utility>
#include <cmath>
#include <complex>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/machine/flexible_frame.hpp"

namespace servotwin::machine {
namespace flexible_frame_test {
namespace {

using cd = std::complex<double>;

std::vector<double> log_grid(double from, double to, int n) {
  std::vector<double> w(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) w[static_cast<std::size_t>(i)] = from * std::pow(to / from, i / (n - 1.0));
  return w;
}

// Distinct moduli of the roots with non-negative imaginary part, ascending.
std::vector<double> root_moduli(const core::Polynomial& p) {
  std::vector<double> m;
  for (const cd& r : p.roots())
    if (r.imag() >= 0.0) m.push_back(std::abs(r));
  std::sort(m.begin(), m.end());
  return m;
}

TEST(FlexibleFrame, StateSpaceReproducesThePrintedTransferFunction) {
  const FlexibleFrame frame = c7_19_flexible_frame();
  const core::StateSpace sys = flexible_frame_state_space(frame);
  const core::TransferFunction printed = flexible_frame_transfer_function(frame);
  for (double w : log_grid(0.02, 100.0, 200)) {
    const cd ss = core::frequency_response(sys, w, kRotorVelocity, kMotorForce);
    const cd tf = printed(cd(0.0, w));
    EXPECT_LT(std::abs(ss - tf), 1e-9 * std::abs(tf)) << "w = " << w;
  }
}

TEST(FlexibleFrame, ThePrintedExampleHasThePrintedFrequencies) {
  // Eq. 7.176: wm = 1.22, ws1 = 5, ws2 = 8.03; zeros 0.7, 4.12, 8.02 (printed to 2-3 digits, so
  // the tolerance is half a unit of the last printed digit). m4 = 0.2 is the catalog's inference.
  const core::TransferFunction p = flexible_frame_transfer_function(c7_19_flexible_frame());
  const std::vector<double> poles = root_moduli(p.den()), zeros = root_moduli(p.num());
  ASSERT_EQ(poles.size(), 4u);
  ASSERT_EQ(zeros.size(), 3u);
  EXPECT_EQ(poles[0], 0.0);  // the rigid-body integrator, exact by construction
  EXPECT_NEAR(poles[1], 1.22, 0.005);
  EXPECT_NEAR(poles[2], 5.0, 0.05);
  EXPECT_NEAR(poles[3], 8.03, 0.005);
  EXPECT_NEAR(zeros[0], 0.7, 0.05);
  EXPECT_NEAR(zeros[1], 4.12, 0.005);
  EXPECT_NEAR(zeros[2], 8.02, 0.005);
  // The third mode is the nearly unobservable one: its pole and zero lie within 0.02 %.
  EXPECT_LT((poles[3] - zeros[2]) / zeros[2], 2e-4);
}

TEST(FlexibleFrame, LoadAndStatorOutputsMatchTheirClosedForms) {
  const FlexibleFrame f = c7_19_flexible_frame();
  const core::StateSpace sys = flexible_frame_state_space(f);
  const double m1 = f.frame_mass, m2 = f.stator_mass, m3 = f.rotor_mass, m4 = f.load_mass;
  const double k1 = f.frame_stiffness, k2 = f.mount_stiffness, k3 = f.coupling_stiffness;
  const double b1 = f.frame_damping, b2 = f.mount_damping, b3 = f.coupling_damping;
  for (double w : log_grid(0.05, 50.0, 60)) {
    const cd s(0.0, w);
    const cd am = s * (m4 * m3 * s * s + b3 * (m3 + m4) * s + k3 * (m3 + m4));
    // Stator on the frame, driven by -Fm: v2 = -s (m1 s^2 + (b1+b2) s + k1 + k2)/det Fm.
    const cd det = (m2 * s * s + b2 * s + k2) * (m1 * s * s + (b1 + b2) * s + k1 + k2) - (b2 * s + k2) * (b2 * s + k2);
    const cd stator = -s * (m1 * s * s + (b1 + b2) * s + k1 + k2) / det;
    const cd load = (b3 * s + k3) / am;  // two-mass load velocity per rotor force
    const cd got_load = core::frequency_response(sys, w, kLoadVelocity, kMotorForce);
    const cd got_stator = core::frequency_response(sys, w, kStatorVelocity, kMotorForce);
    EXPECT_LT(std::abs(got_load - (load - stator)), 1e-9 * std::abs(load - stator)) << w;
    EXPECT_LT(std::abs(got_stator - stator), 1e-9 * std::abs(stator)) << w;
    // A stator force moves the stator exactly as a negative motor force does, and not the rotor.
    const cd from_fs = core::frequency_response(sys, w, kStatorVelocity, kStatorForce);
    EXPECT_LT(std::abs(from_fs + stator), 1e-9 * std::abs(stator)) << w;
  }
}

TEST(FlexibleFrame, VelocityRealizationDropsOnlyTheFloatingPosition) {
  const FlexibleFrame frame = c7_19_flexible_frame();
  const core::StateSpace full = flexible_frame_state_space(frame);
  const core::StateSpace velocity = flexible_frame_velocity_state_space(frame);
  ASSERT_EQ(velocity.A.rows(), 7);
  const std::array<std::pair<Eigen::Index, Eigen::Index>, 4> rows{
      {{kRotorVelocityOut, kRotorVelocity}, {kLoadVelocityOut, kLoadVelocity},
       {kStatorVelocityOut, kStatorVelocity}, {kFrameVelocityOut, kFrameVelocity}}};
  for (double w : log_grid(0.05, 50.0, 30))
    for (const auto& [out7, out8] : rows)
      for (Eigen::Index in = 0; in < 3; ++in) {
        const cd a = core::frequency_response(velocity, w, out7, in), b = core::frequency_response(full, w, out8, in);
        EXPECT_LT(std::abs(a - b), 1e-9 * (1.0 + std::abs(b))) << w;
      }
  // One eigenvalue at 0 (the rigid body's velocity), the rest stable.
  const Eigen::VectorXcd eig = velocity.A.eigenvalues();
  int at_zero = 0;
  for (const cd& l : eig) {
    if (std::abs(l) < 1e-9) ++at_zero;
    else EXPECT_LT(l.real(), 0.0) << l;
  }
  EXPECT_EQ(at_zero, 1);
}

TEST(FlexibleFrame, AStiffGroundMountGivesTheThreeMassLimit) {
  // k1 -> infinity (Sec. 7.6): the frame is the ground and Pf -> s/(m2 s^2 + b2 s + k2).
  FlexibleFrame f = c7_19_flexible_frame();
  f.frame_stiffness = 1e10;
  const core::TransferFunction p = flexible_frame_transfer_function(f);
  for (double w : log_grid(0.05, 50.0, 40)) {
    const cd s(0.0, w);
    const cd pm = (f.load_mass * s * s + f.coupling_damping * s + f.coupling_stiffness) /
                  (s * (f.load_mass * f.rotor_mass * s * s +
                        f.coupling_damping * (f.rotor_mass + f.load_mass) * s +
                        f.coupling_stiffness * (f.rotor_mass + f.load_mass)));
    const cd pf = s / (f.stator_mass * s * s + f.mount_damping * s + f.mount_stiffness);
    EXPECT_LT(std::abs(p(s) - (pm + pf)), 1e-6 * std::abs(pm + pf)) << w;
  }
}

TEST(FlexibleFrame, InvalidParametersNameTheField) {
  FlexibleFrame f = c7_19_flexible_frame();
  f.load_mass = 0.0;
  try {
    (void)flexible_frame_state_space(f);
    FAIL() << "expected an InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "load_mass");
  }
  f = c7_19_flexible_frame();
  f.mount_damping = -0.1;
  try {
    validate(f, "flexible_frame.");
    FAIL() << "expected an InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "flexible_frame.mount_damping");
  }
  f = c7_19_flexible_frame();
  f.frame_stiffness = std::nan("");
  EXPECT_THROW((void)flexible_frame_transfer_function(f), core::InputError);
}

}  // namespace
}  // namespace flexible_frame_test
}  // namespace servotwin::machine
