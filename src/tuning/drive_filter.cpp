#include "servotwin/tuning/drive_filter.hpp"

#include <array>
#include <cmath>
#include <complex>
#include <fmt/format.h>
#include <numbers>
#include <stdexcept>

#include "servotwin/core/error.hpp"

namespace servotwin::tuning {

namespace {

using core::Polynomial;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kMaxDepthDb = 200.0;
constexpr double kMaxDamping = 10.0;

void require(bool ok, const std::string& field, const std::string& message) {
  if (!ok) throw core::InputError(core::at_field(field), message);
}

void require_frequency(double f, const char* what, std::optional<double> ts, const std::string& field) {
  require(std::isfinite(f) && f > 0.0, field, fmt::format("expected a {} > 0 Hz, got {}", what, f));
  if (ts) {
    const double nyquist = 0.5 / *ts;
    require(f < nyquist, field,
            fmt::format("the {} {:g} Hz is not below the Nyquist frequency {:g} Hz of --ts {:g} s: a drive "
                        "sampling at that period cannot realize it",
                        what, f, nyquist, *ts));
  }
}

void require_damping(double z, const char* what, bool zero_allowed, const std::string& field) {
  require(std::isfinite(z) && (zero_allowed ? z >= 0.0 : z > 0.0) && z <= kMaxDamping, field,
          fmt::format("expected a {} in {}0, {}], got {}", what, zero_allowed ? "[" : "(", kMaxDamping, z));
}

/// s² + 2 ζ ω s + ω².
Polynomial quadratic(double omega, double zeta) { return Polynomial{1.0, 2.0 * zeta * omega, omega * omega}; }

}  // namespace

std::string to_string(DriveFilterType type) {
  switch (type) {
    case DriveFilterType::kNotch:
      return "notch";
    case DriveFilterType::kLowpass:
      return "lowpass";
    case DriveFilterType::kBiquad:
      return "biquad";
  }
  return "notch";
}

void validate(const DriveFilterSpec& s, std::optional<double> ts, const std::string& field) {
  if (ts) require(std::isfinite(*ts) && *ts > 0.0, "--ts", fmt::format("expected a sample period > 0 s, got {}", *ts));
  switch (s.type) {
    case DriveFilterType::kNotch:
      require_frequency(s.frequency_hz, "notch centre", ts, field);
      require(std::isfinite(s.width_hz) && s.width_hz > 0.0 && s.width_hz <= 4.0 * s.frequency_hz, field,
              fmt::format("expected a notch width in (0, 4 x centre] = (0, {:g}] Hz, got {}", 4.0 * s.frequency_hz,
                          s.width_hz));
      require(std::isfinite(s.depth_db) && s.depth_db >= 0.0 && s.depth_db <= kMaxDepthDb, field,
              fmt::format("expected a notch depth in [0, {:g}] dB (the attenuation at the centre; a negative depth "
                          "would be a peak), got {}",
                          kMaxDepthDb, s.depth_db));
      return;
    case DriveFilterType::kLowpass:
      require_frequency(s.frequency_hz, "low-pass corner", ts, field);
      if (s.damping) require_damping(*s.damping, "low-pass damping", false, field);
      return;
    case DriveFilterType::kBiquad:
      require_frequency(s.frequency_hz, "biquad numerator frequency", ts, field);
      require_frequency(s.pole_frequency_hz, "biquad denominator frequency", ts, field);
      require(s.damping.has_value(), field, "a biquad needs its numerator damping");
      require_damping(*s.damping, "biquad numerator damping", true, field);
      require_damping(s.pole_damping, "biquad denominator damping", false, field);
      return;
  }
}

core::TransferFunction continuous_filter(const DriveFilterSpec& s) {
  validate(s, std::nullopt);
  const double w = kTwoPi * s.frequency_hz;
  switch (s.type) {
    case DriveFilterType::kNotch: {
      const double zeta_p = s.width_hz / (2.0 * s.frequency_hz);
      const double zeta_z = zeta_p * std::pow(10.0, -s.depth_db / 20.0);
      return {quadratic(w, zeta_z), quadratic(w, zeta_p)};
    }
    case DriveFilterType::kLowpass:
      if (!s.damping) return {Polynomial{w}, Polynomial{1.0, w}};
      return {Polynomial{w * w}, quadratic(w, *s.damping)};
    case DriveFilterType::kBiquad: {
      const double wp = kTwoPi * s.pole_frequency_hz;
      return {(wp * wp / (w * w)) * quadratic(w, *s.damping), quadratic(wp, s.pole_damping)};
    }
  }
  throw std::invalid_argument("continuous_filter: unknown filter type");
}

double prewarp_frequency(const DriveFilterSpec& s) {
  if (s.type == DriveFilterType::kBiquad && s.pole_damping < s.damping.value_or(0.0))
    return kTwoPi * s.pole_frequency_hz;
  return kTwoPi * s.frequency_hz;
}

DiscreteBiquad tustin_biquad(const core::TransferFunction& filter, double ts, double prewarp_rad_s) {
  require(std::isfinite(ts) && ts > 0.0, "ts", fmt::format("expected a sample period > 0 s, got {}", ts));
  require(std::isfinite(prewarp_rad_s) && prewarp_rad_s > 0.0 && prewarp_rad_s * ts < std::numbers::pi, "ts",
          fmt::format("the prewarp frequency {:g} Hz must lie below the Nyquist frequency {:g} Hz",
                      prewarp_rad_s / kTwoPi, 0.5 / ts));
  const int order = filter.den().degree();
  if (order < 1 || order > 2 || filter.num().degree() > order)
    throw std::invalid_argument("tustin_biquad: expected a proper filter of order 1 or 2");
  // s = K (z − 1)/(z + 1); multiplying through by (z + 1)^order gives polynomials in z.
  const double k = prewarp_rad_s / std::tan(0.5 * prewarp_rad_s * ts);
  const auto map = [&](const Polynomial& p) -> std::array<double, 3> {
    const double c2 = order == 2 ? p.coefficient_of_power(2) : 0.0, c1 = p.coefficient_of_power(1),
                 c0 = p.coefficient_of_power(0);
    if (order == 1) return {c1 * k + c0, c0 - c1 * k, 0.0};
    return {c2 * k * k + c1 * k + c0, 2.0 * (c0 - c2 * k * k), c2 * k * k - c1 * k + c0};
  };
  const std::array<double, 3> b = map(filter.num()), a = map(filter.den());
  DiscreteBiquad q;
  q.b0 = b[0] / a[0];
  q.b1 = b[1] / a[0];
  q.b2 = b[2] / a[0];
  q.a1 = a[1] / a[0];
  q.a2 = a[2] / a[0];
  q.ts = ts;
  q.prewarp_hz = prewarp_rad_s / kTwoPi;
  return q;
}

DriveFilter make_drive_filter(const DriveFilterSpec& spec, std::optional<double> ts, const std::string& field) {
  validate(spec, ts, field);
  DriveFilter f{spec, continuous_filter(spec), std::nullopt, {}};
  if (ts) f.discrete = tustin_biquad(f.continuous, *ts, prewarp_frequency(spec));
  return f;
}

core::TransferFunction filter_chain(const std::vector<DriveFilter>& filters) {
  Polynomial num{1.0}, den{1.0};
  for (const DriveFilter& f : filters) {
    num = num * f.continuous.num();
    den = den * f.continuous.den();
  }
  return {num, den};
}

core::DiscreteStateSpace discrete_chain(const std::vector<DriveFilter>& filters, double ts) {
  // Each biquad in controllable canonical form; the chain is their series (the algebra of a
  // discrete series equals the continuous one's).
  std::optional<core::StateSpace> chain;
  for (const DriveFilter& f : filters) {
    if (!f.discrete || std::abs(f.discrete->ts - ts) > 1e-12 * ts)
      throw std::invalid_argument("discrete_chain: a filter without its discrete form at this period");
    const DiscreteBiquad& q = *f.discrete;
    const bool second = q.a2 != 0.0 || q.b2 != 0.0;
    core::StateSpace b;
    if (second) {
      b.A.resize(2, 2);
      b.A << -q.a1, -q.a2, 1.0, 0.0;
      b.B.resize(2, 1);
      b.B << 1.0, 0.0;
      b.C.resize(1, 2);
      b.C << q.b1 - q.a1 * q.b0, q.b2 - q.a2 * q.b0;
    } else {
      b.A = Eigen::MatrixXd::Constant(1, 1, -q.a1);
      b.B = Eigen::MatrixXd::Constant(1, 1, 1.0);
      b.C = Eigen::MatrixXd::Constant(1, 1, q.b1 - q.a1 * q.b0);
    }
    b.D = Eigen::MatrixXd::Constant(1, 1, q.b0);
    chain = chain ? core::series(*chain, b) : b;
  }
  if (!chain) return {Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Constant(1, 1, 1.0), ts};
  return {chain->A, chain->B, chain->C, chain->D, ts};
}

std::complex<double> response(const DiscreteBiquad& q, double omega_rad_s) noexcept {
  const std::complex<double> zi = std::polar(1.0, -omega_rad_s * q.ts);  // z⁻¹
  return (q.b0 + zi * (q.b1 + zi * q.b2)) / (1.0 + zi * (q.a1 + zi * q.a2));
}

}  // namespace servotwin::tuning
