#include "servotwin/tuning/position_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"

namespace servotwin::tuning {

namespace {

using core::InputError;
using core::Polynomial;
using core::TransferFunction;
using Complex = std::complex<double>;
using detail::show;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Relative slack of the "<= 1" tests: |φl/φ*| tends to exactly 1 at ω → 0 for every Kpp.
constexpr double kPeakSlack = 1e-9;

void check_options(const PositionLoopOptions& o) {
  detail::require_grid(o.omega_min, o.omega_max, o.grid_points, o.rel_tol, "options.");
  detail::require_positive(o.peak_limit, "options.peak_limit", "a peak limit");
  detail::require_positive(o.kpp_min, "options.kpp_min", "a smallest gain");
  detail::require_positive(o.kpp_max, "options.kpp_max", "a largest gain");
  if (!(o.kpp_max > o.kpp_min))
    throw InputError(core::at_field("options.kpp_max"), "expected kpp_max > kpp_min, got " + show(o.kpp_max));
  if (o.scan_points < 2 || o.scan_points > 10000)
    throw InputError(core::at_field("options.scan_points"), "expected 2 .. 10000 scan points");
}

/// sup over |Δ| <= 1 of |(A + BΔ)/(C + DΔ)|: for |D| < |C| the image of the unit disk is the disk
/// with centre (A C̄ − B D̄)/(|C|² − |D|²) and radius |A D − B C|/(|C|² − |D|²).
double mobius_disk_max(Complex a, Complex b, Complex c, Complex d) noexcept {
  const double den = std::norm(c) - std::norm(d);
  if (!(den > 0.0)) return kInf;
  return (std::abs(a * std::conj(c) - b * std::conj(d)) + std::abs(a * d - b * c)) / den;
}

}  // namespace

VelocityLoopFunctions functions_of(const VelocityLoop& loop) {
  VelocityLoopFunctions f;
  f.motor_tracking = [&loop](double w) { return loop.motor_tracking(w); };
  f.complementary = [&loop](double w) { return loop.complementary(w); };
  if (loop.has_load()) {
    f.load_tracking = [&loop](double w) { return loop.load_tracking(w); };
    f.motor_from_load_torque = [&loop](double w) { return loop.motor_from_load_torque(w); };
    f.load_from_load_torque = [&loop](double w) { return loop.load_from_load_torque(w); };
  }
  const ClosedLoopTransfer cl = loop.closed_loop();
  f.motor_tracking_rational = cl.motor_tracking;
  for (const Complex& p : cl.characteristic.roots()) {
    const double m = std::abs(p);
    if (m > 0.0 && -p.real() / m < 0.5) f.critical_frequencies.push_back(std::abs(p.imag()));
  }
  return f;
}

PositionLoop::PositionLoop(VelocityLoopFunctions velocity, std::optional<TransferFunction> w2,
                           const PositionLoopOptions& options)
    : v_(std::move(velocity)), w2_(std::move(w2)), options_(options) {
  check_options(options_);
  if (!v_.motor_tracking || !v_.complementary)
    throw std::invalid_argument("PositionLoop: the velocity loop needs motor_tracking and complementary");
  if (w2_) {
    if (!w2_->is_proper()) throw InputError(core::at_field("w2"), "expected a proper weight W2");
    if (w2_->den().degree() > 0 && !core::is_hurwitz(w2_->den()))
      throw InputError(core::at_field("w2"), "expected a stable weight W2 (poles in the open left half-plane)");
  }
  grid_ = grid();
}

std::vector<double> PositionLoop::grid() const {
  std::vector<double> g = core::log_space(options_.omega_min, options_.omega_max, options_.grid_points);
  const auto add = [&](double w) {
    if (w > options_.omega_min && w < options_.omega_max) g.push_back(w);
  };
  for (double w : v_.critical_frequencies) add(w);
  if (w2_)
    for (const Complex& p : w2_->poles()) add(std::abs(p));
  std::sort(g.begin(), g.end());
  g.erase(std::unique(g.begin(), g.end()), g.end());
  return g;
}

double PositionLoop::peak(const std::function<Complex(double)>& f) const {
  return core::peak_on_grid(f, grid_, options_.rel_tol).value;
}

Complex PositionLoop::loop_gain(double omega, double kpp) const {
  return kpp * v_.motor_tracking(omega) / Complex(0.0, omega);
}

Complex PositionLoop::motor_tracking(double omega, double kpp) const {
  // Kpp Tvn/(s + Kpp Tvn): finite at ω = 0 (where it is 1).
  const Complex t = kpp * v_.motor_tracking(omega);
  return t / (Complex(0.0, omega) + t);
}

Complex PositionLoop::load_tracking(double omega, double kpp) const {
  if (!has_load()) return {kNaN, kNaN};
  return kpp * v_.load_tracking(omega) / (Complex(0.0, omega) + kpp * v_.motor_tracking(omega));
}

Complex PositionLoop::load_from_load_torque(double omega, double kpp) const {
  if (!has_load()) return {kNaN, kNaN};
  // (Gld − Tvl (Kpp/s) Gmd Spn)/s = (Gld (s + Kpp Tvn) − Kpp Tvl Gmd)/(s (s + Kpp Tvn)).
  const Complex s(0.0, omega);
  const Complex tv = v_.motor_tracking(omega);
  const Complex num = v_.load_from_load_torque(omega) * (s + kpp * tv) - kpp * v_.load_tracking(omega) * v_.motor_from_load_torque(omega);
  return num / (s * (s + kpp * tv));
}

Complex PositionLoop::robust_stability_function(double omega, double kpp) const {
  if (!w2_) return {kNaN, kNaN};
  // W2 (T Spn + Tpn) = W2 (s T + Kpp Tvn)/(s + Kpp Tvn).
  const Complex s(0.0, omega);
  const Complex tv = kpp * v_.motor_tracking(omega);
  return w2_->frequency_response(omega) * (s * v_.complementary(omega) + tv) / (s + tv);
}

Complex PositionLoop::printed_robust_stability_function(double omega, double kpp) const {
  if (!w2_) return {kNaN, kNaN};
  const Complex s(0.0, omega);
  const Complex tv = kpp * v_.motor_tracking(omega);
  // W2 Tvn Spn − W2 Tpn = W2 (s Tvn − Kpp Tvn)/(s + Kpp Tvn).
  return w2_->frequency_response(omega) * (s * v_.motor_tracking(omega) - tv) / (s + tv);
}

double PositionLoop::sufficient_rp_margin(double omega, double kpp) const {
  if (!w2_) return kNaN;
  const Complex s(0.0, omega);
  const Complex tv = v_.motor_tracking(omega);
  const double w2tv = std::abs(w2_->frequency_response(omega) * tv);
  return std::abs(s + kpp * tv) - w2tv * std::abs(s + kpp) - kpp * (std::abs(tv) + w2tv);
}

double PositionLoop::worst_case_motor_tracking(double omega, double kpp) const {
  if (!w2_) return kNaN;
  // Tp(Δ) = (A + BΔ)/(C + DΔ): A = Kpp Tvn, B = A W2, C = s + Kpp Tvn, D = W2 (s T + Kpp Tvn).
  const Complex s(0.0, omega);
  const Complex w2 = w2_->frequency_response(omega);
  const Complex a = kpp * v_.motor_tracking(omega);
  return mobius_disk_max(a, a * w2, s + a, w2 * (s * v_.complementary(omega) + a));
}

bool PositionLoop::stable(double kpp) const {
  const TransferFunction& t = v_.motor_tracking_rational;
  return core::is_hurwitz(Polynomial{1.0, 0.0} * t.den() + kpp * t.num());
}

double PositionLoop::load_tracking_peak(double kpp) const {
  return peak([&](double w) { return load_tracking(w, kpp); });
}

double PositionLoop::load_disturbance_peak(double kpp) const {
  return peak([&](double w) { return load_from_load_torque(w, kpp); });
}

std::optional<double> PositionLoop::load_bandwidth(double kpp) const {
  // Reference |φl/φ*(0)| = 1 exactly: start the grid at 0.
  std::vector<double> g;
  g.reserve(grid_.size() + 1);
  g.push_back(0.0);
  g.insert(g.end(), grid_.begin(), grid_.end());
  return core::bandwidth([&](double w) { return w == 0.0 ? Complex(1.0, 0.0) : load_tracking(w, kpp); }, g);
}

double PositionLoop::robust_stability_peak(double kpp) const {
  return peak([&](double w) { return robust_stability_function(w, kpp); });
}

double PositionLoop::sufficient_rp_min_margin(double kpp) const {
  // The margin is not a modulus; minimize it by maximizing its negative part's modulus over the grid.
  double m = kInf;
  for (double w : grid_) m = std::min(m, sufficient_rp_margin(w, kpp));
  return m;
}

double PositionLoop::worst_case_peak(double kpp) const {
  return peak([&](double w) { return Complex(worst_case_motor_tracking(w, kpp), 0.0); });
}

double PositionLoop::largest_kpp(const std::function<bool(double)>& pass) const {
  const double lo = options_.kpp_min, hi = options_.kpp_max;
  if (!pass(lo)) return 0.0;
  const std::size_t n = options_.scan_points;
  double good = lo;
  for (std::size_t j = 1; j < n; ++j) {
    const double k = lo * std::pow(hi / lo, static_cast<double>(j) / static_cast<double>(n - 1));
    if (pass(k)) {
      good = k;
      continue;
    }
    double bad = k;
    while (bad - good > 1e-6 * good) {
      const double mid = std::sqrt(good * bad);
      (pass(mid) ? good : bad) = mid;
    }
    return good;
  }
  return good;
}

PositionLoopDesign PositionLoop::design() const {
  PositionLoopDesign d;
  const double limit = options_.peak_limit * (1.0 + kPeakSlack);
  if (has_load()) {
    d.kpp_nominal = largest_kpp([&](double k) { return stable(k) && load_tracking_peak(k) <= limit; });
    if (d.kpp_nominal > 0.0) {
      d.j1 = load_bandwidth(d.kpp_nominal).value_or(0.0);
      d.j2 = load_disturbance_peak(d.kpp_nominal);
      d.peak_load_tracking = load_tracking_peak(d.kpp_nominal);
    }
  }
  if (w2_) {
    d.kpp_rs = largest_kpp([&](double k) { return stable(k) && robust_stability_peak(k) < 1.0; });
    d.kpp_rp = largest_kpp([&](double k) { return stable(k) && sufficient_rp_min_margin(k) >= 0.0; });
    d.kpp_rp_exact = largest_kpp([&](double k) { return stable(k) && worst_case_peak(k) <= 1.0 + kPeakSlack; });
  }
  return d;
}

// ------------------------------------------------------------------------- rational forms

PositionClosedLoop position_closed_loop(const ClosedLoopTransfer& velocity, double kpp) {
  if (!velocity.load_tracking || !velocity.motor_from_load_torque || !velocity.load_from_load_torque)
    throw std::invalid_argument("position_closed_loop: the velocity loop has no load side");
  const Polynomial s{1.0, 0.0};
  const Polynomial& delta = velocity.characteristic;
  const Polynomial& nm = velocity.motor_tracking.num();
  const Polynomial& nl = velocity.load_tracking->num();
  const Polynomial& nmd = velocity.motor_from_load_torque->num();
  const Polynomial& nld = velocity.load_from_load_torque->num();
  const Polynomial chi = s * delta + kpp * nm;
  return PositionClosedLoop{chi, TransferFunction(kpp * nm, chi), TransferFunction(kpp * nl, chi),
                            TransferFunction(nld * chi - kpp * (nl * nmd), s * delta * chi)};
}

PositionClosedForm position_closed_form(const FrictionTwoMass& m, const PidGains& g, double kpp) {
  if (g.kd != 0.0) throw std::invalid_argument("position_closed_form: eq. 7.110 is for a PI velocity loop (kd = 0)");
  const double im = 1.0, il = m.load_inertia, k = m.stiffness, b = m.damping, bm = m.motor_viscous,
               bl = m.load_viscous, kp = g.kp, ki = g.ki;
  const double kppkp = g.wp * kpp * kp;  // every Kpp·Kp of the printed a_i carries wp
  const double a5 = il * im;
  const double a4 = bl * im + il * bm + il * kp + il * b + b * im;
  const double a3 = k * im + il * ki + il * kppkp + il * k + bl * b + b * bm + b * kp + bl * bm + bl * kp;
  const double a2 = il * ki * kpp + k * bm + k * kp + bl * k + b * kppkp + ki * b + bl * kppkp + ki * bl;
  const double a1 = ki * kpp * b + ki * k + ki * kpp * bl + k * kppkp;
  const double a0 = ki * k * kpp;
  const Polynomial den{a5, a4, a3, a2, a1, a0};
  return PositionClosedForm{
      TransferFunction(kpp * (Polynomial{b, k} * Polynomial{g.wp * kp, ki}), den),
      TransferFunction(Polynomial{-im, -(b + bm + kp), -(k + kppkp + ki), -ki * kpp}, den)};
}

}  // namespace servotwin::tuning
