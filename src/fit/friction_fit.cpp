#include "servotwin/fit/friction_fit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "friction_model.hpp"
#include "misfit.hpp"
#include "servotwin/core/levenberg_marquardt.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;
using detail::ChainParameters;
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// θ = (ln J1…ln Jn+1, ln k1…ln kn, ln b1…ln bn, bv/bv_ref, Mm/T_ref, Ml/T_ref[, ln p][, T ωz])
/// for a chain of n shafts: logs keep the positive quantities positive; the three that may be 0
/// are scaled to order one (T_ref the median excitation amplitude, bv_ref = J1 ωz of the start) so
/// that LM's central differences and box bounds act on comparable numbers. The lag pole p and the
/// delay T, when the linear fit has them, are fitted again: friction bends the linear fit's phase,
/// and with it its lag. On the load side (one shaft) θ[0] is ln J (J = Jm + Jl), θ[1] the logit of
/// the motor's share s = Jm/J, and k, bs carry the factor 4s(1 − s): the linear part's resonance
/// (ωp² = k J/(Jm Jl)) is then free of s, which only the friction's describing functions tell
/// (linear data leave it where it starts, 1/2).
struct Layout {
  std::size_t shafts = 1;
  Eigen::Index lag = -1, delay = -1, size = 0;
  Layout(const PlantModel& m, std::size_t n) : shafts(n), size(friction_count()) {
    if (m.lag_pole_rad_s) lag = size++;
    if (m.delay_s) delay = size++;
  }
  [[nodiscard]] Eigen::Index n() const { return static_cast<Eigen::Index>(shafts); }
  [[nodiscard]] Eigen::Index inertia(std::size_t i) const { return static_cast<Eigen::Index>(i); }
  [[nodiscard]] Eigen::Index stiffness(std::size_t i) const { return n() + 1 + static_cast<Eigen::Index>(i); }
  [[nodiscard]] Eigen::Index damping(std::size_t i) const { return 2 * n() + 1 + static_cast<Eigen::Index>(i); }
  /// The parameters held as logarithms (inertias, stiffnesses, dampings).
  [[nodiscard]] Eigen::Index logs() const { return 3 * n() + 1; }
  [[nodiscard]] Eigen::Index viscous() const { return logs(); }
  [[nodiscard]] Eigen::Index motor_coulomb() const { return logs() + 1; }
  [[nodiscard]] Eigen::Index load_coulomb() const { return logs() + 2; }
  [[nodiscard]] Eigen::Index friction_count() const { return logs() + 3; }
};

/// The friction fit is refused when its rms log error exceeds the linear fit's by this factor (on
/// the same points): noise alone leaves the two within a few per cent.
constexpr double kWorseThanLinear = 1.25;
/// ... and by more than this (0.1 % relative error: on noise-free data both are near 0 and their
/// ratio means nothing).
constexpr double kNegligibleRms = 1e-3;

/// What the residuals need besides θ.
struct Context {
  double viscous = 1.0;   ///< bv_ref
  double torque = 1.0;    ///< T_ref
  double time = 1.0;      ///< 1/ωz of the start, the delay's unit
  PlantModel linear;      ///< the linear fit: output kind, lag and delay present or not
  SensorSide sensor = SensorSide::kMotor;
  Layout layout;
};

/// The linear fit's structure (output kind) with θ's lag and delay.
PlantModel actuator_of(const Eigen::VectorXd& t, const Context& c) {
  PlantModel m;
  m.output = c.linear.output;
  if (c.layout.lag >= 0) m.lag_pole_rad_s = std::exp(t[c.layout.lag]);
  if (c.layout.delay >= 0) m.delay_s = t[c.layout.delay] * c.time;
  return m;
}

/// The load side's share s = Jm/J from its logit θ[1].
double motor_share(const Eigen::VectorXd& t) { return 1.0 / (1.0 + std::exp(-t[1])); }

ChainParameters physical_of(const Eigen::VectorXd& t, const Context& c) {
  const Layout& l = c.layout;
  const double viscous = t[l.viscous()] * c.viscous, mm = t[l.motor_coulomb()] * c.torque;
  const double ml = t[l.load_coulomb()] * c.torque;
  if (c.sensor == SensorSide::kLoad && l.shafts == 1) {
    const double total = std::exp(t[0]), share = motor_share(t), q = 4.0 * share * (1.0 - share);
    return detail::two_mass_chain(share * total, (1.0 - share) * total, q * std::exp(t[2]), q * std::exp(t[3]), viscous, mm, ml);
  }
  ChainParameters p;
  if (c.sensor == SensorSide::kLoad) {
    // ln ΣJ, then each further mass's log ratio to the motor's.
    double weights = 1.0;
    for (std::size_t i = 1; i <= l.shafts; ++i) weights += std::exp(t[l.inertia(i)]);
    const double motor = std::exp(t[0]) / weights;
    p.inertia.push_back(motor);
    for (std::size_t i = 1; i <= l.shafts; ++i) p.inertia.push_back(motor * std::exp(t[l.inertia(i)]));
  } else {
    for (std::size_t i = 0; i <= l.shafts; ++i) p.inertia.push_back(std::exp(t[l.inertia(i)]));
  }
  for (std::size_t i = 0; i < l.shafts; ++i) {
    p.stiffness.push_back(std::exp(t[l.stiffness(i)]));
    p.damping.push_back(std::exp(t[l.damping(i)]));
  }
  p.bv = viscous;
  p.mm = mm;
  p.ml = ml;
  return p;
}

struct Point {
  double omega = 0.0;
  Complex log_meas;
  double velocity = 0.0;  ///< the measured side's |V| = |P|·T (velocity output) or ω|P|·T (position)
  double weight = 1.0;    ///< detail::log_residual_weight, as the linear fit's
  /// The weights of the log error's real and imaginary parts: `weight`, lowered where the measured
  /// amplitude's own noise moves the model (errors_in_variables).
  double weight_re = 1.0, weight_im = 1.0;
};

/// |V| of a measured point: the input amplitude times the measured gain (times ω for a position
/// output).
double velocity_of(const core::FrequencyPoint& q, OutputKind output) {
  return std::abs(q.value) * q.amplitude * (output == OutputKind::kPosition ? kTwoPi * q.freq_hz : 1.0);
}

bool residuals(const Eigen::VectorXd& t, const std::vector<Point>& points, const Context& c, Eigen::VectorXd& r) {
  if ((t.head(c.layout.logs()).array().abs() > 700.0).any()) return false;
  const ChainParameters p = physical_of(t, c);
  const PlantModel act = actuator_of(t, c);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Complex m = detail::chain_response(points[k].omega, points[k].velocity, p, act, c.sensor);
    if (!std::isfinite(m.real()) || !std::isfinite(m.imag()) || m == 0.0) return false;
    const Complex e = std::log(m) - points[k].log_meas;
    r[static_cast<Eigen::Index>(2 * k)] = points[k].weight_re * e.real();
    r[static_cast<Eigen::Index>(2 * k + 1)] = points[k].weight_im * std::remainder(e.imag(), kTwoPi);
  }
  return true;
}

/// sqrt(Σ|ln(P_model/P_meas)|²/m) without the weights (FitResult::rms_log_error).
double unweighted_rms(const Eigen::VectorXd& r, const std::vector<Point>& points) {
  double sum = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const double re = r[static_cast<Eigen::Index>(2 * k)] / points[k].weight_re;
    const double im = r[static_cast<Eigen::Index>(2 * k + 1)] / points[k].weight_im;
    sum += re * re + im * im;
  }
  return std::sqrt(sum / static_cast<double>(points.size()));
}

/// σ²(JᵀJ)⁻¹ over the free parameters; a parameter held fixed (`fixed`: bv of an integrator, the
/// split on the load side, pinned by equal bounds) is not estimated, so its column is left out and
/// its row and column are zero (keeping it would spread the data's information over a parameter
/// that cannot move).
Eigen::MatrixXd free_covariance(const core::LmResult& lm, bool known_std, const std::vector<Eigen::Index>& fixed) {
  const Eigen::Index n = lm.jacobian.cols();
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::find(fixed.begin(), fixed.end(), i) == fixed.end()) keep.push_back(i);
  Eigen::MatrixXd j(lm.jacobian.rows(), static_cast<Eigen::Index>(keep.size()));
  for (std::size_t c = 0; c < keep.size(); ++c) j.col(static_cast<Eigen::Index>(c)) = lm.jacobian.col(keep[c]);
  const double dof = static_cast<double>(j.rows() - j.cols());
  const double sigma2 = known_std ? 1.0 : dof > 0.0 ? lm.residual.squaredNorm() / dof : kNan;
  const Eigen::MatrixXd free = core::least_squares_covariance(j, sigma2);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t a = 0; a < keep.size(); ++a)
    for (std::size_t b = 0; b < keep.size(); ++b)
      c(keep[a], keep[b]) = free(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  return c;
}

/// Errors in variables: each point's model uses its measured amplitude |V| = |P_meas|·T, so the
/// measurement's noise enters the model too. With ln P_meas = ln P + δr + jδi (δr, δi of equal
/// variance s²) and g = ∂ln P_model/∂ln|V| (complex), the log error is
/// e = (g − 1)δr − jδi: Re e has variance (Re g − 1)² s², Im e (Im g² + 1) s². Near the
/// antiresonance, where the load's describing function sets the damping, |Re g − 1| reaches 5–10
/// and the plain weights would read that noise as misfit (reduced χ² 4 on 0.5 % noise). The
/// weights are divided by those factors, never raised (where g ≈ 1, friction-dominated points
/// whose magnitude follows the measurement, the model's own error, not the noise, is what is
/// left: such points keep their weight). g by central differences at the first solution.
void errors_in_variables(const Eigen::VectorXd& t, const Context& c, std::vector<Point>& points) {
  const ChainParameters p = physical_of(t, c);
  const PlantModel act = actuator_of(t, c);
  constexpr double h = 1e-5;
  for (Point& q : points) {
    const Complex up = detail::chain_response(q.omega, q.velocity * (1.0 + h), p, act, c.sensor);
    const Complex down = detail::chain_response(q.omega, q.velocity * (1.0 - h), p, act, c.sensor);
    const Complex g = (std::log(up) - std::log(down)) / (std::log1p(h) - std::log1p(-h));
    if (!std::isfinite(g.real()) || !std::isfinite(g.imag())) continue;
    q.weight_re = q.weight / std::max(1.0, std::abs(g.real() - 1.0));
    q.weight_im = q.weight / std::sqrt(1.0 + g.imag() * g.imag());
  }
}

/// A value and its standard deviation from θ's covariance by the delta method, g = ∂value/∂θ.
Estimate delta(double value, const Eigen::VectorXd& g, const Eigen::MatrixXd& c) {
  return {value, detail::std_of_variance(g.dot(c * g))};
}

/// Numerical gradient of a scalar function of θ (central differences on θ's own scale).
template <class F>
Eigen::VectorXd gradient(const Eigen::VectorXd& t, F f) {
  Eigen::VectorXd g(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(t[i]));
    Eigen::VectorXd a = t, b = t;
    a[i] += h;
    b[i] -= h;
    g[i] = (f(a) - f(b)) / (2.0 * h);
  }
  return g;
}

/// A quantity of the linear part (one mode's frequency or damping, the rigid pole) as a function
/// of θ, for the delta method; NaN where a perturbed θ loses the mode.
enum class Modal { kAntiresonanceOmega, kAntiresonanceZeta, kResonanceOmega, kResonanceZeta, kRigidPole, kRatio };

double modal_value(const PlantModel& lp, std::size_t mode, Modal which) {
  if (which == Modal::kRigidPole) return lp.rigid_pole_rad_s;
  if (mode >= lp.modes.size()) return kNan;
  const Mode& m = lp.modes[mode];
  switch (which) {
    case Modal::kAntiresonanceOmega: return m.antiresonance.omega_rad_s;
    case Modal::kAntiresonanceZeta: return m.antiresonance.zeta;
    case Modal::kResonanceOmega: return m.resonance.omega_rad_s;
    case Modal::kResonanceZeta: return m.resonance.zeta;
    default: return m.resonance.omega_rad_s / m.antiresonance.omega_rad_s;
  }
}

void fill_estimates(CoulombFit& out, const Eigen::VectorXd& t, const Eigen::MatrixXd& c, const Context& ctx, RigidKind rigid) {
  const ChainParameters p = physical_of(t, ctx);
  const Layout& l = ctx.layout;
  const bool load = ctx.sensor == SensorSide::kLoad;
  auto scaled_param = [&](Eigen::Index i, double scale) {
    return Estimate{t[i] * scale, scale * detail::std_of_variance(c(i, i))};
  };
  // On the load side the inertias, k and bs are functions of θ: delta method.
  const auto physical = [&](std::vector<double> ChainParameters::*member, std::size_t i) {
    const auto value = [&, member, i](const Eigen::VectorXd& x) { return (physical_of(x, ctx).*member)[i]; };
    return delta((p.*member)[i], gradient(t, value), c);
  };
  out.inertias.clear();
  out.stiffnesses.clear();
  out.shaft_dampings.clear();
  for (std::size_t i = 0; i <= l.shafts; ++i)
    out.inertias.push_back(load ? physical(&ChainParameters::inertia, i) : detail::log_estimate(t, c, l.inertia(i)));
  for (std::size_t i = 0; i < l.shafts; ++i) {
    out.stiffnesses.push_back(load ? physical(&ChainParameters::stiffness, i) : detail::log_estimate(t, c, l.stiffness(i)));
    out.shaft_dampings.push_back(load ? physical(&ChainParameters::damping, i) : detail::log_estimate(t, c, l.damping(i)));
  }
  out.motor_inertia = out.inertias.front();
  out.load_inertia = out.inertias.back();
  out.stiffness = l.shafts == 1 ? out.stiffnesses.front() : Estimate{kNan, kNan};
  out.shaft_damping = l.shafts == 1 ? out.shaft_dampings.front() : Estimate{kNan, kNan};
  out.total_inertia = load ? detail::log_estimate(t, c, 0) : Estimate{p.total_inertia(), kNan};
  if (load && l.shafts == 1) {
    const double share = motor_share(t);
    out.motor_share = {share, share * (1.0 - share) * detail::std_of_variance(c(1, 1))};
  } else if (load) {
    const auto share = [&](const Eigen::VectorXd& x) {
      const ChainParameters q = physical_of(x, ctx);
      return q.inertia.front() / q.total_inertia();
    };
    out.motor_share = delta(share(t), gradient(t, share), c);
  } else {
    out.motor_share = {p.inertia.front() / p.total_inertia(), kNan};
  }
  out.viscous_damping = scaled_param(l.viscous(), ctx.viscous);
  out.motor_coulomb = scaled_param(l.motor_coulomb(), ctx.torque);
  out.load_coulomb = scaled_param(l.load_coulomb(), ctx.torque);
  out.model = detail::chain_linear_part(p, actuator_of(t, ctx), rigid, ctx.sensor);
  // K = p/J1 (p/ΣJ on the load side; without a lag p = 1): ln K = ln p − θ[0].
  double var_ln_gain = c(0, 0);
  if (l.lag >= 0) var_ln_gain += c(l.lag, l.lag) - 2.0 * c(0, l.lag);
  out.gain = {out.model.gain, out.model.gain * detail::std_of_variance(var_ln_gain)};
  out.lag_pole_rad_s = l.lag >= 0 ? detail::log_estimate(t, c, l.lag) : Estimate{kNan, kNan};
  out.delay_s = l.delay >= 0 ? scaled_param(l.delay, ctx.time) : Estimate{kNan, kNan};
  out.theta = t;
  out.covariance = c;
  const auto estimate = [&](std::size_t mode, Modal which) {
    const auto value = [&, mode, which](const Eigen::VectorXd& x) {
      return modal_value(detail::chain_linear_part(physical_of(x, ctx), actuator_of(x, ctx), rigid, ctx.sensor), mode, which);
    };
    return delta(modal_value(out.model, mode, which), gradient(t, value), c);
  };
  out.rigid_pole_rad_s = estimate(0, Modal::kRigidPole);
  out.modes.clear();
  for (std::size_t i = 0; i < out.model.modes.size(); ++i) {
    ModeUncertainty u;
    u.resonance_omega = estimate(i, Modal::kResonanceOmega);
    u.resonance_zeta = estimate(i, Modal::kResonanceZeta);
    u.antiresonance_omega = load ? Estimate{kNan, kNan} : estimate(i, Modal::kAntiresonanceOmega);
    u.antiresonance_zeta = load ? Estimate{kNan, kNan} : estimate(i, Modal::kAntiresonanceZeta);
    out.modes.push_back(u);
  }
  out.resonance_ratio = load || l.shafts != 1 ? Estimate{kNan, kNan} : estimate(0, Modal::kRatio);
}

/// The points the linear fit used (valid, not left out as outliers), with their weights; empty with
/// `why` set when a point carries no excitation amplitude.
std::vector<Point> fitted_points(const core::FrequencyResponse& response, const FitReport& linear, OutputKind output,
                                 std::vector<double>& amplitudes, bool& known_std, std::string& why) {
  std::vector<const core::FrequencyPoint*> used;
  for (const core::FrequencyPoint& q : response.points) {
    const bool left_out = std::any_of(linear.left_out_hz.begin(), linear.left_out_hz.end(),
                                      [&](double hz) { return hz == q.freq_hz; });
    if (q.valid && !left_out) used.push_back(&q);
  }
  known_std = !used.empty() && std::all_of(used.begin(), used.end(), [](const auto* q) { return q->std_dev > 0.0; });
  std::vector<Point> points;
  for (const core::FrequencyPoint* q : used) {
    const double v = velocity_of(*q, output);
    if (!(q->amplitude > 0.0) || !(v > 0.0) || !std::isfinite(v)) {
      why = "Coulomb friction not fitted: the point at " + std::to_string(q->freq_hz) +
            " Hz carries no excitation amplitude (a swept-sine measurement records it per point)";
      return {};
    }
    const double w = detail::log_residual_weight(*q, response.quality_kind, known_std);
    points.push_back({kTwoPi * q->freq_hz, std::log(q->value), v, w, w, w});
    amplitudes.push_back(q->amplitude);
  }
  return points;
}

/// The starts of a load-side chain of n > 1 shafts: a load encoder's response gives the total
/// inertia and the resonances only (n + 1 numbers for 2n + 1 inertias and stiffnesses), so the
/// antiresonances the motor would show are guessed where a chain's lie, between neighbouring
/// resonances (the first between ωp1/4 and ωp1), at 0.3, 0.6 and 0.9 of the way in log frequency
/// each (3^n starts); Cauer's chain of each guess, scaled to the measured total inertia, starts a
/// fit, and the friction, acting at the two ends' velocities, is what moves the split. One guess
/// alone stopped in a local minimum (three-mass chain: motor share 0.13 ± 0.004, true 0.22).
std::vector<ChainParameters> load_side_chains(const PlantModel& lin, std::string& why) {
  const std::size_t n = lin.modes.size();
  const double total = (lin.lag_pole_rad_s ? *lin.lag_pole_rad_s : 1.0) / lin.gain;
  constexpr std::array<double, 3> kWay{0.3, 0.6, 0.9};
  std::size_t combinations = 1;
  for (std::size_t i = 0; i < n; ++i) combinations *= kWay.size();
  std::vector<ChainParameters> chains;
  for (std::size_t c = 0; c < combinations; ++c) {
    std::vector<Mode> modes;
    double k = 1.0 / total;  // low-frequency asymptote K·Πωz²/Πωp²/s = 1/(ΣJ s)
    std::size_t code = c;
    for (std::size_t i = 0; i < n; ++i) {
      Mode m = lin.modes[i];
      const double below = i == 0 ? m.resonance.omega_rad_s / 4.0 : lin.modes[i - 1].resonance.omega_rad_s;
      const double way = kWay[code % kWay.size()];
      code /= kWay.size();
      m.antiresonance.omega_rad_s = below * std::pow(m.resonance.omega_rad_s / below, way);
      k *= (m.resonance.omega_rad_s * m.resonance.omega_rad_s) / (m.antiresonance.omega_rad_s * m.antiresonance.omega_rad_s);
      modes.push_back(m);
    }
    std::string reason;
    if (std::optional<ChainParameters> chain = detail::chain_of_modes(modes, k, reason)) chains.push_back(*chain);
    else why = "Coulomb friction not fitted: no chain for the load-side resonances (" + reason + ")";
  }
  if (!chains.empty()) why.clear();
  return chains;
}

/// "two-mass model", "three-mass chain", "4-mass chain".
std::string chain_name(std::size_t shafts) {
  if (shafts == 1) return "two-mass model";
  return (shafts == 2 ? std::string("three") : std::to_string(shafts + 1)) + "-mass chain";
}

/// The chain the linear fit describes, without friction: on the motor side its two-mass
/// parameters for one mode, Cauer's chain of its undamped modes for more (detail::chain_of_modes);
/// on the load side (one mode) the total inertia 1/K' and the resonance, split by
/// `motor_fraction` (ωp² = k J/(Jm Jl), 2ζp ωp = bs J/(Jm Jl)). Empty with `why` when there is none.
std::vector<ChainParameters> linear_chains(const FitReport& linear, double motor_fraction, std::string& why) {
  const PlantModel& lin = linear.result.model;
  const double lag = lin.lag_pole_rad_s ? *lin.lag_pole_rad_s : 1.0;
  if (lin.sensor == SensorSide::kMotor && lin.modes.size() > 1) {
    std::optional<ChainParameters> chain = detail::chain_of_modes(lin.modes, lin.gain / lag, why);
    if (!chain) {
      why = "Coulomb friction not fitted: the linear fit has no mass-chain reading (" + why + ")";
      return {};
    }
    return {*chain};
  }
  if (lin.sensor == SensorSide::kMotor) {
    const auto& start = linear.result.physical.parameters;
    if (!start) {
      why = "Coulomb friction not fitted: the linear fit has no two-mass parameters (" + linear.result.physical.note + ")";
      return {};
    }
    return {detail::two_mass_chain(start->motor_inertia.value, start->load_inertia.value, start->stiffness.value,
                                   start->damping.value, 0.0, 0.0, 0.0)};
  }
  if (lin.modes.empty() || !(lin.gain > 0.0)) {
    why = "Coulomb friction not fitted: a load-side fit needs a mode and a positive gain";
    return {};
  }
  if (lin.modes.size() > 1) return load_side_chains(lin, why);
  const double total = lag / lin.gain;
  const double jm = motor_fraction * total, jl = (1.0 - motor_fraction) * total, mu = jm * jl / total;
  const ModalPair& res = lin.modes.front().resonance;
  return {detail::two_mass_chain(jm, jl, res.omega_rad_s * res.omega_rad_s * mu, 2.0 * res.zeta * res.omega_rad_s * mu, 0.0,
                                 0.0, 0.0)};
}

}  // namespace

std::complex<double> coulomb_two_mass_response(double omega_rad_s, double motor_velocity_amplitude, double jm, double jl,
                                               double k, double bs, double bv, double mm, double ml,
                                               const PlantModel& linear_model) {
  return detail::chain_response(omega_rad_s, motor_velocity_amplitude, detail::two_mass_chain(jm, jl, k, bs, bv, mm, ml),
                                linear_model, SensorSide::kMotor);
}

std::complex<double> coulomb_two_mass_load_response(double omega_rad_s, double load_velocity_amplitude, double jm, double jl,
                                                    double k, double bs, double bv, double mm, double ml,
                                                    const PlantModel& linear_model) {
  return detail::chain_response(omega_rad_s, load_velocity_amplitude, detail::two_mass_chain(jm, jl, k, bs, bv, mm, ml),
                                linear_model, SensorSide::kLoad);
}

std::complex<double> coulomb_chain_response(double omega_rad_s, double velocity_amplitude, const std::vector<double>& inertias,
                                            const std::vector<double>& stiffnesses, const std::vector<double>& dampings,
                                            double bv, double mm, double ml, const PlantModel& linear_model,
                                            SensorSide sensor) {
  if (inertias.size() < 2 || stiffnesses.size() + 1 != inertias.size() || dampings.size() != stiffnesses.size())
    throw std::invalid_argument("coulomb_chain_response: n + 1 inertias need n stiffnesses and n dampings");
  const auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  const auto non_negative = [](double x) { return x >= 0.0 && std::isfinite(x); };
  if (!std::all_of(inertias.begin(), inertias.end(), positive) ||
      !std::all_of(stiffnesses.begin(), stiffnesses.end(), positive) ||
      !std::all_of(dampings.begin(), dampings.end(), non_negative) || !non_negative(bv) || !non_negative(mm) ||
      !non_negative(ml) || !positive(omega_rad_s) || !positive(velocity_amplitude))
    throw std::invalid_argument(
        "coulomb_chain_response: inertias, stiffnesses, frequency and velocity amplitude must be finite and > 0, "
        "dampings and friction levels finite and >= 0");
  return detail::chain_response(omega_rad_s, velocity_amplitude, {inertias, stiffnesses, dampings, bv, mm, ml},
                                linear_model, sensor);
}

CoulombFit fit_coulomb_friction(const core::FrequencyResponse& response, const FitReport& linear, const FitOptions& options) {
  CoulombFit out;
  const PlantModel& lin = linear.result.model;
  const std::vector<ChainParameters> chains = linear_chains(linear, 0.5, out.note);
  if (chains.empty()) return out;
  const ChainParameters* start = &chains.front();  // the scales (a load-side chain's split does not change them)
  std::vector<double> amplitudes;
  bool known_std = false;
  std::vector<Point> points = fitted_points(response, linear, lin.output, amplitudes, known_std, out.note);
  if (!out.note.empty()) return out;
  const std::size_t m = points.size();
  const Layout layout(lin, start->shafts());
  const bool load = lin.sensor == SensorSide::kLoad;
  const bool fixed_integrator = options.rigid == RigidKind::kIntegrator;
  std::vector<Eigen::Index> fixed;
  if (fixed_integrator) fixed.push_back(layout.viscous());
  const auto free_parameters = static_cast<std::size_t>(layout.size) - fixed.size();
  if (2 * m <= free_parameters) {
    out.note = "Coulomb friction not fitted: " + std::to_string(m) + " points are too few for " +
               std::to_string(free_parameters) + " parameters";
    return out;
  }
  const double lowest_amplitude = amplitudes.front();
  std::nth_element(amplitudes.begin(), amplitudes.begin() + static_cast<std::ptrdiff_t>(m / 2), amplitudes.end());
  const double jm0 = start->inertia.front(), total0 = start->total_inertia();
  // The first antiresonance, the unit of the viscous damping and the delay (two masses: √(k/Jl)).
  const double wz0 = start->shafts() == 1 || load ? std::sqrt(start->stiffness.back() / start->inertia.back())
                                                   : lin.modes.front().antiresonance.omega_rad_s;
  const Context ctx{jm0 * wz0, amplitudes[m / 2], 1.0 / wz0, lin, lin.sensor, layout};

  core::LmOptions lo;
  lo.numeric_jacobian = true;
  lo.record_history = false;
  lo.max_iterations = std::max(options.max_iterations, 400);
  lo.covariance_scale = known_std ? core::LmCovarianceScale::kKnown : core::LmCovarianceScale::kEstimated;
  lo.lower = Eigen::VectorXd::Constant(layout.size, -std::numeric_limits<double>::infinity());
  lo.upper = Eigen::VectorXd::Constant(layout.size, std::numeric_limits<double>::infinity());
  if (layout.delay >= 0) (*lo.lower)[layout.delay] = 0.0;
  (*lo.lower)[layout.viscous()] = 0.0;
  (*lo.lower)[layout.motor_coulomb()] = 0.0;
  (*lo.lower)[layout.load_coulomb()] = 0.0;
  if (fixed_integrator) (*lo.upper)[layout.viscous()] = 0.0;
  if (load) {
    // The share within [0.007, 0.993]: a chain whose one mass vanishes is not a two-mass chain
    // (a longer chain: each mass within e^±5 of the motor's).
    for (std::size_t i = 1; i <= layout.shafts; ++i) {
      (*lo.lower)[layout.inertia(i)] = -5.0;
      (*lo.upper)[layout.inertia(i)] = 5.0;
    }
  }
  const auto f = [&](const Eigen::VectorXd& t, Eigen::VectorXd& res, Eigen::MatrixXd*) {
    return residuals(t, points, ctx, res);
  };

  // Starts: the linear fit's parameters read without friction (its rigid pole as viscous damping),
  // and the same with that damping read as Coulomb friction, split evenly between the masses or all
  // on the load: at the lowest point the describing function 4M/(π|V|) equals the viscous
  // a·ΣJ. An integrator fit has no such damping to read; its friction starts at half the
  // lowest point's excitation amplitude, where friction shows most.
  const double a = lin.rigid == RigidKind::kRealPole ? lin.rigid_pole_rad_s : 0.0;
  const double bv0 = fixed_integrator ? 0.0 : a * total0;
  const double m0 = a > 0.0 ? kPi * points.front().velocity * a * total0 / 4.0 : 0.5 * lowest_amplitude;
  const std::array<std::array<double, 3>, 3> starts{{{bv0, 0.0, 0.0}, {0.0, 0.5 * m0, 0.5 * m0}, {0.0, 0.0, m0}}};
  core::LmResult best;
  best.cost = std::numeric_limits<double>::infinity();
  for (const ChainParameters& chain : chains) {
  for (const auto& [bv, mm, ml] : starts) {
    Eigen::VectorXd t(layout.size);
    for (std::size_t i = 0; i <= layout.shafts; ++i) t[layout.inertia(i)] = std::log(chain.inertia[i]);
    if (load) {
      t[0] = std::log(total0);
      for (std::size_t i = 1; i <= layout.shafts; ++i)
        t[layout.inertia(i)] = layout.shafts == 1 ? 0.0 : std::log(chain.inertia[i] / chain.inertia.front());
    }
    for (std::size_t i = 0; i < layout.shafts; ++i) {
      t[layout.stiffness(i)] = std::log(chain.stiffness[i]);
      t[layout.damping(i)] = std::log(std::max(chain.damping[i], 1e-6 * jm0 * wz0));
    }
    t[layout.viscous()] = bv / ctx.viscous;
    t[layout.motor_coulomb()] = mm / ctx.torque;
    t[layout.load_coulomb()] = ml / ctx.torque;
    // A lag the linear fit pushed far above the data (it traded it for the friction's phase) has
    // no gradient left there; it starts at most a decade above the highest point.
    if (layout.lag >= 0) t[layout.lag] = std::log(std::min(*lin.lag_pole_rad_s, 10.0 * points.back().omega));
    if (layout.delay >= 0) t[layout.delay] = *lin.delay_s / ctx.time;
    core::LmResult run = core::levenberg_marquardt(f, t, 2 * m, lo);
    if (detail::better_run(run, best)) best = std::move(run);
  }
  }
  out.points = m;
  if (!std::isfinite(best.cost) || !best.converged()) {
    out.note = "Coulomb friction fit did not converge: " + (std::isfinite(best.cost) ? best.message : "no valid start") +
               (load && layout.shafts > 1 ? " (from the load encoder a chain's split along its masses shows only through "
                                            "its friction: with little friction it is not determined)"
                                          : "");
    return out;
  }
  // Second pass with the errors-in-variables weights of the first solution (kept when it fails).
  const double first_rms = unweighted_rms(best.residual, points);
  const std::vector<Point> first_weights = points;
  errors_in_variables(best.parameters, ctx, points);
  core::LmResult second = core::levenberg_marquardt(f, best.parameters, 2 * m, lo);
  if (second.converged())
    best = std::move(second);
  else
    points = first_weights;
  out.fitted = true;
  out.iterations = best.iterations;
  out.message = best.message;
  out.cost = best.cost;
  out.weighting = known_std ? "std_dev" : "log-relative";
  out.rms_log_error = unweighted_rms(best.residual, points);
  out.linear_rms_log_error = linear.result.rms_log_error;
  // A chain's shafts give each mode its damping only through n dampers: a response whose modal
  // dampings no chain reproduces (or whose data are not a chain's: a wrong --output-kind or
  // --sensor) makes the friction absorb the rest and fit worse than the linear model. Such a fit
  // is not written.
  // (The first pass's rms counts too: the second lowers the weights of noise-amplified points on
  // purpose, which may raise the unweighted rms without anything being wrong.)
  if (std::min(first_rms, out.rms_log_error) > kWorseThanLinear * out.linear_rms_log_error + kNegligibleRms) {
    out.fitted = false;
    out.note = fmt::format(
        "Coulomb friction not fitted: the {} with friction fits worse than the linear fit (rms log error {:.3g} "
        "against {:.3g}): the response is not that of a chain with friction on its ends (check --output-kind and "
        "--sensor); the linear fit is kept",
        chain_name(layout.shafts), out.rms_log_error, out.linear_rms_log_error);
    return out;
  }
  Eigen::MatrixXd covariance = free_covariance(best, known_std, fixed);
  std::string held;
  const bool share_held = load && !covariance.allFinite();
  if (share_held && layout.shafts > 1) {
    for (std::size_t i = 1; i <= layout.shafts; ++i) fixed.push_back(layout.inertia(i));
    covariance = free_covariance(best, known_std, fixed);
    held = "; the inertias' split along the chain is not seen (too little friction) and is held";
  } else if (share_held) {
    // Friction too small to tell the split (a singular Jacobian): the share stays where LM left it
    // and is no parameter; its std and those of the inertias are then unknown (NaN), not 0.
    fixed.push_back(1);
    covariance = free_covariance(best, known_std, fixed);
    held = "; the motor's share of the inertia is not seen (too little friction) and is held at " +
           std::to_string(motor_share(best.parameters)).substr(0, 5);
  }
  const double dof = 2.0 * static_cast<double>(m) - static_cast<double>(layout.size) + static_cast<double>(fixed.size());
  out.sigma2 = known_std ? 1.0 : best.residual.squaredNorm() / dof;
  const detail::MisfitScale misfit = detail::misfit_scale(best.residual, dof, known_std);
  out.uncertainty_scale = misfit.factor;
  out.uncertainty_note = misfit.note;
  fill_estimates(out, best.parameters, covariance * misfit.factor, ctx, options.rigid);
  if (share_held) {
    // The stiffnesses and dampings follow the held split: their stds would be conditional on it.
    out.motor_share.std = out.motor_inertia.std = out.load_inertia.std = out.stiffness.std = out.shaft_damping.std = kNan;
    for (std::vector<Estimate>* v : {&out.inertias, &out.stiffnesses, &out.shaft_dampings})
      for (Estimate& e : *v) e.std = kNan;
  }
  out.note = chain_name(layout.shafts) +
             " with Coulomb friction on motor and load (describing functions at each point's measured amplitude" +
             (load ? ", seen from the load encoder" : "") + "), " + std::to_string(m) + " points" + held;
  return out;
}

FitReport with_friction_model(FitReport linear, const CoulombFit& f) {
  if (!f.fitted) return linear;
  FitResult& r = linear.result;
  const bool load = f.model.sensor == SensorSide::kLoad;
  r.model = f.model;
  r.gain = f.gain;
  r.rigid_pole_rad_s = f.model.rigid == RigidKind::kRealPole ? f.rigid_pole_rad_s : Estimate{0.0, 0.0};
  r.mode_estimates = f.modes;
  const std::size_t shafts = f.stiffnesses.size();
  if (load && shafts == 1) {
    r.parameter_names = {"ln_total_inertia", "logit_motor_share", "ln_stiffness_at_even_share",
                         "ln_shaft_damping_at_even_share"};
  } else if (load) {
    r.parameter_names = {"ln_total_inertia"};
    for (std::size_t i = 2; i <= shafts + 1; ++i) r.parameter_names.push_back("ln_inertia_" + std::to_string(i) + "_over_motor");
    for (std::size_t i = 1; i <= shafts; ++i) r.parameter_names.push_back("ln_stiffness_" + std::to_string(i));
    for (std::size_t i = 1; i <= shafts; ++i) r.parameter_names.push_back("ln_shaft_damping_" + std::to_string(i));
  } else if (shafts == 1) {
    r.parameter_names = {"ln_motor_inertia", "ln_load_inertia", "ln_stiffness", "ln_shaft_damping"};
  } else {
    r.parameter_names.clear();
    for (std::size_t i = 1; i <= shafts + 1; ++i) r.parameter_names.push_back("ln_inertia_" + std::to_string(i));
    for (std::size_t i = 1; i <= shafts; ++i) r.parameter_names.push_back("ln_stiffness_" + std::to_string(i));
    for (std::size_t i = 1; i <= shafts; ++i) r.parameter_names.push_back("ln_shaft_damping_" + std::to_string(i));
  }
  for (const char* name : {"viscous_damping_scaled", "motor_coulomb_scaled", "load_coulomb_scaled"})
    r.parameter_names.emplace_back(name);
  if (f.model.lag_pole_rad_s) r.parameter_names.emplace_back("ln_lag_pole");
  if (f.model.delay_s) r.parameter_names.emplace_back("delay_scaled");
  r.theta = f.theta;
  r.covariance = f.covariance;
  r.parameters = static_cast<std::size_t>(f.theta.size());
  r.points = f.points;
  r.lag_pole_rad_s = f.lag_pole_rad_s;
  r.delay_s = f.delay_s;
  r.rms_log_error = f.rms_log_error;
  r.cost = f.cost;
  r.sigma2 = f.sigma2;
  r.weighting = f.weighting;
  r.uncertainty_scale = f.uncertainty_scale;
  r.uncertainty_note = f.uncertainty_note;
  r.iterations = f.iterations;
  r.initialization += ", then with Coulomb friction from the linear fit";
  r.message += "; then with Coulomb friction: " + f.message;
  if (load) {
    r.physical.parameters.reset();
    r.physical.note = "no two-mass parameters written from a load-side response (the model has no antiresonance); the "
                      "fit with Coulomb friction gives the total inertia " + std::to_string(f.total_inertia.value) +
                      " and the motor's share " + std::to_string(f.motor_share.value);
    return linear;
  }
  if (shafts != 1) {
    const auto list = [](const std::vector<Estimate>& v) {
      std::string text;
      for (const Estimate& e : v) text += (text.empty() ? "" : ", ") + fmt::format("{:.5g}", e.value);
      return text;
    };
    r.physical.parameters.reset();
    r.physical.note = "not a two-mass system; the fit with Coulomb friction gives the " + chain_name(shafts) +
                      ": inertias " + list(f.inertias) + ", stiffnesses " + list(f.stiffnesses) + ", shaft dampings " +
                      list(f.shaft_dampings) + " (motor first)";
    return linear;
  }
  TwoMassParameters p;
  p.motor_inertia = f.motor_inertia;
  p.load_inertia = f.load_inertia;
  p.stiffness = f.stiffness;
  p.damping = f.shaft_damping;
  p.resonance_ratio = f.resonance_ratio;
  const Mode& m = f.model.modes.front();
  const double ratio = f.resonance_ratio.value;
  p.damping_consistency = m.resonance.zeta / (ratio * m.antiresonance.zeta);
  r.physical.parameters = p;
  r.physical.note = "two-mass parameters of the fit with Coulomb friction (viscous damping at the motor " +
                    std::to_string(f.viscous_damping.value) + ")";
  return linear;
}

std::complex<double> coulomb_response_at(const CoulombFit& f, const core::FrequencyPoint& point) {
  const double v = velocity_of(point, f.model.output);
  if (!f.fitted || !(v > 0.0) || !std::isfinite(v)) return {kNan, 0.0};
  detail::ChainParameters p;
  p.bv = f.viscous_damping.value;
  p.mm = f.motor_coulomb.value;
  p.ml = f.load_coulomb.value;
  for (const Estimate& e : f.inertias) p.inertia.push_back(e.value);
  for (const Estimate& e : f.stiffnesses) p.stiffness.push_back(e.value);
  for (const Estimate& e : f.shaft_dampings) p.damping.push_back(e.value);
  return detail::chain_response(kTwoPi * point.freq_hz, v, p, f.model, f.model.sensor);
}

}  // namespace servotwin::fit
