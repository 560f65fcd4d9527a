#include "servotwin/fit/fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>

#include "servotwin/core/error.hpp"
#include "servotwin/core/levenberg_marquardt.hpp"
#include "servotwin/fit/initialization.hpp"
#include "misfit.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
/// exp() of a larger θ overflows soon after; such a trial point is rejected.
constexpr double kThetaLimit = 300.0;
constexpr std::size_t kGridSize = 25;

std::string num(double v, int digits = 4) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
  return buffer;
}

// ---- data -------------------------------------------------------------------------------------

/// The measured points in the form the fit works on. The log-magnitudes are taken relative to
/// their mean, log_scale, so that the fit is the same for a response in any unit (issue 27 §1: one
/// scaled by 1e150 put the log-gain beyond kThetaLimit): θ's gain entry and the models that
/// complete_start returns are in physical units, refine and finish convert.
struct Data {
  std::vector<double> omega;
  std::vector<Complex> log_meas;  ///< ln|P| − log_scale + j∠P
  std::vector<double> weight;     ///< |P|/std_dev or 1
  double log_scale = 0.0;         ///< mean of ln|P|
  bool known_std = false;
  [[nodiscard]] std::size_t size() const { return omega.size(); }
  /// ln P of point k in physical units, to compare with a physical model.
  [[nodiscard]] Complex measured(std::size_t k) const { return log_meas[k] + log_scale; }
};

bool has_invalid(const core::FrequencyResponse& response) {
  return std::any_of(response.points.begin(), response.points.end(), [](const auto& p) { return !p.valid; });
}

Data make_data(const core::FrequencyResponse& response) {
  Data d;
  d.known_std = std::all_of(response.points.begin(), response.points.end(), [](const auto& p) { return p.std_dev > 0.0; });
  for (const auto& p : response.points) {
    d.omega.push_back(kTwoPi * p.freq_hz);
    d.log_meas.push_back(std::log(p.value));
    d.weight.push_back(detail::log_residual_weight(p, response.quality_kind, d.known_std));
    d.log_scale += d.log_meas.back().real();
  }
  if (!d.log_meas.empty()) d.log_scale /= static_cast<double>(d.log_meas.size());
  for (Complex& l : d.log_meas) l -= d.log_scale;
  return d;
}

/// The outlier rule (issue 25 §1): with the fitted model, each point's weighted complex log
/// residual e_i = w_i·(ln P_model − ln P_meas) (w from make_data). Under Gaussian errors |e| is
/// Rayleigh distributed, whose median is σ·sqrt(2 ln 2); σ is estimated from the median so that
/// the misfit itself does not hide outliers, and floored at the points' own std (1 in weighted
/// units) or at 0.1 % relative error without std. A point with |e_i| > kOutlierSigmas·σ (Rayleigh tail
/// exp(−c²/2) = 4e-5 per point at c = 4.5) is an outlier when it is isolated (neither frequency
/// neighbour above 3 σ: a run of large residuals is model misfit, not a glitch); at most a fifth of the points are
/// rejected, the largest first, and never so many that the model would lack points.
constexpr double kOutlierSigmas = 4.5;
constexpr double kMaxOutlierFraction = 0.2;
constexpr double kOutlierRelativeFloor = 1e-3;
constexpr double kNeighbourSigmas = 3.0;

std::vector<std::size_t> outliers(const core::FrequencyResponse& response, const PlantModel& model,
                                  std::size_t parameters, std::vector<double>& sigmas) {
  const Data d = make_data(response);
  std::vector<double> e(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const Complex diff = std::log(model.response(d.omega[i])) - d.measured(i);
    // Phases differ modulo 2π: the principal logs of two nearby values can sit on either side of ±π.
    e[i] = d.weight[i] * std::abs(Complex(diff.real(), std::remainder(diff.imag(), 2.0 * std::numbers::pi)));
  }
  // A non-finite residual (a model pole on the jω axis) is no ordering key for the median.
  std::vector<double> sorted;
  for (double v : e)
    if (std::isfinite(v)) sorted.push_back(v);
  if (sorted.empty()) return {};
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  // Floored: residuals within the points' own std (weighted data), or below 0.1 % relative error
  // (unweighted), are the measurement, not outliers (a noise-free fit's rounding residuals are
  // not Gaussian and their median says nothing).
  const double floor = d.known_std ? 1.0 : kOutlierRelativeFloor;
  const double sigma = std::max(floor, sorted[sorted.size() / 2] / std::sqrt(2.0 * std::log(2.0)));
  std::vector<std::size_t> out;
  if (!(sigma > 0.0)) return out;
  // A glitch is isolated; a run of large residuals is the model missing something (a mode it does
  // not have, a load-side response without antiresonance), which rejecting would only hide.
  const auto large = [&](std::size_t j) { return e[j] > kNeighbourSigmas * sigma; };
  for (std::size_t i = 0; i < e.size(); ++i)
    if (e[i] > kOutlierSigmas * sigma && !(i > 0 && large(i - 1)) && !(i + 1 < e.size() && large(i + 1))) out.push_back(i);
  std::sort(out.begin(), out.end(), [&](std::size_t a, std::size_t b) { return e[a] > e[b]; });
  const auto by_fraction = static_cast<std::size_t>(kMaxOutlierFraction * static_cast<double>(d.size()));
  // Each point gives two real residuals; keep more than the parameters.
  const std::size_t by_count = d.size() > parameters / 2 + 1 ? d.size() - (parameters / 2 + 1) : 0;
  out.resize(std::min({out.size(), by_fraction, by_count}));
  sigmas.clear();
  for (std::size_t i : out) sigmas.push_back(e[i] / sigma);
  return out;
}

// ---- parameterization -------------------------------------------------------------------------

/// Position of each parameter in θ. A motor-side mode is (ln ωz, ln ζz, ln ωp, ln ζp), a
/// load-side one (ln ωp, ln ζp).
struct Layout {
  std::size_t modes = 0;
  RigidKind rigid = RigidKind::kRealPole;
  OutputKind output = OutputKind::kVelocity;
  bool lag = false, delay = false;
  SensorSide sensor = SensorSide::kMotor;

  [[nodiscard]] Eigen::Index per_mode() const { return sensor == SensorSide::kMotor ? 4 : 2; }
  [[nodiscard]] Eigen::Index rigid_index() const { return 1; }
  [[nodiscard]] Eigen::Index mode_base(std::size_t i) const {
    return static_cast<Eigen::Index>(1 + (rigid == RigidKind::kRealPole ? 1 : 0)) + per_mode() * static_cast<Eigen::Index>(i);
  }
  /// θ index of mode i's ln ωp.
  [[nodiscard]] Eigen::Index resonance_index(std::size_t i) const {
    return mode_base(i) + (sensor == SensorSide::kMotor ? 2 : 0);
  }
  [[nodiscard]] Eigen::Index lag_index() const { return mode_base(modes); }
  [[nodiscard]] Eigen::Index delay_index() const { return mode_base(modes) + (lag ? 1 : 0); }
  [[nodiscard]] Eigen::Index size() const {
    return static_cast<Eigen::Index>(parameter_count(modes, rigid, lag, delay, sensor));
  }
};

Layout layout_of(const PlantModel& m) {
  return Layout{m.modes.size(), m.rigid, m.output, m.lag_pole_rad_s.has_value(), m.delay_s.has_value(), m.sensor};
}

std::vector<std::string> parameter_names(const Layout& l) {
  std::vector<std::string> names{"ln_gain"};
  if (l.rigid == RigidKind::kRealPole) names.emplace_back("ln_rigid_pole");
  for (std::size_t i = 0; i < l.modes; ++i) {
    const std::string p = "mode" + std::to_string(i + 1) + ".";
    if (l.sensor == SensorSide::kMotor)
      for (const char* s : {"ln_wz", "ln_zeta_z"}) names.push_back(p + s);
    for (const char* s : {"ln_wp", "ln_zeta_p"}) names.push_back(p + s);
  }
  if (l.lag) names.emplace_back("ln_lag_pole");
  if (l.delay) names.emplace_back("ln_delay");
  return names;
}

Eigen::VectorXd to_theta(const PlantModel& m) {
  const Layout l = layout_of(m);
  Eigen::VectorXd t(l.size());
  t[0] = std::log(std::abs(m.gain));
  if (l.rigid == RigidKind::kRealPole) t[l.rigid_index()] = std::log(m.rigid_pole_rad_s);
  for (std::size_t i = 0; i < l.modes; ++i) {
    const Eigen::Index b = l.mode_base(i), p = l.resonance_index(i);
    if (l.sensor == SensorSide::kMotor) {
      t[b] = std::log(m.modes[i].antiresonance.omega_rad_s);
      t[b + 1] = std::log(m.modes[i].antiresonance.zeta);
    }
    t[p] = std::log(m.modes[i].resonance.omega_rad_s);
    t[p + 1] = std::log(m.modes[i].resonance.zeta);
  }
  if (l.lag) t[l.lag_index()] = std::log(*m.lag_pole_rad_s);
  if (l.delay) t[l.delay_index()] = std::log(*m.delay_s);
  return t;
}

PlantModel to_model(const Eigen::VectorXd& t, const Layout& l, double sign) {
  PlantModel m;
  m.output = l.output;
  m.rigid = l.rigid;
  m.sensor = l.sensor;
  m.gain = sign * std::exp(t[0]);
  if (l.rigid == RigidKind::kRealPole) m.rigid_pole_rad_s = std::exp(t[l.rigid_index()]);
  for (std::size_t i = 0; i < l.modes; ++i) {
    const Eigen::Index b = l.mode_base(i), p = l.resonance_index(i);
    const ModalPair zeros = l.sensor == SensorSide::kMotor ? ModalPair{std::exp(t[b]), std::exp(t[b + 1])} : ModalPair{};
    m.modes.push_back(Mode{zeros, {std::exp(t[p]), std::exp(t[p + 1])}});
  }
  if (l.lag) m.lag_pole_rad_s = std::exp(t[l.lag_index()]);
  if (l.delay) m.delay_s = std::exp(t[l.delay_index()]);
  return m;
}

/// Weighted log-ratio residuals and their Jacobian in θ (fit.hpp explains the choice).
bool log_residuals(const Eigen::VectorXd& t, const Layout& l, double sign, const Data& data, Eigen::VectorXd& r,
                   Eigen::MatrixXd* jac) {
  if ((t.array().abs() > kThetaLimit).any()) return false;
  const Eigen::Index n = t.size();
  Eigen::VectorXcd d(n);
  const double a = l.rigid == RigidKind::kRealPole ? std::exp(t[l.rigid_index()]) : 0.0;
  for (std::size_t k = 0; k < data.size(); ++k) {
    const Complex s(0.0, data.omega[k]);
    Complex log_p(t[0], sign < 0.0 ? kPi : 0.0);
    d[0] = 1.0;
    if (l.rigid == RigidKind::kRealPole) {
      const Complex f = s + a;
      log_p -= std::log(f);
      d[l.rigid_index()] = -a / f;
    } else {
      log_p -= std::log(s);
    }
    for (std::size_t i = 0; i < l.modes; ++i) {
      const Eigen::Index b = l.mode_base(i);
      for (int pole = l.sensor == SensorSide::kMotor ? 0 : 1; pole < 2; ++pole) {
        const Eigen::Index j = l.sensor == SensorSide::kMotor ? b + 2 * pole : b;
        const double w = std::exp(t[j]), z = std::exp(t[j + 1]);
        const Complex q = s * s + 2.0 * z * w * s + w * w;
        const double sgn = pole ? -1.0 : 1.0;
        log_p += sgn * std::log(q);
        d[j] = sgn * (2.0 * z * w * s + 2.0 * w * w) / q;
        d[j + 1] = sgn * (2.0 * z * w * s) / q;
      }
      if (l.sensor == SensorSide::kLoad) {
        // The shaft's damping zero 2ζω s + ω² (plant_model.hpp), tied to the resonance.
        const double w = std::exp(t[b]), z = std::exp(t[b + 1]);
        const Complex zero = 2.0 * z * w * s + w * w;
        log_p += std::log(zero);
        d[b] += (2.0 * z * w * s + 2.0 * w * w) / zero;
        d[b + 1] += (2.0 * z * w * s) / zero;
      }
    }
    if (l.lag) {
      const double tau = std::exp(t[l.lag_index()]);
      log_p -= std::log(s + tau);
      d[l.lag_index()] = -tau / (s + tau);
    }
    if (l.delay) {
      const Complex sd = s * std::exp(t[l.delay_index()]);
      log_p -= sd;
      d[l.delay_index()] = -sd;
    }
    if (l.output == OutputKind::kPosition) log_p -= std::log(s);
    const Complex e = log_p - data.log_meas[k];
    const double w = data.weight[k];
    const auto row = static_cast<Eigen::Index>(2 * k);
    r[row] = w * e.real();
    r[row + 1] = w * std::remainder(e.imag(), kTwoPi);
    if (jac) {
      jac->row(row) = w * d.real().transpose();
      jac->row(row + 1) = w * d.imag().transpose();
    }
  }
  return true;
}

// ---- completing a start -----------------------------------------------------------------------

/// Cost of a model with the gain optimal in the log-magnitude (closed form: weighted mean) and
/// its sign from the phase; sets the model's gain.
double cost_with_best_gain(PlantModel& m, const Data& data) {
  m.gain = 1.0;
  double sw = 0.0, swl = 0.0;
  Complex rotation = 0.0;
  std::vector<Complex> shape(data.size());
  for (std::size_t k = 0; k < data.size(); ++k) {
    shape[k] = std::log(m.response(data.omega[k]));
    const Complex e = data.log_meas[k] - shape[k];
    const double w2 = data.weight[k] * data.weight[k];
    sw += w2;
    swl += w2 * e.real();
    rotation += w2 * std::polar(1.0, e.imag());
  }
  const double sign = rotation.real() < 0.0 ? -1.0 : 1.0;
  const double log_k = swl / sw;
  m.gain = sign * std::exp(log_k + data.log_scale);
  double cost = 0.0;
  for (std::size_t k = 0; k < data.size(); ++k) {
    const Complex e = shape[k] + Complex(log_k, sign < 0.0 ? kPi : 0.0) - data.log_meas[k];
    const double w = data.weight[k];
    cost += w * w * (e.real() * e.real() + std::pow(std::remainder(e.imag(), kTwoPi), 2));
  }
  return 0.5 * cost;
}

std::vector<double> log_grid(double lo, double hi, std::size_t count) {
  std::vector<double> g(count);
  for (std::size_t i = 0; i < count; ++i)
    g[i] = std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * static_cast<double>(i) / static_cast<double>(count - 1));
  return g;
}

/// Fills in what a start lacks: rigid pole and lag pole on a log grid (lag ≥ rigid pole), the
/// gain in closed form, the delay from the slope of the remaining phase.
PlantModel complete_start(PlantModel m, bool need_rigid_pole, const Layout& l, const Data& data) {
  m.output = l.output;
  const double w_lo = data.omega.front() / 100.0, w_hi = data.omega.back() * 100.0;
  const std::vector<double> grid = log_grid(w_lo, w_hi, kGridSize);
  if (l.lag) m.lag_pole_rad_s = w_hi;
  m.delay_s.reset();
  if (need_rigid_pole || l.lag) {
    PlantModel best = m;
    double best_cost = std::numeric_limits<double>::infinity();
    const std::vector<double> rigid_values =
        need_rigid_pole ? grid : std::vector<double>{m.rigid_pole_rad_s};
    for (double a : rigid_values) {
      for (std::size_t j = 0; j < (l.lag ? grid.size() : 1); ++j) {
        PlantModel trial = m;
        trial.rigid_pole_rad_s = a;
        if (l.lag) {
          if (l.rigid == RigidKind::kRealPole && grid[j] < a) continue;
          trial.lag_pole_rad_s = grid[j];
        }
        const double c = cost_with_best_gain(trial, data);
        if (c < best_cost) {
          best_cost = c;
          best = trial;
        }
      }
    }
    m = best;
  }
  cost_with_best_gain(m, data);
  if (l.delay) {
    // Least-squares slope of the phase misfit through the origin: Δφ ≈ −ω T.
    double num_t = 0.0, den_t = 0.0;
    for (std::size_t k = 0; k < data.size(); ++k) {
      const double dphi = std::remainder((data.log_meas[k] - std::log(m.response(data.omega[k]))).imag(), kTwoPi);
      num_t -= data.omega[k] * dphi;
      den_t += data.omega[k] * data.omega[k];
    }
    const double floor = 1e-3 / data.omega.back();
    m.delay_s = std::max(num_t / den_t, floor);
  }
  return m;
}

// ---- refinement -------------------------------------------------------------------------------

struct Run {
  Eigen::VectorXd theta;
  double sign = 1.0;
  core::LmResult lm;
  std::string start;
};

Run refine(const PlantModel& start, const Data& data, const FitOptions& options, std::string start_name) {
  Run run;
  run.start = std::move(start_name);
  run.sign = start.gain < 0.0 ? -1.0 : 1.0;
  const Layout l = layout_of(start);
  core::LmOptions lm;
  lm.max_iterations = options.max_iterations;
  lm.covariance_scale = data.known_std ? core::LmCovarianceScale::kKnown : core::LmCovarianceScale::kEstimated;
  lm.record_history = false;
  const double sign = run.sign;
  Eigen::VectorXd theta = to_theta(start);
  theta[0] -= data.log_scale;
  run.lm = core::levenberg_marquardt(
      [&](const Eigen::VectorXd& t, Eigen::VectorXd& r, Eigen::MatrixXd* j) { return log_residuals(t, l, sign, data, r, j); },
      theta, 2 * data.size(), lm);
  run.theta = run.lm.parameters;
  return run;
}

/// Swaps θ entries i and j (and the covariance rows/columns).
void swap_parameters(Eigen::VectorXd& t, Eigen::MatrixXd& c, Eigen::Index i, Eigen::Index j) {
  std::swap(t[i], t[j]);
  c.row(i).swap(c.row(j));
  c.col(i).swap(c.col(j));
}

/// Canonical order: modes by resonance frequency; lag pole ≥ rigid pole (the two real poles are
/// interchangeable in the model).
void canonicalize(Eigen::VectorXd& t, Eigen::MatrixXd& c, const Layout& l) {
  if (l.lag && l.rigid == RigidKind::kRealPole && t[l.lag_index()] < t[l.rigid_index()])
    swap_parameters(t, c, l.lag_index(), l.rigid_index());
  for (std::size_t pass = 0; pass < l.modes; ++pass)
    for (std::size_t i = 0; i + 1 < l.modes; ++i) {
      const Eigen::Index a = l.mode_base(i), b = l.mode_base(i + 1);
      if (t[l.resonance_index(i)] > t[l.resonance_index(i + 1)])
        for (Eigen::Index k = 0; k < l.per_mode(); ++k) swap_parameters(t, c, a + k, b + k);
    }
}

/// The covariance factor of FitResult::uncertainty_scale, with its note (detail::misfit_scale).
detail::MisfitScale misfit_scale(const Run& run, const Layout& l, const Data& data) {
  const std::size_t m = data.size();
  const double dof = 2.0 * static_cast<double>(m) - static_cast<double>(l.size());
  Eigen::VectorXd r(static_cast<Eigen::Index>(2 * m));
  if (dof <= 0.0 || m < 3 || !log_residuals(run.theta, l, run.sign, data, r, nullptr)) return {};
  return detail::misfit_scale(r, dof, data.known_std);
}

FitResult finish(const Run& run, const Layout& l, const Data& data) {
  FitResult f;
  f.points = data.size();
  f.parameters = static_cast<std::size_t>(l.size());
  f.initialization = run.start;
  if (run.lm.status == core::LmStatus::kInvalidStart || run.theta.size() != l.size()) {
    // No start could even be evaluated (non-finite model values there): nothing to report.
    f.message = "no start could be evaluated: " + run.lm.message;
    return f;
  }
  Eigen::VectorXd t = run.theta;
  t += data.log_scale * Eigen::VectorXd::Unit(t.size(), 0);  // the gain entry, back to physical units
  const detail::MisfitScale misfit = misfit_scale(run, l, data);
  Eigen::MatrixXd c = run.lm.covariance * misfit.factor;
  f.uncertainty_scale = misfit.factor;
  f.uncertainty_note = misfit.note;
  canonicalize(t, c, l);
  f.model = to_model(t, l, run.sign);
  f.converged = run.lm.converged();
  f.message = run.lm.message;
  f.weighting = data.known_std ? "std_dev" : "log-relative";
  f.iterations = run.lm.iterations;
  f.cost = run.lm.cost;
  f.sigma2 = run.lm.sigma2;
  f.parameter_names = parameter_names(l);
  f.theta = t;
  f.covariance = c;
  double sum = 0.0;
  for (std::size_t k = 0; k < data.size(); ++k) {
    const Complex e = std::log(f.model.response(data.omega[k])) - data.measured(k);
    sum += e.real() * e.real() + std::pow(std::remainder(e.imag(), kTwoPi), 2);
  }
  f.rms_log_error = std::sqrt(sum / static_cast<double>(data.size()));
  f.gain = detail::log_estimate(t, c, 0, run.sign);
  f.rigid_pole_rad_s = l.rigid == RigidKind::kRealPole ? detail::log_estimate(t, c, l.rigid_index()) : Estimate{0.0, 0.0};
  f.lag_pole_rad_s = l.lag ? detail::log_estimate(t, c, l.lag_index()) : Estimate{kNan, kNan};
  f.delay_s = l.delay ? detail::log_estimate(t, c, l.delay_index()) : Estimate{kNan, kNan};
  for (std::size_t i = 0; i < l.modes; ++i) {
    const Eigen::Index b = l.mode_base(i), p = l.resonance_index(i);
    const bool motor = l.sensor == SensorSide::kMotor;
    f.mode_estimates.push_back({motor ? detail::log_estimate(t, c, b) : Estimate{kNan, kNan},
                                motor ? detail::log_estimate(t, c, b + 1) : Estimate{kNan, kNan}, detail::log_estimate(t, c, p),
                                detail::log_estimate(t, c, p + 1)});
  }
  if (l.sensor == SensorSide::kLoad) {
    f.physical.note = "no two-mass parameters from a load-side response: its low-frequency gain gives the total inertia "
                      "(1/K" + std::string(l.lag ? "' = tau2/K" : "") + " = " +
                      num(l.lag ? std::exp(t[l.lag_index()]) / std::abs(f.model.gain) : 1.0 / std::abs(f.model.gain), 6) +
                      "), the split between motor and load needs the motor side's antiresonance";
  } else if (l.modes == 1) {
    const Eigen::Index b = l.mode_base(0);
    // u = (ln K', ln ωz, ln ζz, ln ωn) with K' = K/τ2 when there is a lag (its DC gain 1/τ2
    // belongs to the gain the motor inertia is read from): u = T θ, cov(u) = T C Tᵀ.
    Eigen::MatrixXd to_u = Eigen::MatrixXd::Zero(4, c.cols());
    to_u(0, 0) = 1.0;
    if (l.lag) to_u(0, l.lag_index()) = -1.0;
    for (Eigen::Index i = 0; i < 3; ++i) to_u(1 + i, b + i) = 1.0;
    const Eigen::Matrix4d sub = to_u * c * to_u.transpose();
    f.physical = two_mass_parameters(f.model, sub);
  } else if (l.modes == 0) {
    f.physical.note = "not a two-mass system: the model has no flexible mode (rigid body only)";
  } else {
    f.physical.note = "not a two-mass system: the model has " + std::to_string(l.modes) +
                      " flexible modes (two-mass parameters need exactly one)";
  }
  return f;
}

/// Three-point interpolation (C5.8) through the lowest point and the measured points at the
/// antiresonance and resonance of `pair`.
void add_three_point_start(const core::FrequencyResponse& response, const std::pair<Extremum, Extremum>& pair,
                           OutputKind output, const Layout& l, const Data& data,
                           std::vector<std::pair<PlantModel, std::string>>& starts, std::string& failures) {
  std::array<std::size_t, 3> idx{0, std::min(pair.first.index, pair.second.index), std::max(pair.first.index, pair.second.index)};
  if (idx[1] == 0) return;
  std::array<double, 3> w{};
  std::array<Complex, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& p = response.points[idx[i]];
    w[i] = kTwoPi * p.freq_hz;
    v[i] = output == OutputKind::kPosition ? p.value * Complex(0.0, w[i]) : p.value;
  }
  const InterpolationResult ip = three_point_interpolation(w, v, l.rigid);
  if (ip.model)
    starts.emplace_back(complete_start(*ip.model, false, l, data), "three-point");
  else
    failures += "three-point interpolation: " + ip.failure + "; ";
}

void require_enough_points(std::size_t points, std::size_t parameters, const std::string& what) {
  // LM needs more real residuals (2 per point) than parameters for a covariance estimate.
  const std::size_t needed = parameters / 2 + 1;
  if (points < needed)
    throw core::InputError(core::at_field("points"),
                           what + " has " + std::to_string(parameters) + " parameters and needs at least " +
                               std::to_string(needed) + " frequency points; the response has " + std::to_string(points));
}

}  // namespace

// ---- public -----------------------------------------------------------------------------------

void validate_response(const core::FrequencyResponse& response) {
  if (response.points.empty()) throw core::InputError(core::at_field("points"), "the frequency response has no points");
  for (std::size_t i = 0; i < response.points.size(); ++i) {
    const auto& p = response.points[i];
    const std::string at = "points[" + std::to_string(i) + "].";
    if (!(std::isfinite(p.freq_hz) && p.freq_hz > 0.0))
      throw core::InputError(core::at_field(at + "freq_hz"), "expected a finite frequency > 0, got " + num(p.freq_hz));
    if (i > 0 && !(p.freq_hz > response.points[i - 1].freq_hz))
      throw core::InputError(core::at_field(at + "freq_hz"), "frequencies must increase strictly, got " + num(p.freq_hz, 10) +
                                                                 " Hz after " + num(response.points[i - 1].freq_hz, 10) + " Hz");
    if (!(std::isfinite(p.value.real()) && std::isfinite(p.value.imag())))
      throw core::InputError(core::at_field(at + "value"), "expected a finite complex value, got NaN or infinity");
    if (std::abs(p.value) == 0.0)
      throw core::InputError(core::at_field(at + "value"), "a zero response cannot be fitted on a log scale");
    if (!(std::isfinite(p.std_dev) && p.std_dev >= 0.0))
      throw core::InputError(core::at_field(at + "std_dev"), "expected a finite standard deviation >= 0, got " + num(p.std_dev));
  }
}

OutputDetection detect_output(const core::FrequencyResponse& response) {
  if (has_invalid(response)) return detect_output(response.valid_only());
  OutputDetection out;
  out.detected = true;
  const auto& pts = response.points;
  if (pts.size() < 3) {
    out.detected = false;
    out.slope_db_per_decade = kNan;
    out.note = "too few points to detect the output kind; assuming velocity";
    return out;
  }
  const double lo = std::log10(pts.front().freq_hz), hi = std::log10(pts.back().freq_hz);
  const PeakPicking peaks = pick_peaks(response, OutputKind::kVelocity);
  std::size_t first_extremum = pts.size();
  for (const auto* list : {&peaks.resonances, &peaks.antiresonances})
    for (const Extremum& e : *list)
      if (e.prominence > 0.1) first_extremum = std::min(first_extremum, e.index);
  std::size_t count = 0;
  while (count < pts.size() && (count < 3 || std::log10(pts[count].freq_hz) <= lo + 0.25 * (hi - lo)) &&
         (count < 3 || count < first_extremum))
    ++count;
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double x = std::log10(pts[i].freq_hz), y = 20.0 * std::log10(std::abs(pts[i].value));
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double c = static_cast<double>(count);
  out.slope_db_per_decade = (c * sxy - sx * sy) / (c * sxx - sx * sx);
  out.output = out.slope_db_per_decade > -30.0 ? OutputKind::kVelocity : OutputKind::kPosition;
  out.note = "low-frequency slope " + num(out.slope_db_per_decade, 3) + " dB/dec over the lowest " + std::to_string(count) +
             " points: " + to_string(out.output) + " output";
  return out;
}

PhysicalExtraction two_mass_parameters(const PlantModel& model, const Eigen::Matrix4d& log_covariance) {
  PhysicalExtraction out;
  if (model.modes.size() != 1) {
    out.note = "not a two-mass system: the model has " + std::to_string(model.modes.size()) + " flexible modes";
    return out;
  }
  // With a lag 1/(s + τ2) the high-frequency asymptote of the mechanics is (K/τ2)/s.
  const double k1 = model.lag_pole_rad_s ? model.gain / *model.lag_pole_rad_s : model.gain;
  const double wz = model.modes[0].antiresonance.omega_rad_s, zz = model.modes[0].antiresonance.zeta;
  const double wn = model.modes[0].resonance.omega_rad_s, zn = model.modes[0].resonance.zeta;
  if (!(k1 > 0.0)) {
    out.note = "not a two-mass system: the gain is negative (sensor or actuator sign reversed?)";
    return out;
  }
  const double r = wn / wz;
  if (!(r > 1.0)) {
    out.note = "not a two-mass system: the resonance (" + num(wn / kTwoPi) + " Hz) lies below the antiresonance (" +
               num(wz / kTwoPi) + " Hz); a collocated motor-side response has the antiresonance first";
    return out;
  }
  const double im = 1.0 / k1, il = im * (r * r - 1.0), k = il * wz * wz, b = 2.0 * zz * wz * il;
  // Delta method: gradients with respect to u = (ln K', ln ωz, ln ζz, ln ωn), K' = K/τ2 with a lag
  // (the caller transforms θ's covariance to u), else K.
  auto with_std = [&](double v, const Eigen::Vector4d& g) { return Estimate{v, std::sqrt(g.dot(log_covariance * g))}; };
  TwoMassParameters p;
  p.motor_inertia = with_std(im, Eigen::Vector4d(-im, 0.0, 0.0, 0.0));
  p.load_inertia = with_std(il, Eigen::Vector4d(-il, -2.0 * wn * wn / (wz * wz * k1), 0.0, 2.0 * wn * wn / (wz * wz * k1)));
  p.stiffness = with_std(k, Eigen::Vector4d(-k, -2.0 * wz * wz / k1, 0.0, 2.0 * wn * wn / k1));
  p.damping = with_std(b, Eigen::Vector4d(-b, 2.0 * zz * (-wn * wn / wz - wz) / k1, b, 4.0 * zz * wn * wn / (wz * k1)));
  p.resonance_ratio = with_std(r, Eigen::Vector4d(0.0, -r, 0.0, r));
  p.damping_consistency = zn / (r * zz);
  out.parameters = p;
  out.note = std::string("two-mass parameters from ") + (model.lag_pole_rad_s ? "K/tau2" : "K") +
             " = 1/Im, antiresonance and resonance (r = " + num(r) + ")";
  return out;
}

FitResult refine_model(const core::FrequencyResponse& response, const PlantModel& start, const FitOptions& options) {
  validate_response(response);
  if (has_invalid(response)) return refine_model(response.valid_only(), start, options);
  const Layout l = layout_of(start);
  require_enough_points(response.size(), static_cast<std::size_t>(l.size()), "the model");
  const Data data = make_data(response);
  return finish(refine(start, data, options, "given"), l, data);
}

FitResult fit_model(const core::FrequencyResponse& response, std::size_t modes, OutputKind output,
                    const FitOptions& options) {
  validate_response(response);
  if (has_invalid(response)) return fit_model(response.valid_only(), modes, output, options);
  const Layout l{modes, options.rigid, output, options.lag, options.delay, options.sensor};
  const bool load = options.sensor == SensorSide::kLoad;
  const std::string what = modes == 1 && !load ? "the two-mass model"
                                               : "a model with " + std::to_string(modes) + (load ? " load-side" : "") + " modes";
  require_enough_points(response.size(), static_cast<std::size_t>(l.size()), what);
  const Data data = make_data(response);

  std::vector<std::pair<PlantModel, std::string>> starts;
  std::string failures;
  if (modes > 0 && load) {
    // A load-side response has maxima only (plant_model.hpp): peak picking gives the resonances.
    const PeakPicking peaks = pick_peaks(response, output);
    const auto choices = resonance_choices(peaks, modes);
    if (choices.empty())
      failures += "peak picking: " + std::to_string(peaks.resonances.size()) + " resonance(s) found, " +
                  std::to_string(modes) + " needed; ";
    for (auto choice : choices) {
      std::sort(choice.begin(), choice.end(), [](const Extremum& a, const Extremum& b) { return a.omega_rad_s < b.omega_rad_s; });
      PlantModel m;
      m.rigid = options.rigid;
      m.sensor = SensorSide::kLoad;
      for (const Extremum& res : choice) m.modes.push_back(Mode{{}, {res.omega_rad_s, res.zeta}});
      starts.emplace_back(complete_start(m, options.rigid == RigidKind::kRealPole, l, data), "peak-picking");
    }
  } else if (modes > 0) {
    const PeakPicking peaks = pick_peaks(response, output);
    const auto choices = resonance_choices(peaks, modes);
    if (choices.empty()) failures += "peak picking: " + pair_modes(peaks, modes).failure + "; ";
    for (const auto& choice : choices) {
      const ModePairing pairing = pair_modes(peaks, choice);
      if (pairing.pairs.empty()) {
        failures += "peak picking: " + pairing.failure + "; ";
        continue;
      }
      if (modes == 1) add_three_point_start(response, pairing.pairs.front(), output, l, data, starts, failures);
      PlantModel m;
      m.rigid = options.rigid;
      for (const auto& [anti, res] : pairing.pairs)
        m.modes.push_back(Mode{{anti.omega_rad_s, anti.zeta}, {res.omega_rad_s, res.zeta}});
      starts.emplace_back(complete_start(m, options.rigid == RigidKind::kRealPole, l, data), "peak-picking");
    }
  } else {
    PlantModel m;
    m.rigid = options.rigid;
    m.sensor = options.sensor;
    starts.emplace_back(complete_start(m, options.rigid == RigidKind::kRealPole, l, data), "rigid");
  }
  if (starts.empty()) {
    FitResult f;
    f.points = response.size();
    f.parameters = static_cast<std::size_t>(l.size());
    f.message = "no starting point: " + failures.substr(0, failures.size() - 2);
    f.physical.note = modes == 1 && !load ? "not a two-mass system: no resonance/antiresonance pair found in the data "
                                            "(a load encoder's response has no antiresonance: fit it as a load-side response)"
                                          : "";
    return f;
  }
  std::optional<Run> best;
  for (auto& [start, name] : starts) {
    Run run = refine(start, data, options, name);
    if (!best || detail::better_run(run.lm, best->lm)) best = std::move(run);
  }
  return finish(*best, l, data);
}

ModelRequest parse_model_request(const std::string& text, const std::string& option) {
  ModelRequest r;
  if (text == "two-mass") {
    r.kind = ModelRequest::Kind::kTwoMass;
    r.modes = 1;
    return r;
  }
  if (text == "auto") {
    r.kind = ModelRequest::Kind::kAuto;
    return r;
  }
  const std::string prefix = "modes:";
  if (text.rfind(prefix, 0) == 0) {
    const std::string digits = text.substr(prefix.size());
    if (!digits.empty() && digits.size() <= 2 && std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
      r.kind = ModelRequest::Kind::kModes;
      r.modes = static_cast<std::size_t>(std::stoi(digits));
      return r;
    }
  }
  throw core::InputError(core::at_field(option), "expected two-mass, modes:N (N = 0..99) or auto, got '" + text + "'");
}

std::string to_string(const ModelRequest& request) {
  switch (request.kind) {
    case ModelRequest::Kind::kTwoMass: return "two-mass";
    case ModelRequest::Kind::kModes: return "modes:" + std::to_string(request.modes);
    case ModelRequest::Kind::kAuto: return "auto";
  }
  return "";
}

FitReport fit_plant(const core::FrequencyResponse& response, const ModelRequest& request, const FitOptions& options) {
  validate_response(response);
  if (has_invalid(response)) {
    FitReport report = fit_plant(response.valid_only(), request, options);
    std::vector<std::pair<double, std::string>> left;
    for (std::size_t k = 0; k < report.left_out.size(); ++k) left.emplace_back(report.left_out_hz[k], report.left_out[k]);
    for (const auto& p : response.points)
      if (!p.valid) left.emplace_back(p.freq_hz, num(p.freq_hz, 6) + " Hz: " + (p.note.empty() ? "marked invalid" : p.note));
    // Invalid points and the refit's outliers in one frequency order.
    std::stable_sort(left.begin(), left.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    report.left_out.clear();
    report.left_out_hz.clear();
    for (auto& [hz, why] : left) {
      report.left_out_hz.push_back(hz);
      report.left_out.push_back(std::move(why));
    }
    return report;
  }
  FitReport report;
  report.request = request;
  if (options.output == OutputChoice::kDetect) {
    report.output = detect_output(response);
  } else {
    report.output.output = options.output == OutputChoice::kVelocity ? OutputKind::kVelocity : OutputKind::kPosition;
    report.output.slope_db_per_decade = kNan;
    report.output.note = "output given by the user: " + to_string(report.output.output);
  }
  const OutputKind output = report.output.output;
  const std::size_t m = response.size();
  const bool known_std = std::all_of(response.points.begin(), response.points.end(), [](const auto& p) { return p.std_dev > 0.0; });

  std::vector<std::size_t> orders;
  if (request.kind == ModelRequest::Kind::kAuto) {
    report.selection.method = "auto";
    // Peaks below the noise are not modes: a prominence threshold of 0.1 neper (0.9 dB) or three
    // times the median relative standard deviation, whichever is larger.
    double threshold = 0.1;
    if (known_std) {
      std::vector<double> rel;
      for (const auto& p : response.points) rel.push_back(p.std_dev / std::abs(p.value));
      std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(rel.size() / 2), rel.end());
      threshold = std::max(threshold, 3.0 * rel[rel.size() / 2]);
    }
    const PeakPicking peaks = pick_peaks(response, output);
    const auto found = static_cast<std::size_t>(std::count_if(peaks.resonances.begin(), peaks.resonances.end(),
                                                              [&](const Extremum& e) { return e.prominence >= threshold; }));
    std::size_t top = std::min(options.max_modes, found);
    while (top > 0 && 2 * m <= parameter_count(top, options.rigid, options.lag, options.delay, options.sensor)) --top;
    for (std::size_t n = 0; n <= top; ++n) orders.push_back(n);
    require_enough_points(m, parameter_count(0, options.rigid, options.lag, options.delay), "the rigid model");
    report.selection.criterion =
        known_std ? "smallest n with reduced chi-square 2*cost/(2m-p) <= 1 + 3*sqrt(2/(2m-p)) (within the noise level); "
                    "BIC if none"
                  : "minimum BIC = 2m*ln(RSS/2m) + p*ln(2m) over the 2m log-ratio residuals";
    report.selection.criterion += "; n = 0.." + std::to_string(top) + " (" + std::to_string(found) +
                                  " resonance peak(s) above " + num(threshold, 2) + " neper prominence, max " +
                                  std::to_string(options.max_modes) + ")";
  } else {
    report.selection.method = "fixed";
    report.selection.criterion = "model order given by the user (" + to_string(request) + ")";
    orders.push_back(request.kind == ModelRequest::Kind::kTwoMass ? 1 : request.modes);
  }

  std::vector<FitResult> fits;
  for (std::size_t n : orders) {
    FitResult f = fit_model(response, n, output, options);
    SelectionCandidate c;
    c.modes = n;
    c.parameters = f.parameters;
    c.converged = f.converged;
    c.cost = f.cost;
    c.message = f.message;
    const double residuals = 2.0 * static_cast<double>(m);
    const double p = static_cast<double>(f.parameters);
    if (report.selection.method == "auto") {
      const double rss = std::max(2.0 * f.cost, residuals * 1e-18);
      c.score = known_std ? 2.0 * f.cost / (residuals - p) : residuals * std::log(rss / residuals) + p * std::log(residuals);
    } else {
      c.score = kNan;
    }
    report.selection.candidates.push_back(c);
    fits.push_back(std::move(f));
  }

  std::optional<std::size_t> chosen;
  const auto& cands = report.selection.candidates;
  if (report.selection.method == "auto") {
    if (known_std)
      for (std::size_t i = 0; i < cands.size() && !chosen; ++i) {
        const double dof = 2.0 * static_cast<double>(m) - static_cast<double>(cands[i].parameters);
        if (cands[i].converged && cands[i].score <= 1.0 + 3.0 * std::sqrt(2.0 / dof)) chosen = i;
      }
    if (!chosen) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < cands.size(); ++i) {
        const double rss = std::max(2.0 * cands[i].cost, 2.0 * static_cast<double>(m) * 1e-18);
        const double bic = 2.0 * static_cast<double>(m) * std::log(rss / (2.0 * static_cast<double>(m))) +
                           static_cast<double>(cands[i].parameters) * std::log(2.0 * static_cast<double>(m));
        if (cands[i].converged && bic < best) {
          best = bic;
          chosen = i;
        }
      }
      if (chosen && known_std) report.selection.criterion += "; no order reached the noise level, chose by BIC";
    }
    if (!chosen)
      throw core::InputError(core::at_field("--model"), "automatic order selection: no model order converged (" +
                                                            fits.front().message + ")");
  } else {
    chosen = 0;
    const FitResult& f = fits.front();
    if (!f.converged) {
      std::string msg = "fitting '" + to_string(request) + "' failed: " + f.message;
      if (f.iterations > 0) msg += " after " + std::to_string(f.iterations) + " iterations (rms log error " + num(f.rms_log_error, 3) + ")";
      if (!f.physical.note.empty() && request.kind == ModelRequest::Kind::kTwoMass) msg += "; " + f.physical.note;
      msg += "; check the data (points, noise, sign) or try another --model";
      throw core::InputError(core::at_field("--model"), msg);
    }
  }
  report.selection.chosen = fits[*chosen].model.modes.size();
  report.result = std::move(fits[*chosen]);
  if (options.reject_outliers) {
    std::vector<double> sigmas;
    const std::vector<std::size_t> bad = outliers(response, report.result.model, report.result.parameters, sigmas);
    if (!bad.empty()) {
      // Refit without them (once: the refit does not look again), the points listed in left_out.
      core::FrequencyResponse cleaned = response;
      for (std::size_t k = 0; k < bad.size(); ++k) {
        core::FrequencyPoint& p = cleaned.points[bad[k]];
        p.valid = false;
        p.note = "outlier: residual " + num(sigmas[k], 3) + " robust sigma from the first fit (rule: > " +
                 num(kOutlierSigmas, 2) + ")";
      }
      FitOptions once = options;
      once.reject_outliers = false;
      try {
        return fit_plant(cleaned, request, once);
      } catch (const core::InputError&) {
        // The refit failed (too few points left, no order converged): keep the first fit.
        report.result.message += "; the refit without " + std::to_string(bad.size()) +
                                 " outlier(s) failed, so they were kept";
      }
    }
  }
  return report;
}

}  // namespace servotwin::fit
