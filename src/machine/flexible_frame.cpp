#include "servotwin/machine/flexible_frame.hpp"

#include <array>
#include <cmath>
#include <string>

#include "field_errors.hpp"

namespace servotwin::machine {

void validate(const FlexibleFrame& f, std::string_view prefix) {
  const auto field = [&](const char* name) { return std::string(prefix) + name; };
  detail::positive(f.frame_mass, field("frame_mass"));
  detail::positive(f.frame_stiffness, field("frame_stiffness"));
  detail::non_negative(f.frame_damping, field("frame_damping"));
  detail::positive(f.stator_mass, field("stator_mass"));
  detail::positive(f.mount_stiffness, field("mount_stiffness"));
  detail::non_negative(f.mount_damping, field("mount_damping"));
  detail::positive(f.rotor_mass, field("rotor_mass"));
  detail::positive(f.coupling_stiffness, field("coupling_stiffness"));
  detail::non_negative(f.coupling_damping, field("coupling_damping"));
  detail::positive(f.load_mass, field("load_mass"));
}

FlexibleFrame c7_19_flexible_frame() noexcept {
  FlexibleFrame f;
  f.frame_mass = 70.0;
  f.frame_stiffness = 4500.0;
  f.frame_damping = 0.01;
  f.stator_mass = 0.2;
  f.mount_stiffness = 5.0;
  f.mount_damping = 0.02;
  f.rotor_mass = 0.1;
  f.coupling_stiffness = 0.1;
  f.coupling_damping = 0.01;
  f.load_mass = 0.2;
  return f;
}

core::StateSpace flexible_frame_state_space(const FlexibleFrame& f) {
  validate(f);
  // M x'' + B x' + K x = F u: the frame/stator pair and the rotor/load pair are two separate
  // spring-damper chains, joined only by the motor force (action on the rotor, reaction on the
  // stator).
  const double k1 = f.frame_stiffness, k2 = f.mount_stiffness, k3 = f.coupling_stiffness;
  const double b1 = f.frame_damping, b2 = f.mount_damping, b3 = f.coupling_damping;
  Eigen::Matrix4d stiffness, damping;
  stiffness << k1 + k2, -k2, 0, 0,  //
      -k2, k2, 0, 0,                //
      0, 0, k3, -k3,                //
      0, 0, -k3, k3;
  damping << b1 + b2, -b2, 0, 0,  //
      -b2, b2, 0, 0,              //
      0, 0, b3, -b3,              //
      0, 0, -b3, b3;
  const Eigen::Vector4d inverse_mass(1.0 / f.frame_mass, 1.0 / f.stator_mass, 1.0 / f.rotor_mass,
                                     1.0 / f.load_mass);
  Eigen::Matrix<double, 4, 3> forces;  // columns Fm, Fl, Fs acting on masses 1..4
  forces << 0, 0, 0,  //
      -1, 0, 1,       //
      1, 0, 0,        //
      0, 1, 0;

  core::StateSpace sys;
  sys.A = Eigen::MatrixXd::Zero(8, 8);
  sys.B = Eigen::MatrixXd::Zero(8, 3);
  sys.C = Eigen::MatrixXd::Zero(6, 8);
  sys.D = Eigen::MatrixXd::Zero(6, 3);
  for (Eigen::Index i = 0; i < 4; ++i) {
    sys.A(2 * i, 2 * i + 1) = 1.0;
    for (Eigen::Index j = 0; j < 4; ++j) {
      sys.A(2 * i + 1, 2 * j) = -inverse_mass(i) * stiffness(i, j);
      sys.A(2 * i + 1, 2 * j + 1) = -inverse_mass(i) * damping(i, j);
    }
    sys.B.row(2 * i + 1) = inverse_mass(i) * forces.row(i);
  }
  const auto position = [](Eigen::Index mass) { return 2 * mass; };
  const auto velocity = [](Eigen::Index mass) { return 2 * mass + 1; };
  sys.C(kRotorVelocity, velocity(2)) = 1.0;
  sys.C(kRotorVelocity, velocity(1)) = -1.0;
  sys.C(kLoadVelocity, velocity(3)) = 1.0;
  sys.C(kLoadVelocity, velocity(1)) = -1.0;
  sys.C(kRotorPosition, position(2)) = 1.0;
  sys.C(kRotorPosition, position(1)) = -1.0;
  sys.C(kLoadPosition, position(3)) = 1.0;
  sys.C(kLoadPosition, position(1)) = -1.0;
  sys.C(kStatorVelocity, velocity(1)) = 1.0;
  sys.C(kFrameVelocity, velocity(0)) = 1.0;
  return sys;
}

core::StateSpace flexible_frame_velocity_state_space(const FlexibleFrame& frame) {
  const core::StateSpace full = flexible_frame_state_space(frame);
  // z = T x with z4 = x3 - x4 (0-based state 4) and z6 = x4; x = T^-1 z. The spring k3 and damper b3
  // act on x3 - x4 only and no output below reads a position of the pair, so z6 drives nothing
  // (its column of T A T^-1 is A (e4 + e6) = 0) and is dropped.
  Eigen::MatrixXd t = Eigen::MatrixXd::Identity(8, 8), t_inverse = Eigen::MatrixXd::Identity(8, 8);
  t(4, 6) = -1.0;
  t_inverse(4, 6) = 1.0;
  const Eigen::MatrixXd a = t * full.A * t_inverse;
  const Eigen::MatrixXd b = t * full.B;
  std::array<Eigen::Index, 7> keep{0, 1, 2, 3, 4, 5, 7};
  core::StateSpace sys;
  sys.A = a(keep, keep);
  sys.B = b(keep, Eigen::all);
  const std::array<Eigen::Index, 4> outputs{kRotorVelocity, kLoadVelocity, kStatorVelocity, kFrameVelocity};
  sys.C = (full.C * t_inverse)(outputs, keep);
  sys.D = Eigen::MatrixXd::Zero(4, 3);
  return sys;
}

core::TransferFunction flexible_frame_transfer_function(const FlexibleFrame& f) {
  validate(f);
  const double m1 = f.frame_mass, m2 = f.stator_mass, m3 = f.rotor_mass, m4 = f.load_mass;
  const double k1 = f.frame_stiffness, k2 = f.mount_stiffness, k3 = f.coupling_stiffness;
  const double b1 = f.frame_damping, b2 = f.mount_damping, b3 = f.coupling_damping;
  using core::Polynomial;
  const Polynomial s{1.0, 0.0};
  // Eq. 7.172, Pm = bm/am (rotor and load) and Pf = bs/as (stator and frame).
  const Polynomial bm{m4, b3, k3};
  const Polynomial am = s * Polynomial{m4 * m3, b3 * (m3 + m4), k3 * (m3 + m4)};
  const Polynomial bs = s * Polynomial{m1, b1 + b2, k1 + k2};
  const Polynomial as{m2 * m1, m2 * (b1 + b2) + b2 * m1, k2 * (m2 + m1) + b2 * b1 + m2 * k1, k2 * b1 + b2 * k1,
                      k2 * k1};
  return {bm * as + bs * am, am * as};
}

}  // namespace servotwin::machine
