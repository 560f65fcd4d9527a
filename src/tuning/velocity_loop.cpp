#include "servotwin/tuning/velocity_loop.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace servotwin::tuning {

using core::Polynomial;
using core::TransferFunction;
using Complex = std::complex<double>;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void check_gains(const PidGains& g) {
  for (double v : {g.kp, g.ki, g.kd, g.tau, g.wp, g.wd}) {
    if (!std::isfinite(v)) throw std::invalid_argument("pid_controller: gains must be finite");
  }
  if (g.tau < 0.0) throw std::invalid_argument("pid_controller: tau must be >= 0");
  if (g.kd != 0.0 && g.tau == 0.0) {
    throw std::invalid_argument("pid_controller: an ideal derivative (kd != 0, tau = 0) is improper");
  }
}

/// The plant without higher modes when they are not wanted, so the two-mass realization exists.
NormalizedPlant design_plant(const NormalizedPlant& plant, bool with_higher_modes) {
  return with_higher_modes ? plant : plant.first_mode();
}

/// The loop algebra assumes one proper controller denominator for both paths.
void check_controller(const ControllerTf& c) {
  const Polynomial& den = c.feedback.den();
  if (!(c.reference.den() == den))
    throw std::invalid_argument("VelocityLoop: the reference and feedback paths must share one denominator");
  if (c.feedback.num().degree() > den.degree() || c.reference.num().degree() > den.degree())
    throw std::invalid_argument("VelocityLoop: the controller must be proper");
}

}  // namespace

ControllerTf pid_controller(const PidGains& g) {
  check_gains(g);
  if (g.kd == 0.0) {
    // Without integral action there is no pole at 0: keep the controller a constant so the loop
    // polynomial does not carry a spurious root at s = 0.
    if (g.ki == 0.0) return {TransferFunction(Polynomial{g.kp}, Polynomial{1.0}),
                             TransferFunction(Polynomial{g.wp * g.kp}, Polynomial{1.0})};
    return {TransferFunction(Polynomial{g.kp, g.ki}, Polynomial{1.0, 0.0}),
            TransferFunction(Polynomial{g.wp * g.kp, g.ki}, Polynomial{1.0, 0.0})};
  }
  // C = kp + ki/s + kd s/(τs + 1) over the common denominator s(τs + 1).
  if (g.ki == 0.0) {
    return {TransferFunction(Polynomial{g.kp * g.tau + g.kd, g.kp}, Polynomial{g.tau, 1.0}),
            TransferFunction(Polynomial{g.wp * g.kp * g.tau + g.wd * g.kd, g.wp * g.kp}, Polynomial{g.tau, 1.0})};
  }
  const Polynomial den{g.tau, 1.0, 0.0};
  return {TransferFunction(Polynomial{g.kp * g.tau + g.kd, g.kp + g.ki * g.tau, g.ki}, den),
          TransferFunction(Polynomial{g.wp * g.kp * g.tau + g.wd * g.kd, g.wp * g.kp + g.ki * g.tau, g.ki}, den)};
}

std::optional<TwoMassTransfer> two_mass_transfer(const NormalizedPlant& plant) {
  const std::optional<FrictionTwoMass> m = two_mass_realization(plant);
  if (!m) return std::nullopt;
  // Every function over the monic (s + a)(s² + 2ζp r s + r²) = D'/Il (the two-mass realization,
  // normalized_plant.hpp).
  const TransferFunction motor = plant.motor(false);
  const Polynomial& den = motor.den();
  const double k = m->stiffness;
  const double il = m->load_inertia;
  const Polynomial coupling{m->damping / il, k / il};  // c/Il
  return TwoMassTransfer{motor, TransferFunction(coupling, den), TransferFunction(-1.0 * coupling, den),
                         TransferFunction(Polynomial{-1.0 / il, -(m->motor_viscous + m->damping) / il, -k / il}, den)};
}

TransferFunction pade_delay(double delay, int order) {
  if (!std::isfinite(delay) || delay < 0.0) throw std::invalid_argument("pade_delay: delay must be finite and >= 0");
  if (order < 1 || order > 10) throw std::invalid_argument("pade_delay: order must lie in [1, 10]");
  if (delay == 0.0) return {Polynomial{1.0}, Polynomial{1.0}};
  // e^{-x} ≈ Σ c_k (−x)^k / Σ c_k x^k with c_k = (2N − k)! N! / ((2N)! k! (N − k)!), x = sT.
  const auto n = static_cast<std::size_t>(order);
  std::vector<double> c(n + 1);
  c[0] = 1.0;
  for (std::size_t k = 1; k <= n; ++k) {
    c[k] = c[k - 1] * static_cast<double>(n - k + 1) / (static_cast<double>(k) * static_cast<double>(2 * n - k + 1));
  }
  std::vector<double> num(n + 1), den(n + 1);  // descending powers of s
  for (std::size_t k = 0; k <= n; ++k) {
    const double term = c[k] * std::pow(delay, static_cast<double>(k));
    den[n - k] = term;
    num[n - k] = (k % 2 == 0) ? term : -term;
  }
  return {Polynomial(num), Polynomial(den)};
}

struct VelocityLoop::Values {
  Complex nc, dc, nr, na, da, nf, df, np, dp, delta;
  Complex cm, cl;  // the feedback numerators on ωm and ωl (0 for a channel not measured)
  Complex nm;      // Σ channel·plant numerator (cm·np + cl·nl): L = na nf nm/(dc da df dp)
};

VelocityLoop::VelocityLoop(const NormalizedPlant& plant, const PidGains& gains, bool with_hf, bool with_higher_modes,
                           int pade_order)
    : VelocityLoop(plant, pid_controller(gains), with_hf, with_higher_modes, pade_order) {}

VelocityLoop::VelocityLoop(const NormalizedPlant& plant, ControllerTf controller, bool with_hf, bool with_higher_modes,
                           int pade_order)
    : controller_(std::move(controller)), pade_order_(pade_order), r_(plant.r) {
  check_controller(controller_);
  if (!(plant.r > 1.0) || !std::isfinite(plant.r)) {
    throw std::invalid_argument("VelocityLoop: the plant's resonance ratio must be > 1 (use normalize())");
  }
  const NormalizedPlant p = design_plant(plant, with_higher_modes);
  const TransferFunction motor = p.motor(true);
  plant_num_ = motor.num();
  plant_den_ = motor.den();
  if (with_hf) {
    validate(p.hf);
    const TransferFunction act = p.hf.actuator_rational();
    const TransferFunction fb = p.hf.feedback_rational();
    act_num_ = act.num();
    act_den_ = act.den();
    fb_num_ = fb.num();
    fb_den_ = fb.den();
    delay_ = p.hf.delay_s.value_or(0.0);
  }
  if (const std::optional<FrictionTwoMass> m = p.higher_modes.empty() ? two_mass_realization(p)
                                                                        : std::nullopt) {
    const std::optional<TwoMassTransfer> tm = two_mass_transfer(p);
    has_load_ = tm.has_value();
    if (tm) {
      load_num_ = tm->load_from_torque.num();
      motor_dist_num_ = tm->motor_from_load_torque.num();
      load_dist_num_ = tm->load_from_load_torque.num();
      load_inertia_ = m->load_inertia;
    }
  }
  has_load_tracking_ = has_load_;
  if (!p.higher_modes.empty()) {
    if (const std::optional<TransferFunction> estimate = p.load_estimate()) {
      has_load_tracking_ = true;
      load_num_ = (plant_den_.leading() / estimate->den().leading()) * estimate->num();
    }
  }
  const TransferFunction pade = pade_delay(delay_, pade_order_);
  characteristic_ = characteristic(pade.num(), pade.den());
}

VelocityLoop VelocityLoop::load_feedback(const NormalizedPlant& plant, ControllerTf controller, bool with_hf,
                                         int pade_order) {
  VelocityLoop loop(plant, std::move(controller), with_hf, true, pade_order);
  if (!loop.has_load_)
    throw std::invalid_argument("VelocityLoop::load_feedback: the plant has no two-mass realization to measure the load of");
  loop.measured_ = Measured::kLoad;
  const TransferFunction pade = pade_delay(loop.delay_, loop.pade_order_);
  loop.characteristic_ = loop.characteristic(pade.num(), pade.den());
  return loop;
}

VelocityLoop VelocityLoop::two_measurements(const NormalizedPlant& plant, TwoMeasurementController controller,
                                            bool with_hf, int pade_order) {
  if (!(controller.load.den() == controller.motor.feedback.den()))
    throw std::invalid_argument("VelocityLoop::two_measurements: the load channel must share the controller's denominator");
  if (controller.load.num().degree() > controller.load.den().degree())
    throw std::invalid_argument("VelocityLoop::two_measurements: the load channel must be proper");
  VelocityLoop loop = load_feedback(plant, std::move(controller.motor), with_hf, pade_order);
  loop.measured_ = Measured::kBoth;
  loop.load_channel_ = controller.load.num();
  const TransferFunction pade = pade_delay(loop.delay_, loop.pade_order_);
  loop.characteristic_ = loop.characteristic(pade.num(), pade.den());
  return loop;
}

Polynomial VelocityLoop::motor_channel_num() const {
  return measured_ == Measured::kLoad ? Polynomial{} : controller_.feedback.num();
}

Polynomial VelocityLoop::load_channel_num() const {
  switch (measured_) {
    case Measured::kLoad: return controller_.feedback.num();
    case Measured::kBoth: return load_channel_;
    case Measured::kMotor: break;
  }
  return {};
}

Polynomial VelocityLoop::measured_combination() const {
  if (measured_ == Measured::kMotor) return controller_.feedback.num() * plant_num_;
  return motor_channel_num() * plant_num_ + load_channel_num() * load_num_;
}

double VelocityLoop::controller_hf_limit() const noexcept {
  const Polynomial& num = controller_.feedback.num();
  const Polynomial& den = controller_.feedback.den();
  if (num.degree() < den.degree()) return 0.0;
  return std::abs(num.coefficient_of_power(num.degree()) / den.coefficient_of_power(den.degree()));
}

Polynomial VelocityLoop::characteristic(const Polynomial& delay_num, const Polynomial& delay_den) const {
  // The same products, in the same order, as rational(): both give the identical Δ.
  return controller_.feedback.den() * (act_den_ * delay_den) * fb_den_ * plant_den_ +
         (act_num_ * delay_num) * fb_num_ * measured_combination();
}

VelocityLoop::Values VelocityLoop::values(double omega) const noexcept {
  const Complex s(0.0, omega);
  Values v;
  v.nc = controller_.feedback.num()(s);
  v.dc = controller_.feedback.den()(s);
  v.nr = controller_.reference.num()(s);
  v.na = act_num_(s) * std::polar(1.0, -omega * delay_);
  v.da = act_den_(s);
  v.nf = fb_num_(s);
  v.df = fb_den_(s);
  v.np = plant_num_(s);
  v.dp = plant_den_(s);
  v.cm = measured_ == Measured::kLoad ? Complex(0.0, 0.0) : v.nc;
  v.cl = measured_ == Measured::kMotor ? Complex(0.0, 0.0)
         : measured_ == Measured::kLoad ? v.nc
                                         : load_channel_(s);
  v.nm = v.cm * v.np + (measured_ == Measured::kMotor ? Complex(0.0, 0.0) : v.cl * load_num_(s));
  v.delta = v.dc * v.da * v.df * v.dp + v.na * v.nf * v.nm;
  return v;
}

Complex VelocityLoop::controller(double omega) const noexcept {
  return controller_.feedback.frequency_response(omega);
}

Complex VelocityLoop::plant(double omega) const noexcept {
  const Complex s(0.0, omega);
  return plant_num_(s) / plant_den_(s);
}

Complex VelocityLoop::loop_gain(double omega) const noexcept {
  const Values v = values(omega);
  return (v.na * v.nf * v.nm) / (v.dc * v.da * v.df * v.dp);
}

Complex VelocityLoop::sensitivity(double omega) const noexcept {
  const Values v = values(omega);
  return v.dc * v.da * v.df * v.dp / v.delta;
}

Complex VelocityLoop::complementary(double omega) const noexcept {
  const Values v = values(omega);
  return v.na * v.nf * v.nm / v.delta;
}

Complex VelocityLoop::motor_tracking(double omega) const noexcept {
  const Values v = values(omega);
  return v.nr * v.na * v.df * v.np / v.delta;
}

Complex VelocityLoop::effort(double omega) const noexcept {
  const Values v = values(omega);
  return v.nr * v.da * v.df * v.dp / v.delta;
}

Complex VelocityLoop::load_tracking(double omega) const noexcept {
  if (!has_load_tracking_) return {kNaN, kNaN};
  const Values v = values(omega);
  return v.nr * v.na * v.df * load_num_(Complex(0.0, omega)) / v.delta;
}

Complex VelocityLoop::motor_from_load_torque(double omega) const noexcept {
  if (!has_load_) return {kNaN, kNaN};
  return responses(omega).motor_from_load_torque;
}

Complex VelocityLoop::load_from_load_torque(double omega) const noexcept {
  if (!has_load_) return {kNaN, kNaN};
  return responses(omega).load_from_load_torque;
}

Complex VelocityLoop::open_loop_load_from_load_torque(double omega) const noexcept {
  if (!has_load_) return {kNaN, kNaN};
  const Complex s(0.0, omega);
  return load_dist_num_(s) / plant_den_(s);
}

VelocityLoop::Responses VelocityLoop::responses(double omega) const noexcept {
  const Values v = values(omega);
  const Complex s(0.0, omega);
  const Complex open = v.na * v.nf * v.nm;
  const Complex plant_side = v.dc * v.da * v.df * v.dp;
  Responses r;
  r.loop_gain = open / plant_side;
  r.sensitivity = plant_side / v.delta;
  r.complementary = open / v.delta;
  r.motor_tracking = v.nr * v.na * v.df * v.np / v.delta;
  r.effort = v.nr * v.da * v.df * v.dp / v.delta;
  r.load_tracking = has_load_tracking_ ? v.nr * v.na * v.df * load_num_(s) / v.delta : Complex(kNaN, kNaN);
  if (!has_load_) {
    r.motor_from_load_torque = r.load_from_load_torque = r.open_loop_load_from_load_torque = {kNaN, kNaN};
    return r;
  }
  const Complex load_dist = load_dist_num_(s);
  // The measured velocity's disturbance is the open one times S; the other's is the open one minus
  // the torque's effect. With the two-mass identity nLl·nP − nLm·nMl = −s·dP/Il the dP cancels
  // exactly, which keeps the value finite at ω = 0 for an integrating plant.
  // ωm/Tl = (md·dc da df + s na nf cl/Il)/Δ, ωl/Tl = (ld·dc da df − s na nf cm/Il)/Δ: each channel's
  // torque reaches the other velocity through the shaft only (md·nl − np·ld = s·dp/Il).
  const Complex closed = v.dc * v.da * v.df;
  const Complex shaft = s * v.na * v.nf / load_inertia_;
  r.motor_from_load_torque = (motor_dist_num_(s) * closed + shaft * v.cl) / v.delta;
  r.load_from_load_torque = (load_dist * closed - shaft * v.cm) / v.delta;
  r.open_loop_load_from_load_torque = load_dist / v.dp;
  return r;
}

ClosedLoopTransfer VelocityLoop::rational(const Polynomial& delay_num, const Polynomial& delay_den) const {
  const Polynomial& dc = controller_.feedback.den();
  const Polynomial& nr = controller_.reference.num();
  const Polynomial na = act_num_ * delay_num;
  const Polynomial da = act_den_ * delay_den;
  const Polynomial open_den = dc * da * fb_den_ * plant_den_;
  const Polynomial open_num = na * fb_num_ * measured_combination();
  const Polynomial delta = open_den + open_num;
  ClosedLoopTransfer cl{delta,
                        TransferFunction(open_den, delta),
                        TransferFunction(open_num, delta),
                        TransferFunction(nr * na * fb_den_ * plant_num_, delta),
                        TransferFunction(nr * da * fb_den_ * plant_den_, delta),
                        std::nullopt,
                        std::nullopt,
                        std::nullopt,
                        std::nullopt};
  if (has_load_tracking_) cl.load_tracking = TransferFunction(nr * na * fb_den_ * load_num_, delta);
  if (has_load_) {
    // As responses(); u/Tl = −nf da (cm·md + cl·ld)/Δ.
    const Polynomial closed = dc * da * fb_den_;
    const Polynomial shaft = (1.0 / load_inertia_) * (Polynomial{1.0, 0.0} * na * fb_num_);
    const Polynomial cm = motor_channel_num(), cl_load = load_channel_num();
    cl.motor_from_load_torque = TransferFunction(motor_dist_num_ * closed + shaft * cl_load, delta);
    cl.load_from_load_torque = TransferFunction(load_dist_num_ * closed + (-1.0) * (shaft * cm), delta);
    cl.effort_from_load_torque =
        TransferFunction(-1.0 * (fb_num_ * (cm * motor_dist_num_ + cl_load * load_dist_num_) * da), delta);
  }
  return cl;
}

ClosedLoopTransfer VelocityLoop::closed_loop() const {
  const TransferFunction pade = pade_delay(delay_, pade_order_);
  return rational(pade.num(), pade.den());
}

bool VelocityLoop::stable() const { return core::is_hurwitz(characteristic_); }

}  // namespace servotwin::tuning
