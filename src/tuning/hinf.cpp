#include "servotwin/tuning/hinf.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/hinf.hpp"
#include "servotwin/core/model_reduction.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/lqg.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {

namespace {

using core::Polynomial;
using Eigen::MatrixXd;

void check_weights(const VelocityHinfWeights& w) {
  detail::require_positive(w.omega_0s, "omega_0s", "a pole-pair frequency w0S");
  if (w.omega_0t) detail::require_positive(*w.omega_0t, "omega_0t", "a bandwidth cap w0T");
  detail::require_finite(w.xi_v, "xi_v");
  if (w.xi_v < kXiVMin || w.xi_v > kXiVMax)
    throw core::InputError(core::at_field("xi_v"),
                           "expected a damping in [0.707, 1] (catalog C7.14), got " + detail::show(w.xi_v));
  detail::require_positive(w.ms, "ms", "a sensitivity peak limit");
  detail::require_positive(w.mt, "mt", "a tracking peak limit");
  if (!(w.backoff >= 1.0 && w.backoff <= 10.0))
    throw core::InputError(core::at_field("backoff"), "expected a gamma backoff in [1, 10], got " + detail::show(w.backoff));
  if (w.rolloff) detail::require_positive(*w.rolloff, "rolloff", "a roll-off corner frequency");
  if (w.controller_order && *w.controller_order < 1)
    throw core::InputError(core::at_field("controller_order"),
                           "expected a number of controller states >= 1, got " + std::to_string(*w.controller_order));
}

/// s^2 + 2 zeta w s + w^2.
Polynomial quadratic(double omega, double zeta) { return Polynomial{1.0, 2.0 * zeta * omega, omega * omega}; }

/// The rational factors the design model adds to the first mode's Pm: the known HF dynamics
/// (delay as Padé(1)) and the higher modes, kept apart because V treats them differently.
struct ExtraDynamics {
  Polynomial hf_num{1.0}, hf_den{1.0};
  Polynomial modes_num{1.0}, modes_den{1.0};
  Polynomial relocated{1.0};  ///< the higher pairs at damping xi_v (V's numerator, kActive)
};

ExtraDynamics extra_dynamics(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  ExtraDynamics e;
  // Known HF dynamics (torque path, measurement filter, the delay as its first-order Padé
  // approximant) enter Pe: C7.14 allows designing with them, and a controller designed without a
  // delay loses most of its bandwidth to it.
  if (!plant.hf.empty()) {
    const core::TransferFunction act = plant.hf.actuator_rational(), fb = plant.hf.feedback_rational();
    e.hf_num = act.num() * fb.num();
    e.hf_den = act.den() * fb.den();
    if (plant.hf.delay_s) {
      const core::TransferFunction pade = pade_delay(*plant.hf.delay_s, 1);
      e.hf_num = e.hf_num * pade.num();
      e.hf_den = e.hf_den * pade.den();
    }
  }
  // The roll-off filter the controller will carry at its output: designed with as a known lag.
  if (weights.rolloff) {
    e.hf_num = *weights.rolloff * e.hf_num;
    e.hf_den = e.hf_den * Polynomial{1.0, *weights.rolloff};
  }
  if (weights.modes == ModeHandling::kFirstMode) return e;
  // Each higher mode with unit DC gain, as NormalizedPlant::motor() has it.
  for (const fit::Mode& m : plant.higher_modes) {
    // A practically unobservable mode stays out of the design model: the motor can neither see nor
    // drive it, relocating it would cost a controller gain ~1/(wp/wz - 1), and its barely damped,
    // nearly cancelled pair makes the synthesis' Riccati equations ill-posed (C7.19's frame with a
    // 5 ms delay finds no controller with it). The tuner still evaluates the loop with it.
    if (practically_unobservable(m)) continue;
    const double wz = m.antiresonance.omega_rad_s, wp = m.resonance.omega_rad_s;
    e.modes_num = ((wp * wp) / (wz * wz)) * (e.modes_num * quadratic(wz, m.antiresonance.zeta));
    e.modes_den = e.modes_den * quadratic(wp, m.resonance.zeta);
    e.relocated = e.relocated * quadratic(wp, weights.xi_v);
  }
  return e;
}

/// p^k, k >= 0.
Polynomial power(const Polynomial& p, int k) {
  Polynomial out{1.0};
  for (int i = 0; i < k; ++i) out = out * p;
  return out;
}

/// (s + w0S)^k (s^2 + 2 xi r s + r^2): the closed-loop poles V and W2 ask for (k = 2 velocity,
/// 3 position).
Polynomial target_poles(double omega_0s, double xi_v, double r, int k) {
  return power(Polynomial{1.0, omega_0s}, k) * Polynomial{1.0, 2.0 * xi_v * r, r * r};
}

/// Observable canonical form of [n_w / den, n_u / den] + [d_w, 0] over one monic den: both
/// inputs see the same states, so V's integrators are Pe's.
core::StateSpace shared_realization(const Polynomial& den, const Polynomial& num_w, const Polynomial& num_u) {
  const int n = den.degree();
  const double lead = den.leading();
  const auto coefficient = [&](const Polynomial& p, int power) { return p.coefficient_of_power(power) / lead; };
  const double d_w = num_w.degree() == n ? coefficient(num_w, n) : 0.0;
  core::StateSpace g;
  g.A = MatrixXd::Zero(n, n);
  g.B = MatrixXd::Zero(n, 2);
  g.C = MatrixXd::Zero(1, n);
  g.D = MatrixXd::Zero(1, 2);
  for (int i = 0; i < n; ++i) {
    const int power = n - 1 - i;
    g.A(i, 0) = -coefficient(den, power);
    if (i + 1 < n) g.A(i, i + 1) = 1.0;
    g.B(i, 0) = coefficient(num_w, power) - d_w * coefficient(den, power);
    g.B(i, 1) = coefficient(num_u, power);
  }
  g.C(0, 0) = 1.0;
  g.D(0, 0) = d_w;
  return g;
}

/// Which velocity the loop measures: the motor's (C7.14) or the load's (C7.17).
enum class Sensor { kMotor, kLoad };

/// The plant's numerator over (s + a)(s^2 + 2 zeta_p r s + r^2): the motor's antiresonance, or the
/// load's coupling b/k s + 1 of the two-mass realization (InputError without one).
Polynomial measured_numerator(const NormalizedPlant& plant, Sensor sensor) {
  if (sensor == Sensor::kMotor) return Polynomial{1.0, 2.0 * plant.zeta_z, 1.0};
  if (!plant.higher_modes.empty())
    throw core::InputError(core::at_field("plant"), "the load-side design (C7.17) needs a two-mass plant; this one has " +
                                                         std::to_string(plant.higher_modes.size()) + " higher mode(s)");
  const std::optional<core::TransferFunction> load = plant.load();
  if (!load)
    throw core::InputError(core::at_field("plant"),
                           "the load-side design (C7.17) needs a two-mass realization, and this plant has none "
                           "(its friction terms would be negative)");
  return (1.0 / load->den().leading()) * load->num();
}

/// The generalized plant of C7.14 for the velocity (k = 2: Pe = Pm/s) or the position loop (k = 3:
/// Pe = Pm/s^2), or of C7.17 for the load velocity (k = 2, Pe = Pl/s, W2's numerator (s + w0T)^4),
/// as documented in the header.
core::StateSpace mixed_sensitivity_plant(const NormalizedPlant& plant, const VelocityHinfWeights& weights, int k,
                                         Sensor sensor = Sensor::kMotor) {
  check_weights(weights);
  detail::require_ratio(plant.r, "r");
  const double r = plant.r;
  const double w0s = weights.omega_0s;
  const double w0t = weights.omega_0t.value_or(r);
  // Pe = Pm/s^(k-1) = N / (s^(k-1) (s + a) D), Im = 1 (normalized_plant.hpp).
  const Polynomial numerator = measured_numerator(plant, sensor);
  const Polynomial resonance{1.0, 2.0 * plant.zeta_p * r, r * r};
  const ExtraDynamics extra = extra_dynamics(plant, weights);
  const Polynomial den = power(Polynomial{1.0, 0.0}, k - 1) * Polynomial{1.0, plant.a} * resonance * extra.hf_den *
                         extra.modes_den;
  const Polynomial target = target_poles(w0s, weights.xi_v, r, k);
  // V keeps its shape over the HF factors; over the higher modes it either keeps them (passive:
  // the controller may cancel them) or relocates them (active, eq. 7.164).
  const Polynomial v_modes = weights.modes == ModeHandling::kActive ? extra.relocated : extra.modes_den;
  const core::StateSpace g =
      shared_realization(den, target * extra.hf_den * v_modes, numerator * extra.hf_num * extra.modes_num);

  const Polynomial lead_t{1.0, w0t}, lead_r{1.0, r};
  // The load sees no antiresonance to notch: C7.17's W2 rolls off with (s + w0T)^4 alone.
  const Polynomial w2_num = sensor == Sensor::kLoad ? power(lead_t, 4) : power(lead_t, k) * lead_r * lead_r;
  const core::TransferFunction w2((1.0 / (weights.mt * std::pow(w0t, k) * r * r)) * w2_num, target);
  const core::StateSpace w = core::to_state_space(w2);

  const Eigen::Index ng = g.states(), nw = w.states();
  core::StateSpace p;
  p.A = MatrixXd::Zero(ng + nw, ng + nw);
  p.A.topLeftCorner(ng, ng) = g.A;
  p.A.bottomRightCorner(nw, nw) = w.A;
  p.B = MatrixXd::Zero(ng + nw, 2);
  p.B.topRows(ng) = g.B;
  p.B.bottomRightCorner(nw, 1) = w.B;
  p.C = MatrixXd::Zero(3, ng + nw);
  p.D = MatrixXd::Zero(3, 2);
  p.C.row(0).head(ng) = g.C / weights.ms;
  p.D.row(0) = g.D / weights.ms;
  p.C.row(1).tail(nw) = w.C;
  p.D(1, 1) = w.D(0, 0);
  p.C.row(2).head(ng) = -g.C;
  p.D.row(2) = -g.D;
  return p;
}

/// Hankel singular values at or below this fraction of the largest are pole-zero cancellations
/// (exact ones show at 1e-30, ill-conditioned ones near 1e-7): the default controller drops them,
/// changing K by at most 2e-6 n of its Hankel scale.
constexpr double kCancellationLevel = 1e-6;

std::vector<double> as_vector(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

/// K = K0/s, reduced to `order` states when asked: the Hankel singular values of its stable part
/// are recorded either way.
core::StateSpace compensator_transfer(HinfDesign& d, std::optional<int> order, bool minimal) {
  core::StateSpace integrator;
  integrator.A = MatrixXd::Zero(1, 1);
  integrator.B = MatrixXd::Ones(1, 1);
  integrator.C = MatrixXd::Ones(1, 1);
  integrator.D = MatrixXd::Zero(1, 1);
  const core::StateSpace k = core::series(d.k0, integrator);
  d.full_order = static_cast<int>(k.states());
  if (!order && !minimal) return k;
  core::StableSplit split;
  try {
    split = core::stable_split(k, core::kStableBoundary);
    if (!order) d.hankel = as_vector(core::hankel_singular_values(split.stable));
  } catch (const std::domain_error&) {
    if (order) throw;
    d.hankel.clear();  // poles too close to the boundary to split: keep K as it is
    return k;
  }
  std::optional<int> target = order;
  if (!target) {
    // The minimal realization: W2's poles (the target pair and (s + w0S)^k) cancel in K, which
    // shows as Hankel singular values near rounding level; those states go, nothing else.
    const double floor = kCancellationLevel * (d.hankel.empty() ? 0.0 : d.hankel.front());
    const auto cancelled = std::count_if(d.hankel.begin(), d.hankel.end(), [&](double h) { return h <= floor; });
    if (cancelled == 0) return k;
    target = d.full_order - static_cast<int>(cancelled);
  }
  const int kept = static_cast<int>(split.unstable.states());
  if (*target < kept || *target > d.full_order)
    throw core::InputError(core::at_field("controller_order"),
                           "expected between " + std::to_string(kept) + " (the controller's integrator and unstable poles) and " +
                               std::to_string(d.full_order) + " (its full order) states, got " + std::to_string(*target));
  const core::BalancedTruncation bt = core::balanced_truncation_stable_part(split, *target);
  d.hankel = as_vector(bt.hankel);
  d.reduction_error_bound = bt.error_bound;
  return bt.reduced;
}

/// K followed by the roll-off F = ωf/(s + ωf) (VelocityHinfWeights::rolloff).
core::StateSpace with_rolloff(const core::StateSpace& k, std::optional<double> rolloff) {
  if (!rolloff) return k;
  core::StateSpace f;
  f.A = MatrixXd::Constant(1, 1, -*rolloff);
  f.B = MatrixXd::Constant(1, 1, *rolloff);
  f.C = MatrixXd::Constant(1, 1, 1.0);
  f.D = MatrixXd::Zero(1, 1);
  return core::series(k, f);
}

/// K = K0/s (with its roll-off) as a 1-DoF law u = K (reference - measurement) with inputs
/// [reference, measurement], balanced, with its poles.
void add_compensator(HinfDesign& d, const VelocityHinfWeights& weights) {
  const core::StateSpace k = core::balance_states(
      with_rolloff(compensator_transfer(d, weights.controller_order, weights.minimal_realization), weights.rolloff));
  if (weights.rolloff) ++d.full_order;  // F's state, kept by every reduction
  d.compensator.A = k.A;
  d.compensator.B.resize(k.states(), 2);
  d.compensator.B << k.B, -k.B;
  d.compensator.C = k.C;
  d.compensator.D.resize(1, 2);
  d.compensator.D << k.D, -k.D;
  d.controller_poles = detail::sorted_poles(k.A);
  d.controller_stable = stable_except_integrator(d.controller_poles);
}

HinfDesign design(const NormalizedPlant& plant, const VelocityHinfWeights& weights, int k,
                  Sensor sensor = Sensor::kMotor) {
  HinfDesign d;
  d.generalized_plant = mixed_sensitivity_plant(plant, weights, k, sensor);
  d.omega_0t = weights.omega_0t.value_or(plant.r);
  core::HinfOptions options;
  options.backoff = weights.backoff;
  const core::HinfSynthesis s = core::hinf_synthesis(d.generalized_plant, 1, 1, options);
  d.k0 = s.design.controller;
  d.gamma_optimal = s.gamma_optimal;
  d.gamma = s.design.gamma;
  d.closed_loop_norm = s.closed_loop_norm;
  add_compensator(d, weights);
  return d;
}

}  // namespace

bool practically_unobservable(const fit::Mode& mode) noexcept {
  return mode.resonance.omega_rad_s < kUnobservableModeRatio * mode.antiresonance.omega_rad_s;
}

const char* to_string(ModeHandling m) noexcept {
  switch (m) {
    case ModeHandling::kPassive: return "passive";
    case ModeHandling::kActive: return "active";
    case ModeHandling::kFirstMode: break;
  }
  return "first";
}

std::optional<ModeHandling> parse_mode_handling(const std::string& text) noexcept {
  for (ModeHandling m : {ModeHandling::kFirstMode, ModeHandling::kPassive, ModeHandling::kActive})
    if (text == to_string(m)) return m;
  return std::nullopt;
}

core::StateSpace velocity_mixed_sensitivity_plant(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return mixed_sensitivity_plant(plant, weights, 2);
}

core::StateSpace load_side_mixed_sensitivity_plant(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return mixed_sensitivity_plant(plant, weights, 2, Sensor::kLoad);
}

HinfDesign load_side_hinf(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return design(plant, weights, 2, Sensor::kLoad);
}

core::StateSpace position_mixed_sensitivity_plant(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return mixed_sensitivity_plant(plant, weights, 3);
}

HinfDesign velocity_hinf(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return design(plant, weights, 2);
}

HinfDesign position_hinf(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return design(plant, weights, 3);
}

}  // namespace servotwin::tuning
