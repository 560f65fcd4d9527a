#include "servotwin/tuning/hinf.hpp"

#include <cmath>
#include <string>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/hinf.hpp"
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

/// The generalized plant of C7.14 for the velocity (k = 2: Pe = Pm/s) or the position loop (k = 3:
/// Pe = Pm/s^2), as documented in the header.
core::StateSpace mixed_sensitivity_plant(const NormalizedPlant& plant, const VelocityHinfWeights& weights, int k) {
  check_weights(weights);
  detail::require_ratio(plant.r, "r");
  const double r = plant.r;
  const double w0s = weights.omega_0s;
  const double w0t = weights.omega_0t.value_or(r);
  // Pe = Pm/s^(k-1) = N / (s^(k-1) (s + a) D), Im = 1 (normalized_plant.hpp).
  const Polynomial antiresonance{1.0, 2.0 * plant.zeta_z, 1.0};
  const Polynomial resonance{1.0, 2.0 * plant.zeta_p * r, r * r};
  // Known HF dynamics (torque path, measurement filter, the delay as its first-order Padé
  // approximant) enter Pe: C7.14 allows designing with them, and a controller designed without a
  // delay loses most of its bandwidth to it. V keeps its shape: its numerator gets the same poles.
  Polynomial extra_num{1.0}, extra_den{1.0};
  if (!plant.hf.empty()) {
    const core::TransferFunction act = plant.hf.actuator_rational(), fb = plant.hf.feedback_rational();
    extra_num = act.num() * fb.num();
    extra_den = act.den() * fb.den();
    if (plant.hf.delay_s) {
      const core::TransferFunction pade = pade_delay(*plant.hf.delay_s, 1);
      extra_num = extra_num * pade.num();
      extra_den = extra_den * pade.den();
    }
  }
  const Polynomial den = power(Polynomial{1.0, 0.0}, k - 1) * Polynomial{1.0, plant.a} * resonance * extra_den;
  const Polynomial target = target_poles(w0s, weights.xi_v, r, k);
  const core::StateSpace g = shared_realization(den, target * extra_den, antiresonance * extra_num);

  const Polynomial lead_t{1.0, w0t}, lead_r{1.0, r};
  const core::TransferFunction w2((1.0 / (weights.mt * std::pow(w0t, k) * r * r)) * (power(lead_t, k) * lead_r * lead_r),
                                  target);
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

/// K = K0/s as a 1-DoF law u = K (reference - measurement) with inputs [reference, measurement],
/// balanced, with its poles.
void add_compensator(HinfDesign& d) {
  core::StateSpace integrator;
  integrator.A = MatrixXd::Zero(1, 1);
  integrator.B = MatrixXd::Ones(1, 1);
  integrator.C = MatrixXd::Ones(1, 1);
  integrator.D = MatrixXd::Zero(1, 1);
  const core::StateSpace k = core::balance_states(core::series(d.k0, integrator));
  d.compensator.A = k.A;
  d.compensator.B.resize(k.states(), 2);
  d.compensator.B << k.B, -k.B;
  d.compensator.C = k.C;
  d.compensator.D.resize(1, 2);
  d.compensator.D << k.D, -k.D;
  d.controller_poles = detail::sorted_poles(k.A);
  d.controller_stable = stable_except_integrator(d.controller_poles);
}

HinfDesign design(const NormalizedPlant& plant, const VelocityHinfWeights& weights, int k) {
  HinfDesign d;
  d.generalized_plant = mixed_sensitivity_plant(plant, weights, k);
  d.omega_0t = weights.omega_0t.value_or(plant.r);
  core::HinfOptions options;
  options.backoff = weights.backoff;
  const core::HinfSynthesis s = core::hinf_synthesis(d.generalized_plant, 1, 1, options);
  d.k0 = s.design.controller;
  d.gamma_optimal = s.gamma_optimal;
  d.gamma = s.design.gamma;
  d.closed_loop_norm = s.closed_loop_norm;
  add_compensator(d);
  return d;
}

}  // namespace

core::StateSpace velocity_mixed_sensitivity_plant(const NormalizedPlant& plant, const VelocityHinfWeights& weights) {
  return mixed_sensitivity_plant(plant, weights, 2);
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
