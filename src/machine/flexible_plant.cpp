#include "field_errors.hpp"
#include "servotwin/machine/flexible_plant.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <string>

#include <Eigen/Eigenvalues>

#include "gaussian.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::machine {

namespace {

// Regimes are enumerated exhaustively (2^count precomputed transition matrices).
constexpr std::size_t kMaxSwitchingElements = 10;
constexpr int kMaxSubsteps = 4096;
constexpr int kMinNonlinearSubsteps = 8;
constexpr double kSubstepPhase = 0.05;  // omega_max h per sub-step
constexpr int kMaxDelaySamples = 100000;
constexpr double kMinSamplePeriod = 1e-7;

using detail::fail;
using detail::number;

using detail::non_negative;
using detail::positive;
std::string indexed(const char* name, std::size_t i) { return std::string(name) + "[" + std::to_string(i) + "]"; }

void validate_chain(const MassChain& c) {
  const std::size_t n = c.masses();
  if (n == 0) fail("inertia", "expected at least one mass");
  if (n > 64) fail("inertia", "at most 64 masses are supported, found " + std::to_string(n));
  for (std::size_t i = 0; i < n; ++i) positive(c.inertia[i], indexed("inertia", i));
  if (c.stiffness.size() != n - 1)
    fail("stiffness", "expected " + std::to_string(n - 1) + " shaft stiffnesses for " + std::to_string(n) +
                          " masses, found " + std::to_string(c.stiffness.size()));
  for (std::size_t i = 0; i + 1 < n; ++i) positive(c.stiffness[i], indexed("stiffness", i));
  const auto optional_size = [](const auto& v, std::size_t expected, const char* field) {
    if (!v.empty() && v.size() != expected)
      fail(field, "expected " + std::to_string(expected) + " values (or none), found " + std::to_string(v.size()));
  };
  optional_size(c.damping, n - 1, "damping");
  optional_size(c.viscous, n, "viscous");
  optional_size(c.friction, n, "friction");
  optional_size(c.backlash, n - 1, "backlash");
  for (std::size_t i = 0; i < c.damping.size(); ++i) non_negative(c.damping[i], indexed("damping", i));
  for (std::size_t i = 0; i < c.viscous.size(); ++i) non_negative(c.viscous[i], indexed("viscous", i));
  for (std::size_t i = 0; i < c.backlash.size(); ++i) non_negative(c.backlash[i], indexed("backlash", i));
  std::size_t switching = 0;
  for (std::size_t i = 0; i < c.friction.size(); ++i) {
    const auto& f = c.friction[i];
    const std::string p = indexed("friction", i);
    non_negative(f.coulomb, p + ".coulomb");
    non_negative(f.stick_band, p + ".stick_band");
    if (f.stiction) {
      non_negative(*f.stiction, p + ".stiction");
      if (*f.stiction < f.coulomb)
        fail(p + ".stiction", "the stiction level " + number(*f.stiction) + " must not be below the Coulomb level " +
                                  number(f.coulomb));
    }
    if (f.active()) ++switching;
  }
  for (double d : c.backlash)
    if (d > 0.0) ++switching;
  if (switching > kMaxSwitchingElements)
    fail("friction", "at most " + std::to_string(kMaxSwitchingElements) +
                         " masses with friction plus shafts with backlash are supported, found " +
                         std::to_string(switching));
}

void validate_transfer_function(const core::TransferFunction& tf) {
  const auto& num = tf.num();
  const auto& den = tf.den();
  for (double v : num.coefficients())
    if (!std::isfinite(v)) fail("num", "expected finite coefficients");
  for (double v : den.coefficients())
    if (!std::isfinite(v)) fail("den", "expected finite coefficients");
  if (den.degree() < 0) fail("den", "the denominator must not be zero");
  if (num.degree() > den.degree())
    fail("num", "the transfer function must be proper (numerator degree " + std::to_string(num.degree()) +
                    " > denominator degree " + std::to_string(den.degree()) + ")");
  for (const auto& p : tf.poles()) {
    if (p.real() > 1e-9 * std::max(1.0, std::abs(p)))
      fail("den", "the plant must be stable or marginally stable; it has a pole at " + number(p.real()) +
                      (p.imag() >= 0 ? "+" : "") + number(p.imag()) + "j rad/s");
  }
}

void validate_settings(const PlantSettings& s) {
  positive(s.ts, "ts");
  if (s.ts < kMinSamplePeriod)
    fail("ts", "expected a sample period of at least " + number(kMinSamplePeriod) + " s (10 MHz), found " + number(s.ts));
  non_negative(s.current_lag, "current_lag");
  if (s.delay_samples < 0 || s.delay_samples > kMaxDelaySamples)
    fail("delay_samples", "expected a whole number in [0, " + std::to_string(kMaxDelaySamples) + "], found " +
                              std::to_string(s.delay_samples));
  non_negative(s.noise_std, "noise_std");
  non_negative(s.quantization, "quantization");
  if (s.substeps < 0 || s.substeps > kMaxSubsteps)
    fail("substeps", "expected 0 (automatic) or a count up to " + std::to_string(kMaxSubsteps) + ", found " +
                         std::to_string(s.substeps));
}

/// Issue 27 §1: dynamics far faster than the sample period (a stiffness of 1e300, a current lag of
/// 1e-12 s) overflow the discretization and the transfer function's coefficients. The limit is
/// what the sub-stepped simulation resolves, kSubstepPhase per sub-step over kMaxSubsteps: rates
/// (a shaft's frequency sqrt(k (1/J_i + 1/J_i+1)), its damping rate b (1/J_i + 1/J_i+1), a mass's
/// viscous rate v/J, the current loop's 1/tau) times ts up to 204.8, a mode 65 times above Nyquist.
void validate_speed(const MassChain& c, const PlantSettings& s) {
  constexpr double limit = kSubstepPhase * kMaxSubsteps;
  const auto check = [&](double rate, const std::string& field, const char* what, const char* advice) {
    if (rate * s.ts <= limit) return;
    fail(field, std::string(what) + " is " + number(rate * s.ts) + " times the sampling rate (rad/s x ts " +
                    number(s.ts) + " s; at most " + number(limit) + ", a mode 65 times above Nyquist, can be "
                    "sampled or simulated): " + advice);
  };
  for (std::size_t i = 0; i + 1 < c.masses(); ++i) {
    const double compliance = 1.0 / c.inertia[i] + 1.0 / c.inertia[i + 1];
    check(std::sqrt(c.stiffness[i] * compliance), indexed("stiffness", i), "the shaft's frequency",
          "a coupling this stiff is rigid; join the masses it couples, or use a shorter ts");
    if (i < c.damping.size())
      check(c.damping[i] * compliance, indexed("damping", i), "the shaft's damping rate", "check its units");
  }
  for (std::size_t i = 0; i < c.viscous.size(); ++i)
    check(c.viscous[i] / c.inertia[i], indexed("viscous", i), "the viscous rate v/J", "check its units");
  if (s.current_lag > 0.0)
    check(1.0 / s.current_lag, "current_lag", "the current loop's rate 1/tau", "give 0 for no current loop lag");
}

// Continuous dynamics of the chain in one regime: `pinned[i]` freezes mass i (its rows are zero),
// `open[s]` disconnects shaft s (backlash gap). States [phi_1 w_1 ... phi_n w_n (lag)], inputs
// [u, f_1 .. f_n] with f_i an extra torque on mass i. Without lag, u drives mass 1 directly.
void chain_dynamics(const MassChain& c, double current_lag, const std::vector<bool>& pinned,
                    const std::vector<bool>& open, Eigen::MatrixXd& a, Eigen::MatrixXd& b) {
  const auto n = static_cast<Eigen::Index>(c.masses());
  const Eigen::Index states = 2 * n + (current_lag > 0.0 ? 1 : 0);
  a = Eigen::MatrixXd::Zero(states, states);
  b = Eigen::MatrixXd::Zero(states, 1 + n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    if (pinned[ui]) continue;
    const double m = c.inertia[ui];
    const Eigen::Index w = 2 * i + 1;
    a(2 * i, w) = 1.0;
    a(w, w) -= c.viscous_of(ui) / m;
    b(w, 1 + i) = 1.0 / m;
    if (i == 0) {
      if (current_lag > 0.0) a(w, states - 1) = 1.0 / m;
      else b(w, 0) = 1.0 / m;
    }
    // Shaft to the left (torque +T on this mass) and to the right (-T).
    // A connected shaft pulls this mass towards its neighbour `other` whichever side it is on:
    // torque k (phi_other - phi_i) + d (w_other - w_i).
    const auto couple = [&](std::size_t shaft, Eigen::Index other) {
      if (open[shaft]) return;
      const double k = c.stiffness[shaft], d = c.damping_of(shaft);
      a(w, 2 * i) -= k / m;
      a(w, w) -= d / m;
      a(w, 2 * other) += k / m;
      a(w, 2 * other + 1) += d / m;
    };
    if (i > 0) couple(static_cast<std::size_t>(i - 1), i - 1);
    if (i + 1 < n) couple(ui, i + 1);
  }
  if (current_lag > 0.0) {
    a(states - 1, states - 1) = -1.0 / current_lag;
    b(states - 1, 0) = 1.0 / current_lag;
  }
}

// [Phi Gamma] of the zero-order-hold discretization over h, row-major.
Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> transition(const Eigen::MatrixXd& a,
                                                                                    const Eigen::MatrixXd& b,
                                                                                    double h) {
  core::StateSpace sys{a, b, Eigen::MatrixXd::Zero(1, a.rows()), Eigen::MatrixXd::Zero(1, b.cols())};
  const core::DiscreteStateSpace d = core::discretize_zoh(sys, h);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> ab(a.rows(), a.cols() + b.cols());
  ab << d.A, d.B;
  return ab;
}

double highest_frequency(const MassChain& c) {
  const auto modes = chain_modes(c);
  return modes.empty() ? 0.0 : modes.back().omega;
}

double sign(double v) noexcept { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

}  // namespace

// ---- names ---------------------------------------------------------------------------------

std::string_view to_string(PlantOutput output) noexcept {
  switch (output) {
    case PlantOutput::MotorVelocity: return "motor_velocity";
    case PlantOutput::MotorPosition: return "motor_position";
    case PlantOutput::LoadVelocity: return "load_velocity";
    case PlantOutput::LoadPosition: return "load_position";
  }
  return "motor_velocity";
}

std::optional<PlantOutput> plant_output_from_string(std::string_view text) noexcept {
  for (auto o : {PlantOutput::MotorVelocity, PlantOutput::MotorPosition, PlantOutput::LoadVelocity,
                 PlantOutput::LoadPosition})
    if (to_string(o) == text) return o;
  return std::nullopt;
}

// ---- chain description ---------------------------------------------------------------------

double MassChain::damping_of(std::size_t shaft) const noexcept { return shaft < damping.size() ? damping[shaft] : 0.0; }
double MassChain::viscous_of(std::size_t mass) const noexcept { return mass < viscous.size() ? viscous[mass] : 0.0; }
double MassChain::backlash_of(std::size_t shaft) const noexcept {
  return shaft < backlash.size() ? backlash[shaft] : 0.0;
}
KarnoppFriction MassChain::friction_of(std::size_t mass) const noexcept {
  return mass < friction.size() ? friction[mass] : KarnoppFriction{};
}

MassChain two_mass(double motor_inertia, double load_inertia, double stiffness, double damping, double motor_viscous,
                   double load_viscous) {
  MassChain c;
  c.inertia = {motor_inertia, load_inertia};
  c.stiffness = {stiffness};
  c.damping = {damping};
  c.viscous = {motor_viscous, load_viscous};
  return c;
}

void validate(const PlantConfig& config) {
  if (const auto* chain = std::get_if<MassChain>(&config.model)) validate_chain(*chain);
  else validate_transfer_function(std::get<TransferFunctionModel>(config.model).tf);
  validate_settings(config.settings);
  if (const auto* chain = std::get_if<MassChain>(&config.model)) validate_speed(*chain, config.settings);
  if (config.frame) {
    validate(*config.frame, "frame.");
    if (!std::holds_alternative<TransferFunctionModel>(config.model))
      detail::fail("frame", "a frame goes with its transfer-function model (eq. 7.172), not with a mass chain");
  }
}

// ---- linear models -------------------------------------------------------------------------

core::StateSpace mass_chain_state_space(const MassChain& chain) {
  validate_chain(chain);
  const std::size_t n = chain.masses();
  Eigen::MatrixXd a, b;
  chain_dynamics(chain, 0.0, std::vector<bool>(n, false), std::vector<bool>(n, false), a, b);
  const auto states = a.rows();
  // Output rows select motor (states 0, 1) and load (2n-2, 2n-1) coordinates.
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(states, states);
  const auto last = static_cast<Eigen::Index>(2 * (n - 1));
  Eigen::MatrixXd c(4, states);
  c << identity.row(0), identity.row(1), identity.row(last), identity.row(last + 1);
  return {a, b.col(0), c, Eigen::MatrixXd::Zero(4, 1)};
}

core::TransferFunction mass_chain_transfer_function(const MassChain& chain, PlantOutput output) {
  validate_chain(chain);
  const std::size_t n = chain.masses();
  // Diagonal and coupling polynomials of Z(s) = M s^2 + B s + K.
  std::vector<core::Polynomial> diag(n), coupling(n > 0 ? n - 1 : 0);
  for (std::size_t i = 0; i < n; ++i) {
    double b = chain.viscous_of(i), k = 0.0;
    if (i > 0) b += chain.damping_of(i - 1), k += chain.stiffness[i - 1];
    if (i + 1 < n) b += chain.damping_of(i), k += chain.stiffness[i];
    diag[i] = core::Polynomial{chain.inertia[i], b, k};
  }
  for (std::size_t i = 0; i + 1 < n; ++i) coupling[i] = core::Polynomial{chain.damping_of(i), chain.stiffness[i]};
  // tail[i] = det Z_{i..n-1} (continuant from the load end); tail[n] = 1.
  std::vector<core::Polynomial> tail(n + 1);
  tail[n] = core::Polynomial{1.0};
  for (std::size_t i = n; i-- > 0;) {
    tail[i] = diag[i] * tail[i + 1];
    if (i + 2 <= n) tail[i] = tail[i] - coupling[i] * coupling[i] * tail[i + 2];
  }
  // det Z(0) = det K = 0 for a chain without springs to ground: drop the constant term.
  auto det = std::vector<double>(tail[0].coefficients().begin(), tail[0].coefficients().end());
  det.pop_back();
  const core::Polynomial q(det);
  const std::size_t j = (output == PlantOutput::MotorPosition || output == PlantOutput::MotorVelocity) ? 0 : n - 1;
  core::Polynomial num{1.0};
  for (std::size_t i = 0; i < j; ++i) num = num * coupling[i];
  num = num * tail[j + 1];
  const bool position = output == PlantOutput::MotorPosition || output == PlantOutput::LoadPosition;
  const core::Polynomial den = position ? q * core::Polynomial{1.0, 0.0} : q;
  return core::TransferFunction(num, den).normalized();
}

TwoMassParameters two_mass_parameters(double im, double il, double k, double b) {
  positive(im, "motor_inertia");
  positive(il, "load_inertia");
  positive(k, "stiffness");
  non_negative(b, "damping");
  TwoMassParameters p;
  p.omega_n = std::sqrt(k * (il + im) / (il * im));
  p.omega_z = std::sqrt(k / il);
  p.zeta = std::sqrt(b * b * (il + im) / (4.0 * k * il * im));
  p.zeta_z = std::sqrt(b * b / (4.0 * k * il));
  p.r = std::sqrt(1.0 + il / im);
  p.k1 = 1.0 / im;
  p.k2 = b / (im * il);
  return p;
}

TwoMassParameters two_mass_parameters(const MassChain& chain) {
  validate_chain(chain);
  if (chain.masses() != 2) fail("inertia", "expected exactly two masses, found " + std::to_string(chain.masses()));
  return two_mass_parameters(chain.inertia[0], chain.inertia[1], chain.stiffness[0], chain.damping_of(0));
}

std::vector<ChainMode> chain_modes(const MassChain& chain) {
  validate_chain(chain);
  const auto n = static_cast<Eigen::Index>(chain.masses());
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n), k = Eigen::MatrixXd::Zero(n, n), b = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    m(i, i) = chain.inertia[ui];
    b(i, i) = chain.viscous_of(ui);
  }
  for (Eigen::Index s = 0; s + 1 < n; ++s) {
    const auto us = static_cast<std::size_t>(s);
    const double ks = chain.stiffness[us], bs = chain.damping_of(us);
    k(s, s) += ks, k(s + 1, s + 1) += ks, k(s, s + 1) -= ks, k(s + 1, s) -= ks;
    b(s, s) += bs, b(s + 1, s + 1) += bs, b(s, s + 1) -= bs, b(s + 1, s) -= bs;
  }
  // Scale to M = I first (M is diagonal): the symmetric problem D^-1/2 K D^-1/2 is then
  // independent of the inertia units, and its eigenvectors give phi = D^-1/2 v with phi^T M phi = 1.
  const Eigen::VectorXd inv_sqrt_m = m.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd ks = inv_sqrt_m.asDiagonal() * k * inv_sqrt_m.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(ks);
  const double top = std::max(solver.eigenvalues().cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  std::vector<ChainMode> modes;
  for (Eigen::Index i = 0; i < n; ++i) {
    ChainMode mode;
    const double lambda = solver.eigenvalues()(i);
    // The rigid-body eigenvalue is 0 up to rounding of the largest one.
    mode.omega = lambda > 64.0 * std::numeric_limits<double>::epsilon() * top ? std::sqrt(lambda) : 0.0;
    mode.shape = inv_sqrt_m.asDiagonal() * solver.eigenvectors().col(i);
    const double biggest = mode.shape.cwiseAbs().maxCoeff();
    for (Eigen::Index j = 0; j < n; ++j) {
      if (std::abs(mode.shape(j)) > 1e-9 * biggest) {
        if (mode.shape(j) < 0.0) mode.shape = -mode.shape;
        break;
      }
    }
    mode.zeta = mode.omega > 0.0 ? mode.shape.dot(b * mode.shape) / (2.0 * mode.omega) : 0.0;
    modes.push_back(std::move(mode));
  }
  return modes;
}

// ---- the sampled plant ---------------------------------------------------------------------

FlexiblePlant::~FlexiblePlant() = default;
FlexiblePlant::FlexiblePlant(FlexiblePlant&&) noexcept = default;
FlexiblePlant& FlexiblePlant::operator=(FlexiblePlant&&) noexcept = default;

FlexiblePlant::FlexiblePlant(const PlantConfig& config)
    : config_(config), noise_(std::make_unique<detail::GaussianSource>(config.settings.seed, 0)) {
  validate(config_);
  if (const auto* chain = std::get_if<MassChain>(&config_.model)) build_mass_chain(*chain);
  else build_transfer_function(std::get<TransferFunctionModel>(config_.model).tf);
  delay_line_.assign(static_cast<std::size_t>(config_.settings.delay_samples), 0.0);
  reset();
}

void FlexiblePlant::build_mass_chain(const MassChain& chain) {
  chain_ = true;
  n_ = chain.masses();
  const double lag = config_.settings.current_lag;
  for (std::size_t i = 0; i < n_; ++i) {
    inertia_.push_back(chain.inertia[i]);
    viscous_.push_back(chain.viscous_of(i));
    friction_.push_back(chain.friction_of(i));
    if (friction_.back().active()) friction_masses_.push_back(i);
  }
  for (std::size_t s = 0; s + 1 < n_; ++s) {
    stiffness_.push_back(chain.stiffness[s]);
    shaft_damping_.push_back(chain.damping_of(s));
    half_gap_.push_back(0.5 * chain.backlash_of(s));
    if (half_gap_.back() > 0.0) backlash_shafts_.push_back(s);
  }
  nonlinear_ = !friction_masses_.empty() || !backlash_shafts_.empty();
  Eigen::MatrixXd a, b;
  chain_dynamics(chain, lag, std::vector<bool>(n_, false), std::vector<bool>(n_, false), a, b);
  states_ = a.rows();
  lag_index_ = lag > 0.0 ? states_ - 1 : -1;
  const double ts = config_.settings.ts;
  if (!nonlinear_) {
    // Inputs [u, Tl]: b's columns are [u, f_1 .. f_n] with f_i a torque on mass i, and the load
    // torque opposes the motion of the last mass.
    Eigen::MatrixXd inputs(b.rows(), 2);
    inputs.col(0) = b.col(0);
    inputs.col(1) = -b.col(static_cast<Eigen::Index>(n_));
    ab_ = transition(a, inputs, ts);
    substeps_ = 1;
  } else {
    substeps_ = config_.settings.substeps;
    if (substeps_ == 0) {
      const double needed = std::ceil(highest_frequency(chain) * ts / kSubstepPhase);
      substeps_ = static_cast<int>(std::clamp(needed, static_cast<double>(kMinNonlinearSubsteps),
                                              static_cast<double>(kMaxSubsteps)));
    }
    const double h = ts / substeps_;
    const std::size_t f = friction_masses_.size(), g = backlash_shafts_.size();
    const std::size_t regimes = std::size_t{1} << (f + g);
    regime_.reserve(regimes);
    std::vector<bool> pinned(n_), open(n_);
    for (std::size_t r = 0; r < regimes; ++r) {
      std::fill(pinned.begin(), pinned.end(), false);
      std::fill(open.begin(), open.end(), false);
      for (std::size_t j = 0; j < f; ++j) pinned[friction_masses_[j]] = ((r >> j) & 1U) != 0;
      for (std::size_t j = 0; j < g; ++j) open[backlash_shafts_[j]] = ((r >> (f + j)) & 1U) != 0;
      chain_dynamics(chain, lag, pinned, open, a, b);
      regime_.push_back(transition(a, b, h));
    }
  }
  xw_.setZero(states_ + 1 + static_cast<Eigen::Index>(n_));  // also holds [x; u; Tl] of the linear step
  next_.setZero(states_);
  x_.setZero(states_);
}

void FlexiblePlant::build_transfer_function(const core::TransferFunction& tf) {
  chain_ = false;
  const core::StateSpace ss = core::to_state_space(tf.normalized());
  const double lag = config_.settings.current_lag;
  const Eigen::Index order = ss.states();
  states_ = order + (lag > 0.0 ? 1 : 0);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(states_, states_);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(states_, 1);
  a.topLeftCorner(order, order) = ss.A;
  c_ = Eigen::RowVectorXd::Zero(states_);
  c_.head(order) = ss.C.row(0);
  if (lag > 0.0) {
    // The plant is driven by the lagged torque state; its feedthrough D reads that state too.
    a.block(0, order, order, 1) = ss.B;
    a(order, order) = -1.0 / lag;
    b(order, 0) = 1.0 / lag;
    c_(order) = ss.D(0, 0);
    d_ = 0.0;
    lag_index_ = order;
  } else {
    b.topRows(order) = ss.B;
    d_ = ss.D(0, 0);
  }
  ab_ = transition(a, b, config_.settings.ts);
  xw_.setZero(states_ + 1);
  next_.setZero(states_);
  x_.setZero(states_);
  substeps_ = 1;
}

void FlexiblePlant::reset() noexcept {
  x_.setZero();
  std::fill(delay_line_.begin(), delay_line_.end(), 0.0);
  delay_pos_ = 0;
  stuck_ = 0;
  last_u_ = 0.0;
  *noise_ = detail::GaussianSource(config_.settings.seed, 0);
}

void FlexiblePlant::set_chain_state(const Eigen::VectorXd& angles, const Eigen::VectorXd& velocities) {
  if (!chain_) fail("model", "a transfer-function plant has no mass-chain state");
  const auto n = static_cast<Eigen::Index>(n_);
  if (angles.size() != n || velocities.size() != n)
    fail("state", "expected " + std::to_string(n_) + " angles and velocities");
  if (!angles.allFinite() || !velocities.allFinite()) fail("state", "expected finite values");
  x_.setZero();
  for (Eigen::Index i = 0; i < n; ++i) {
    x_(2 * i) = angles(i);
    x_(2 * i + 1) = velocities(i);
  }
  stuck_ = 0;
}

double FlexiblePlant::shaft_torque(std::size_t shaft) const {
  if (!chain_) fail("model", "a transfer-function plant has no shafts");
  if (shaft + 1 >= n_) fail("shaft", "shaft index " + std::to_string(shaft) + " out of range");
  const auto s = static_cast<Eigen::Index>(shaft);
  const double twist = x_(2 * s) - x_(2 * s + 2);
  const double rate = x_(2 * s + 1) - x_(2 * s + 3);
  const double hg = half_gap_[shaft];
  if (hg > 0.0 && std::abs(twist) <= hg) return 0.0;
  return stiffness_[shaft] * (twist - hg * sign(twist)) + shaft_damping_[shaft] * rate;
}

double FlexiblePlant::external_torque(std::size_t mass, double u, double load) const noexcept {
  const auto i = static_cast<Eigen::Index>(mass);
  double t = -viscous_[mass] * x_(2 * i + 1);
  if (mass == 0) t += lag_index_ >= 0 ? x_(lag_index_) : u;
  if (mass + 1 == n_) t -= load;
  // shaft_torque cannot throw for valid indices; repeated inline to stay noexcept.
  const auto torque = [this](std::size_t s) noexcept {
    const auto e = static_cast<Eigen::Index>(s);
    const double twist = x_(2 * e) - x_(2 * e + 2);
    const double hg = half_gap_[s];
    if (hg > 0.0 && std::abs(twist) <= hg) return 0.0;
    return stiffness_[s] * (twist - hg * sign(twist)) + shaft_damping_[s] * (x_(2 * e + 1) - x_(2 * e + 3));
  };
  if (mass > 0) t += torque(mass - 1);
  if (mass + 1 < n_) t -= torque(mass);
  return t;
}

void FlexiblePlant::advance_linear(double u, double load) noexcept {
  const Eigen::Index n = states_;
  const Eigen::Index width = ab_.cols();  // n + 1, or n + 2 with a chain's load-torque input
  double* xw = xw_.data();
  for (Eigen::Index i = 0; i < n; ++i) xw[i] = x_[i];
  xw[n] = u;
  if (width > n + 1) xw[n + 1] = load;
  double* x = x_.data();
  for (Eigen::Index r = 0; r < n; ++r) {
    const double* row = ab_.data() + r * width;
    double acc = 0.0;
    for (Eigen::Index j = 0; j < width; ++j) acc += row[j] * xw[j];
    x[r] = acc;
  }
}

void FlexiblePlant::advance_nonlinear(double u, double load) noexcept {
  const Eigen::Index n = states_;
  const Eigen::Index width = n + 1 + static_cast<Eigen::Index>(n_);
  const std::size_t f = friction_masses_.size();
  double* xw = xw_.data();
  double* force = xw + n + 1;  // f_1 .. f_n
  // Direction each friction mass moves in during the sub-step (0 = pinned); a reversal stops it.
  double direction[kMaxSwitchingElements] = {};
  for (int step = 0; step < substeps_; ++step) {
    std::size_t regime = 0;
    for (std::size_t i = 0; i < n_; ++i) force[i] = 0.0;
    force[n_ - 1] = -load;
    for (std::size_t j = 0; j < backlash_shafts_.size(); ++j) {
      const std::size_t s = backlash_shafts_[j];
      const auto e = static_cast<Eigen::Index>(s);
      const double twist = x_(2 * e) - x_(2 * e + 2);
      if (std::abs(twist) <= half_gap_[s]) {
        regime |= std::size_t{1} << (f + j);
      } else {
        // Contact: T = k twist + b rate - k (D/2) sign(twist); the offset acts as -T on the
        // left mass and +T on the right one.
        const double offset = stiffness_[s] * half_gap_[s] * sign(twist);
        force[s] += offset;
        force[s + 1] -= offset;
      }
    }
    stuck_ = 0;
    for (std::size_t j = 0; j < f; ++j) {
      const std::size_t i = friction_masses_[j];
      const auto w = static_cast<Eigen::Index>(2 * i + 1);
      const auto& fr = friction_[i];
      const double v = x_(w);
      if (std::abs(v) <= fr.stick_band) {
        const double te = external_torque(i, u, load);
        if (std::abs(te) < fr.static_level()) {
          x_(w) = 0.0;  // Karnopp stick: the velocity is exactly zero, the mass pinned
          regime |= std::size_t{1} << j;
          stuck_ |= std::uint64_t{1} << i;
          direction[j] = 0.0;
        } else {
          force[i] -= fr.static_level() * sign(te);
          direction[j] = sign(te);
        }
      } else {
        force[i] -= fr.coulomb * sign(v);
        direction[j] = sign(v);
      }
    }
    for (Eigen::Index i = 0; i < n; ++i) xw[i] = x_[i];
    xw[n] = u;
    const double* m = regime_[regime].data();
    double* next = next_.data();
    for (Eigen::Index r = 0; r < n; ++r) {
      const double* row = m + r * width;
      double acc = 0.0;
      for (Eigen::Index c = 0; c < width; ++c) acc += row[c] * xw[c];
      next[r] = acc;
    }
    // A sliding mass whose velocity reversed inside the sub-step came to rest there: stop it so
    // that the stick test of the next sub-step decides (no chatter around zero).
    for (std::size_t j = 0; j < f; ++j) {
      const auto w = static_cast<Eigen::Index>(2 * friction_masses_[j] + 1);
      if (direction[j] != 0.0 && direction[j] * next[w] < 0.0) next[w] = 0.0;
    }
    x_.swap(next_);
  }
}

double FlexiblePlant::exact_output() const noexcept {
  if (!chain_) return c_.dot(x_) + d_ * last_u_;
  const auto last = static_cast<Eigen::Index>(2 * (n_ - 1));
  switch (config_.settings.output) {
    case PlantOutput::MotorPosition: return x_(0);
    case PlantOutput::MotorVelocity: return x_(1);
    case PlantOutput::LoadPosition: return x_(last);
    case PlantOutput::LoadVelocity: return x_(last + 1);
  }
  return x_(1);
}

double FlexiblePlant::next_noise() noexcept { return (*noise_)(); }

PlantMeasurement FlexiblePlant::make_measurement(double y_exact) noexcept {
  PlantMeasurement m;
  m.y_exact = y_exact;
  double y = y_exact;
  const auto& s = config_.settings;
  if (s.noise_std > 0.0) y += s.noise_std * next_noise();
  if (s.quantization > 0.0) y = s.quantization * std::round(y / s.quantization);
  m.y = y;
  if (chain_) {
    const auto last = static_cast<Eigen::Index>(2 * (n_ - 1));
    m.motor_position = x_(0);
    m.motor_velocity = x_(1);
    m.load_position = x_(last);
    m.load_velocity = x_(last + 1);
  } else {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    m.motor_position = m.motor_velocity = m.load_position = m.load_velocity = nan;
  }
  return m;
}

PlantMeasurement FlexiblePlant::step(double torque_command, double load_torque) noexcept {
  double u = std::isfinite(torque_command) ? torque_command : 0.0;
  const double load = std::isfinite(load_torque) ? load_torque : 0.0;
  if (!delay_line_.empty()) {
    const double delayed = delay_line_[delay_pos_];
    delay_line_[delay_pos_] = u;
    delay_pos_ = delay_pos_ + 1 == delay_line_.size() ? 0 : delay_pos_ + 1;
    u = delayed;
  }
  last_u_ = u;
  if (nonlinear_) advance_nonlinear(u, load);
  else advance_linear(u, load);
  return make_measurement(exact_output());
}

PlantMeasurement FlexiblePlant::measure() noexcept { return make_measurement(exact_output()); }

core::TransferFunction FlexiblePlant::transfer_function() const {
  if (chain_) return transfer_function(config_.settings.output);
  core::TransferFunction tf = std::get<TransferFunctionModel>(config_.model).tf;
  const double lag = config_.settings.current_lag;
  if (lag > 0.0) tf = core::series(tf, core::TransferFunction(core::Polynomial{1.0}, core::Polynomial{lag, 1.0}));
  return tf.normalized();
}

core::TransferFunction FlexiblePlant::transfer_function(PlantOutput output) const {
  if (!chain_) fail("output", "a transfer-function plant has one output only");
  core::TransferFunction tf = mass_chain_transfer_function(std::get<MassChain>(config_.model), output);
  const double lag = config_.settings.current_lag;
  if (lag > 0.0) tf = core::series(tf, core::TransferFunction(core::Polynomial{1.0}, core::Polynomial{lag, 1.0}));
  return tf.normalized();
}

}  // namespace servotwin::machine
