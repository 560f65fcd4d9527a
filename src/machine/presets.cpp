#include "servotwin/machine/presets.hpp"

#include <cmath>
#include <complex>

#include "servotwin/core/error.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/machine/rigid_axis.hpp"

namespace servotwin::machine {

namespace {

// Fadal VMC 2216 virtual axes. The thesis gives only the closed-loop coefficients, so the plant is
// chosen as a 100 kg table driven with K = 100 N/V (units N s^2/mm and N/V, K/J = 1000 1/(V s^2)
// in mm) and every remaining parameter is solved exactly from the printed "actual" columns.
constexpr double kInertia = 0.1;  // [N s^2/mm] = 100 kg
constexpr double kGain = 100.0;   // [N/V]

// Table 3.4, PID (no feedforward): a1 = (B + K kd)/J, a2 = K kp/J, a3 = K ki/J, b1 = K kd/J.
struct PidColumn {
  double a1, a2, a3, b1, d0, d1;
};
constexpr PidColumn kPidX{192.65, 44356.23, 316830.21, 190.10, 441.0, -302.0};
constexpr PidColumn kPidY{178.75, 41031.98, 293085.57, 175.85, 409.0, -388.0};

// Table 3.3, P-PI (no feedforward): a1 = (B + K kv)/J, a2 = K (kv kp + ki)/J, a3 = K ki kp/J,
// b2 = K kv kp/J.
struct PPiColumn {
  double a1, a2, a3, b2, d0, d1;
};
constexpr PPiColumn kPPiX{372.76, 62009.83, 1527104.87, 11106.33, 441.0, -302.0};
constexpr PPiColumn kPPiY{372.76, 61999.31, 1527104.86, 11095.82, 409.0, -388.0};

// Table 3.5, sliding mode: a1..a3 (b0 = 1, b1 = a1, b2 = a2 follow from the law). The plant
// damping is the PID table's B/J = a1 - b1 (same machine). The OCR of Y's a3 reads
// "4 5861711.35"; the printed poles (31.83 Hz and 27.25 Hz / 0.86) confirm 5861711.35.
struct SmcColumn {
  double a1, a2, a3, damping_over_inertia, d0, d1;
};
constexpr SmcColumn kSmcX{390.10, 57029.44, 3801962.50, 192.65 - 190.10, 441.0, -302.0};
constexpr SmcColumn kSmcY{493.09, 87925.67, 5861711.35, 178.75 - 175.85, 409.0, -388.0};

Nonlinearities fadal_nonlinearities(double d0, double d1) {
  Nonlinearities n;
  n.friction.coulomb_pos = d0 * kInertia;  // Eq. 3.3: d0 = F+/J
  n.friction.coulomb_neg = d1 * kInertia;
  n.u_max = 10.0;
  n.dac_bits = 16;
  n.dac_range = 10.0;
  n.encoder_resolution = 0.001;  // 1 um
  n.encoder_noise_std = 0.0;     // quantization is the only measurement noise by default
  n.delay_samples = 0;
  return n;
}

AxisConfig fadal_axis(const char* name, const Controller& controller, double damping, double d0, double d1) {
  AxisConfig a;
  a.name = name;
  a.plant = {kInertia, damping, kGain};
  a.controller = controller;
  a.nonlinear = fadal_nonlinearities(d0, d1);
  return a;
}

AxisConfig pid_axis(const char* name, const PidColumn& t) {
  PidController c;
  c.kd = t.b1 * kInertia / kGain;
  c.kp = t.a2 * kInertia / kGain;
  c.ki = t.a3 * kInertia / kGain;
  return fadal_axis(name, c, (t.a1 - t.b1) * kInertia, t.d0, t.d1);
}

AxisConfig ppi_axis(const char* name, const PPiColumn& t) {
  PPiController c;
  const double ki_kj = t.a2 - t.b2;    // K ki / J
  c.kp = t.a3 / ki_kj;                 // a3 / (K ki / J)
  const double kv_kj = t.b2 / c.kp;    // K kv / J
  c.kv = kv_kj * kInertia / kGain;
  c.ki = ki_kj * kInertia / kGain;
  return fadal_axis(name, c, (t.a1 - kv_kj) * kInertia, t.d0, t.d1);
}

// The real root -lambda of s^3 + a1 s^2 + a2 s + a3, polished by Newton's method.
double real_root_magnitude(double a1, double a2, double a3) {
  const core::Polynomial p{1.0, a1, a2, a3};
  double best = 0.0, best_imag = std::numeric_limits<double>::infinity();
  for (const auto& r : p.roots()) {
    if (std::abs(r.imag()) < best_imag) {
      best_imag = std::abs(r.imag());
      best = r.real();
    }
  }
  for (int i = 0; i < 4; ++i) best -= p(best) / p.derivative()(best);
  return -best;
}

AxisConfig smc_axis(const char* name, const SmcColumn& t) {
  // (s + lambda)(s^2 + alpha s + beta) with alpha = (B + K ks)/J, beta = K rho/J.
  SlidingModeController c;
  c.lambda = real_root_magnitude(t.a1, t.a2, t.a3);
  const double alpha = t.a1 - c.lambda;
  const double beta = t.a3 / c.lambda;
  c.ks = (alpha - t.damping_over_inertia) * kInertia / kGain;
  c.rho = beta * kInertia / kGain;
  return fadal_axis(name, c, t.damping_over_inertia * kInertia, t.d0, t.d1);
}

MachineConfig fadal(const char* name, const char* description, AxisConfig x, AxisConfig y) {
  MachineConfig m;
  m.name = name;
  m.description = description;
  m.ts = 0.001;
  m.cnc.accel = 2000.0;
  m.cnc.jerk.reset();
  m.cnc.rapid_feed_mm_min = 12000.0;
  // Each block its own trapezoid/triangle ("trapezoidal and triangular velocity transitions",
  // thesis 3.3): the Table 3.2 program then lasts ~21 s, the thesis captured 22 s.
  m.cnc.exact_stop_every_block = true;
  m.axes = {std::move(x), std::move(y)};
  return m;
}

// Ball-screw drive of thesis section 3.4.2 / Table 4.2.
constexpr double kBallscrewZero = -0.99937;  // closed-loop zero z1 (Table 4.2), ts = 1 ms
constexpr double kBallscrewTs = 0.001;

// B/J such that the zero of the zero-order-hold model of K/(s (J s + B)) lies at z1:
// zero(a) = -(phi1^2 - e phi2)/phi2 rises monotonically from -1 (a = 0) towards 0.
double damping_ratio_for_zero(double z1, double ts) {
  auto zero = [ts](double a) {
    const double e = std::exp(-a * ts);
    const double p1 = RigidAxisDynamics::phi1(a, ts);
    const double p2 = RigidAxisDynamics::phi2(a, ts);
    return -(p1 * p1 - e * p2) / p2;
  };
  double lo = 0.0, hi = 1.0 / ts;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (zero(mid) < z1 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

AxisConfig ballscrew_axis(const char* name) {
  AxisConfig a;
  a.name = name;
  a.plant.inertia = kInertia;
  a.plant.gain = kGain;
  a.plant.damping = damping_ratio_for_zero(kBallscrewZero, kBallscrewTs) * kInertia;
  PolePlacementController c;
  c.wn_hz = 30.0;
  c.zeta = 0.7;
  c.zpetc = true;
  a.controller = c;
  // Friction as the identified Table 4.2 levels (LM 1032.57 / -996.03, GA 1024.55 / -987.61).
  a.nonlinear.friction.coulomb_pos = 1030.0 * kInertia;
  a.nonlinear.friction.coulomb_neg = -1000.0 * kInertia;
  a.nonlinear.u_max = 10.0;
  a.nonlinear.dac_bits = 16;
  a.nonlinear.dac_range = 10.0;
  a.nonlinear.encoder_resolution = 0.00125;  // 1.25 um of table motion (thesis)
  a.nonlinear.encoder_noise_std = 0.0;
  return a;
}

}  // namespace

std::vector<std::string> preset_names() { return {"fadal-ppi", "fadal-pid", "fadal-smc", "ballscrew-zpetc"}; }

MachineConfig preset(std::string_view name) {
  if (name == "fadal-ppi")
    return fadal("fadal-ppi",
                 "Fadal VMC 2216 virtual X/Y axes, P-PI cascade without feedforward; closed loop = thesis Table 3.3 "
                 "'actual' (J = 0.1 N s^2/mm, K = 100 N/V chosen, gains and B solved from the table)",
                 ppi_axis("x", kPPiX), ppi_axis("y", kPPiY));
  if (name == "fadal-pid")
    return fadal("fadal-pid",
                 "Fadal VMC 2216 virtual X/Y axes, PID without feedforward; closed loop = thesis Table 3.4 'actual' "
                 "(J = 0.1 N s^2/mm, K = 100 N/V chosen, gains and B solved from the table)",
                 pid_axis("x", kPidX), pid_axis("y", kPidY));
  if (name == "fadal-smc")
    return fadal("fadal-smc",
                 "Fadal VMC 2216 virtual X/Y axes, adaptive sliding-mode control (full feedforward, disturbance "
                 "adaptation); closed loop = thesis Table 3.5 'actual' (plant B/J from Table 3.4)",
                 smc_axis("x", kSmcX), smc_axis("y", kSmcY));
  if (name == "ballscrew-zpetc") {
    MachineConfig m;
    m.name = "ballscrew-zpetc";
    m.description =
        "Ball-screw drive of thesis section 3.4.2: pole placement at 30 Hz / 0.7 with Kalman disturbance observer and "
        "ZPETC (preview 2), ts = 1 ms; B/J from the closed-loop zero z1 = -0.99937, K/J = 1000 chosen; x and y are "
        "identical copies of the single drive so XY contours can run";
    m.ts = kBallscrewTs;
    m.cnc.accel = 2000.0;
    m.cnc.jerk.reset();
    m.cnc.rapid_feed_mm_min = 12000.0;
    m.axes = {ballscrew_axis("x"), ballscrew_axis("y")};
    return m;
  }
  std::string names;
  for (const auto& n : preset_names()) names += (names.empty() ? "" : ", ") + n;
  throw core::InputError(core::SourceLocation{"", 0, 0, "preset"},
                         "unknown machine preset '" + std::string(name) + "' (known: " + names + ")");
}

}  // namespace servotwin::machine
