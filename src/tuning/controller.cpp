#include "servotwin/tuning/controller.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/tuning/uncertainty.hpp"

namespace servotwin::tuning {

std::string to_string(Structure structure) {
  switch (structure) {
    case Structure::kPi:
      return "pi";
    case Structure::kPid:
      return "pid";
    case Structure::kPiP:
      return "pi+p";
    case Structure::kLqg:
      return "lqg";
    case Structure::kLqgP:
      return "lqg+p";
    case Structure::kHinf:
      return "hinf";
    case Structure::kLqgPos:
      return "lqg-pos";
    case Structure::kHinfPos:
      return "hinf-pos";
    case Structure::kHinfLoad:
      return "hinf-load";
    case Structure::kLqgLoad:
      return "lqg-load";
  }
  return "pi";
}

bool is_full_order(Structure structure) noexcept {
  return structure == Structure::kLqg || structure == Structure::kLqgP || structure == Structure::kHinf ||
         structure == Structure::kHinfLoad || structure == Structure::kLqgLoad || is_position_controller(structure);
}

bool has_position_loop(Structure structure) noexcept {
  return structure == Structure::kPiP || structure == Structure::kLqgP;
}

bool is_position_controller(Structure structure) noexcept {
  return structure == Structure::kLqgPos || structure == Structure::kHinfPos;
}

bool controls_position(Structure structure) noexcept {
  return has_position_loop(structure) || is_position_controller(structure);
}

bool is_hinf(Structure structure) noexcept {
  return structure == Structure::kHinf || structure == Structure::kHinfPos || structure == Structure::kHinfLoad;
}

bool measures_load(Structure structure) noexcept {
  return structure == Structure::kHinfLoad || structure == Structure::kLqgLoad;
}

bool measures_both(Structure structure) noexcept { return structure == Structure::kLqgLoad; }

bool is_lqg(Structure structure) noexcept {
  return structure == Structure::kLqg || structure == Structure::kLqgP || structure == Structure::kLqgPos ||
         structure == Structure::kLqgLoad;
}

std::optional<Structure> structure_from_string(const std::string& name) {
  for (Structure s : {Structure::kPi, Structure::kPid, Structure::kPiP, Structure::kLqg, Structure::kLqgP, Structure::kHinf,
                      Structure::kLqgPos, Structure::kHinfPos, Structure::kHinfLoad, Structure::kLqgLoad}) {
    if (to_string(s) == name) return s;
  }
  return std::nullopt;
}

core::StateSpace controller_state_space(const PidGains& g) {
  core::StateSpace sys;
  if (g.kd == 0.0) {
    // One integrator state xi' = ω* − ωm; u = ki xi + wp kp ω* − kp ωm.
    sys.A = Eigen::MatrixXd::Zero(1, 1);
    sys.B.resize(1, 2);
    sys.B << 1.0, -1.0;
    sys.C.resize(1, 1);
    sys.C << g.ki;
    sys.D.resize(1, 2);
    sys.D << g.wp * g.kp, -g.kp;
    return sys;
  }
  if (!(g.tau > 0.0)) throw std::invalid_argument("controller_state_space: a derivative needs tau > 0");
  // Filtered derivative of v = wd ω* − ωm: kd s/(τs + 1) v = (kd/τ)(v − xd), xd' = (v − xd)/τ.
  const double k = g.kd / g.tau;
  sys.A.resize(2, 2);
  sys.A << 0.0, 0.0, 0.0, -1.0 / g.tau;
  sys.B.resize(2, 2);
  sys.B << 1.0, -1.0, g.wd / g.tau, -1.0 / g.tau;
  sys.C.resize(1, 2);
  sys.C << g.ki, -k;
  sys.D.resize(1, 2);
  sys.D << g.wp * g.kp + g.wd * k, -g.kp - k;
  return sys;
}

core::StateSpace to_physical(const core::StateSpace& n, const PlantScales& plant, bool position_inputs) {
  const double wz = plant.omega_z, torque = plant.motor_inertia * plant.omega_z;
  const double input = position_inputs ? wz : 1.0;
  return {wz * n.A, wz * input * n.B, torque * n.C, torque * input * n.D};
}

namespace {

/// The drive filters' chain on the normalized time axis (s_physical = ωz s).
core::TransferFunction normalized_filters(const Controller& c) {
  return to_normalized_time(filter_chain(c.drive_filters), c.plant.omega_z);
}

}  // namespace

ControllerTf with_output_filter(const ControllerTf& k, const core::TransferFunction& f) {
  return {core::series(k.feedback, f), core::series(k.reference, f)};
}

core::StateSpace controller_state_space(const Controller& c) {
  if (!is_full_order(c.structure)) {
    // Each filter realized on its own: the product polynomial of several filters near a kHz has
    // coefficients of ω⁶ ~ 1e22, a badly conditioned companion form.
    core::StateSpace k = controller_state_space(c.physical);
    for (const DriveFilter& f : c.drive_filters) k = core::series(k, core::to_state_space(f.continuous));
    return k;
  }
  if (!c.full_order) throw std::invalid_argument("controller_state_space: a full-order controller without its compensator");
  return to_physical(c.full_order->compensator, c.plant, is_position_controller(c.structure));
}

ControllerTf normalized_controller(const Controller& c) {
  if (!is_full_order(c.structure)) {
    if (c.drive_filters.empty()) return pid_controller(c.normalized);
    return with_output_filter(pid_controller(c.normalized), normalized_filters(c));
  }
  if (!c.full_order) throw std::invalid_argument("normalized_controller: a full-order controller without its compensator");
  return compensator_form(c.structure, c.full_order->compensator);
}

ControllerTf compensator_form(Structure structure, const core::StateSpace& compensator) {
  if (measures_both(structure))
    throw std::invalid_argument("compensator_form: " + to_string(structure) + " has three inputs (use compensator_loop)");
  const ControllerTf tf = two_dof_form(compensator);
  return is_position_controller(structure) ? velocity_form(tf) : tf;
}

VelocityLoop compensator_loop(const NormalizedPlant& plant, Structure structure, const core::StateSpace& compensator,
                              bool with_hf, bool with_higher_modes) {
  if (measures_both(structure))
    return VelocityLoop::two_measurements(plant.first_mode(), two_measurement_form(compensator), with_hf);
  const ControllerTf tf = compensator_form(structure, compensator);
  if (measures_load(structure)) return VelocityLoop::load_feedback(plant.first_mode(), tf, with_hf);
  return VelocityLoop(plant, tf, with_hf, with_higher_modes);
}

VelocityLoop controller_loop(const NormalizedPlant& plant, const Controller& c, bool with_hf, bool with_higher_modes) {
  if (!is_full_order(c.structure)) return VelocityLoop(plant, normalized_controller(c), with_hf, with_higher_modes);
  if (!c.full_order) throw std::invalid_argument("controller_loop: a full-order controller without its compensator");
  return compensator_loop(plant, c.structure, c.full_order->compensator, with_hf, with_higher_modes);
}

namespace {

void check_period(double ts, std::optional<double> prewarp_rad_s) {
  if (!std::isfinite(ts) || ts <= 0.0) {
    throw core::InputError(core::at_field("ts"), "expected a sample period > 0 s, got " + std::to_string(ts));
  }
  const double nyquist = std::numbers::pi / ts;
  if (prewarp_rad_s && (!std::isfinite(*prewarp_rad_s) || *prewarp_rad_s <= 0.0 || *prewarp_rad_s >= nyquist)) {
    throw core::InputError(core::at_field("ts"),
                           "the prewarp frequency " + std::to_string(*prewarp_rad_s / (2.0 * std::numbers::pi)) +
                               " Hz must lie below the Nyquist frequency " +
                               std::to_string(nyquist / (2.0 * std::numbers::pi)) + " Hz: shorten the sample period");
  }
}

}  // namespace

core::DiscreteStateSpace discretize_controller(const PidGains& physical, double ts, std::optional<double> prewarp_rad_s) {
  check_period(ts, prewarp_rad_s);
  return core::discretize_tustin(controller_state_space(physical), ts, prewarp_rad_s);
}

core::DiscreteStateSpace discretize_controller(const Controller& controller, double ts,
                                               std::optional<double> prewarp_rad_s) {
  check_period(ts, prewarp_rad_s);
  if (controller.drive_filters.empty() || is_full_order(controller.structure))
    return core::discretize_tustin(controller_state_space(controller), ts, prewarp_rad_s);
  // The gains' part prewarped at the loop's frequency, each filter at its own (as a drive runs them).
  const core::DiscreteStateSpace k = core::discretize_tustin(controller_state_space(controller.physical), ts, prewarp_rad_s);
  std::vector<DriveFilter> filters;
  for (const DriveFilter& f : controller.drive_filters) filters.push_back(make_drive_filter(f.spec, ts, "ts"));
  const core::DiscreteStateSpace chain = discrete_chain(filters, ts);
  const core::StateSpace s = core::series({k.A, k.B, k.C, k.D}, {chain.A, chain.B, chain.C, chain.D});
  return {s.A, s.B, s.C, s.D, ts};
}

}  // namespace servotwin::tuning
