// Velocity-loop indices and the J1/J2 choice of ω* (loop_analysis.hpp; catalog C7.8, C7.15; plan
// §1.6, §1.14, §2 E24-qual). References:
//   * tests/data/tuning/loop_reference.json, written by tools/reference/tuning_loop_reference.py:
//     block-diagram frequency functions (numpy, delay exact) on a 200 001-point grid refined by
//     scipy.optimize.minimize_scalar / brentq; time responses by scipy.signal.lsim of the rational
//     closed loop (scipy.interpolate.pade delay) on 400 001 points over 60 time constants;
//   * the printed minimum closed-loop dampings of E24 (its qualitative row, [R]);
//   * closed forms of a PI loop on a rigid 1/s plant (a two-mass plant with r = 1, whose zeros
//     cancel its resonance exactly);
//   * a brute-force ω* scan for choose_omega_star().
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/tuning/loop_analysis.hpp"

namespace servotwin::tuning {
namespace {

using Complex = std::complex<double>;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSqrtHalfValue = std::numbers::sqrt2 / 2.0;

const nlohmann::json& loop_reference() {
  static const nlohmann::json j =
      test_support::read_json_fixture("tuning/loop_reference.json", "tuning_loop_reference.py");
  return j;
}

/// JSON null is the script's +infinity (no crossing).
double value_of(const nlohmann::json& j) { return j.is_null() ? kInf : j.get<double>(); }

NormalizedPlant plant_of(const nlohmann::json& c) {
  NormalizedPlant p = normalized_two_mass(c.at("r").get<double>(), c.at("zeta_z").get<double>());
  if (c.value("tau_f", 0.0) > 0.0) p.hf.feedback_filter_s = c.at("tau_f").get<double>();
  if (c.value("delay", 0.0) > 0.0) p.hf.delay_s = c.at("delay").get<double>();
  return p;
}

PidGains gains_of(const nlohmann::json& c) {
  return {c.at("kp").get<double>(), c.at("ki").get<double>(), c.value("kd", 0.0), c.value("tau", 0.0),
          c.value("wp", 1.0), 0.0};
}

void expect_rel(double got, double want, double tol, const std::string& what) {
  if (std::isinf(want)) {
    EXPECT_EQ(got, want) << what;
    return;
  }
  EXPECT_LE(std::abs(got - want), tol * std::max(std::abs(want), 1e-300)) << what << ": got " << got << " want " << want;
}

// ----------------------------------------------------------------------------- scipy fixture

TEST(LoopAnalysis, MatchesTheScipyReferenceLoops) {
  for (const nlohmann::json& c : loop_reference().at("cases")) {
    const std::string name = c.at("name");
    SCOPED_TRACE(name + ": " + c.at("source").get<std::string>());
    const LoopIndices x = analyse(plant_of(c), gains_of(c));
    ASSERT_TRUE(x.closed_loop_stable);
    // Closed-loop poles: numpy.roots of Δ (Padé delay included).
    const auto got = test::sorted_roots(x.closed_loop_poles);
    std::vector<Complex> want;
    for (const nlohmann::json& p : c.at("poles")) want.push_back(test::root_of(p));
    want = test::sorted_roots(want);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t k = 0; k < got.size(); ++k)
      EXPECT_LT(std::abs(got[k] - want[k]), 1e-7 * std::max(std::abs(want[k]), 1.0)) << got[k] << " vs " << want[k];
    expect_rel(x.min_damping, c.at("min_damping"), 1e-7, "min damping");
    // Frequency indices: grid + refinement on both sides (rel_tol 1e-6 in ω ⇒ ~1e-12 in value).
    expect_rel(x.peak_s, c.at("peak_s"), 1e-8, "‖S‖");
    expect_rel(x.peak_s_omega, c.at("peak_s_omega"), 1e-4, "ω of ‖S‖");
    expect_rel(x.peak_t, c.at("peak_t"), 1e-8, "‖T‖");
    expect_rel(x.peak_tm, c.at("peak_tm"), 1e-8, "‖ωm/ω*‖");
    expect_rel(x.peak_tl, c.at("peak_tl"), 1e-8, "‖ωl/ω*‖");
    expect_rel(x.peak_load_disturbance, c.at("peak_load_disturbance"), 1e-8, "‖ωl/Tl‖");
    expect_rel(x.j2, c.at("j2"), 1e-8, "J2");
    expect_rel(x.modulus_margin, c.at("modulus_margin"), 1e-8, "modulus margin");
    expect_rel(x.bandwidth_motor, c.at("bandwidth_motor"), 1e-8, "motor bandwidth");
    expect_rel(x.bandwidth_load, c.at("bandwidth_load"), 1e-8, "load bandwidth");
    expect_rel(x.gain_margin_db, value_of(c.at("gain_margin_db")), 1e-8, "gain margin");
    expect_rel(x.phase_margin_deg, value_of(c.at("phase_margin_deg")), 1e-8, "phase margin");
    expect_rel(x.hf_controller_gain, c.at("hf_controller_gain"), 1e-12, "|C(j10r)|");
    // Time indices: exact ZOH samples at dt = 0.02/max|p| against lsim at a ~10x finer step.
    EXPECT_NEAR(x.overshoot, c.at("overshoot").get<double>(), 1e-4);
    EXPECT_NEAR(x.overshoot_motor, c.at("overshoot_motor").get<double>(), 1e-4);
    expect_rel(x.settling_time, c.at("settling_time"), 1e-4, "settling time (load)");
    expect_rel(x.settling_time_motor, c.at("settling_time_motor"), 1e-4, "settling time (motor)");
    expect_rel(x.itae_load_step, c.at("itae_load_step"), 1e-4, "ITAE");
    expect_rel(x.peak_torque_step, c.at("peak_torque_step"), 1e-4, "peak torque");
  }
}

TEST(LoopAnalysis, UnstableLoopReportsInfinitiesWithoutThrowing) {
  // The E24 ω* = 2 rigid gains (28.8, 36) on the E26 plant with the delay 0.15: unstable (the script
  // finds max Re of the closed-loop poles = +5.28).
  const nlohmann::json& u = loop_reference().at("unstable");
  const LoopIndices x = analyse(plant_of(u), PidGains{28.8, 36.0});
  EXPECT_FALSE(x.closed_loop_stable);
  double max_re = -kInf;
  for (const Complex& p : x.closed_loop_poles) max_re = std::max(max_re, p.real());
  EXPECT_NEAR(max_re, u.at("max_real").get<double>(), 1e-6);
  EXPECT_TRUE(std::isnan(x.bandwidth_load));
  EXPECT_TRUE(std::isnan(x.phase_margin_deg));
  EXPECT_EQ(x.peak_s, kInf);
  EXPECT_EQ(x.j2, kInf);
  EXPECT_EQ(x.modulus_margin, 0.0);
  EXPECT_EQ(x.itae_load_step, kInf);
  EXPECT_EQ(x.settling_time, kInf);
  EXPECT_DOUBLE_EQ(x.hf_controller_gain, std::abs(Complex(28.8, 0.0) + 36.0 / Complex(0.0, 30.0)));
}

// ----------------------------------------------------------------------------- printed numbers

TEST(LoopAnalysis, E24QualitativeDampings) {
  // Plan §2 row E24-qual [R]: the rigid PI gains of E24 (pole placement ξ* = 0.8 on 1/(9s), and the
  // symmetric optimum) on the two-mass plant Im = 1, Il = 8, b = 0.2, k = 8 (r = 3, ζz = 0.0125)
  // with the τf = 0.01 feedback filter: min closed-loop damping 0.745, 0.487, 0.060, 0.0125 (tol 1e-3).
  NormalizedPlant plant = normalized_two_mass(3.0, 0.0125);
  plant.hf.feedback_filter_s = 0.01;
  struct Row {
    PidGains gains;
    double min_damping;
  };
  for (const Row& row : {Row{{4.32, 0.81}, 0.745}, Row{{8.64, 3.24}, 0.487}, Row{{28.8, 36.0}, 0.060},
                         Row{{450.0, 11250.0}, 0.0125}}) {
    const LoopIndices x = analyse(plant, row.gains);
    EXPECT_TRUE(x.closed_loop_stable) << row.gains.kp;
    EXPECT_NEAR(x.min_damping, row.min_damping, 1e-3) << row.gains.kp;
  }
  // The printed least-damped pairs: ω* = 2 → −0.056 ± 0.928j; SO → −0.012 ± 1.000j (the antiresonance).
  const auto least_damped = [&](const PidGains& g) {
    const LoopIndices x = analyse(plant, g);
    Complex best;
    double z = kInf;
    for (const Complex& p : x.closed_loop_poles)
      if (p.imag() >= 0.0 && -p.real() / std::abs(p) < z) {
        z = -p.real() / std::abs(p);
        best = p;
      }
    return best;
  };
  const Complex p2 = least_damped({28.8, 36.0});
  EXPECT_NEAR(p2.real(), -0.056, 1e-3);
  EXPECT_NEAR(p2.imag(), 0.928, 1e-3);
  const Complex pso = least_damped({450.0, 11250.0});
  EXPECT_NEAR(pso.real(), -0.012, 1e-3);
  EXPECT_NEAR(pso.imag(), 1.000, 1e-3);
}

// ----------------------------------------------------------------------------- closed forms

/// Pm = 1/s: the first mode with r = 1 and ζp = ζz cancels exactly, and so does a "higher mode"
/// whose antiresonance equals its resonance; the higher mode also removes the load side (r = 1 has
/// no two-mass realization), so the indices are the motor's.
/// A plant whose modes cancel exactly, leaving the rigid Pm = 1/(4s): the first mode
/// (s² + s + 1)/(s² + 2s + 4) times a "higher mode" (1/4)(s² + 2s + 4)/(s² + s + 1).
constexpr double kRigidGain = 4.0;  // PI gains are multiplied by it so that L = (kp s + ki)/s²
NormalizedPlant rigid_plant() {
  NormalizedPlant p;
  p.r = 2.0;
  p.zeta_z = 0.5;
  p.zeta_p = 0.5;
  p.higher_modes.push_back(fit::Mode{{2.0, 0.5}, {1.0, 0.5}});
  return p;
}

TEST(LoopAnalysis, RigidPiMatchesClosedForms) {
  // L = (kp s + ki)/s² with kp = 2ζω*, ki = ω*²: |L(jωc)| = 1 at ωc² = (kp² + sqrt(kp⁴ + 4ki²))/2,
  // PM = atan(kp ωc/ki); the phase never reaches −180° for ω > 0 (GM = +inf).
  const double w = 0.7, zeta = 0.5;
  const double kp = 2.0 * zeta * w, ki = w * w;
  const double wc = std::sqrt((kp * kp + std::sqrt(kp * kp * kp * kp + 4.0 * ki * ki)) / 2.0);
  const double pm = std::atan(kp * wc / ki) * 180.0 / std::numbers::pi;
  // wp = 0: ωm/ω* = ω*²/(s² + 2ζω* s + ω*²), the textbook second order: overshoot e^{−πζ/√(1−ζ²)},
  // peak 1/(2ζ√(1−ζ²)), bandwidth at the level λ = 10^(−3/20) (core::bandwidth's −3 dB, not 1/√2):
  // (1 − x)² + 4ζ²x = 1/λ², x = (ω/ω*)², so x = 1 − 2ζ² + sqrt((1 − 2ζ²)² − 1 + 1/λ²); the torque u = s·ωm
  // (plant 1/s) peaks at ω*·exp(−ζ acos ζ/√(1−ζ²)) (maximum of the impulse response).
  const LoopIndices x = analyse(rigid_plant(), PidGains{kRigidGain * kp, kRigidGain * ki, 0.0, 0.0, 0.0, 0.0});
  ASSERT_TRUE(x.closed_loop_stable);
  const double rz = std::sqrt(1.0 - zeta * zeta);
  EXPECT_NEAR(x.gain_crossover, wc, 1e-10 * wc);
  EXPECT_NEAR(x.phase_margin_deg, pm, 1e-8);
  EXPECT_EQ(x.gain_margin_db, kInf);
  EXPECT_NEAR(x.peak_tm, 1.0 / (2.0 * zeta * rz), 1e-10);
  const double inv_level2 = std::pow(10.0, 0.3);
  const double a = 1.0 - 2.0 * zeta * zeta;
  EXPECT_NEAR(x.bandwidth_motor, w * std::sqrt(a + std::sqrt(a * a - 1.0 + inv_level2)), 1e-8 * w);
  EXPECT_NEAR(x.overshoot_motor, std::exp(-std::numbers::pi * zeta / rz), 1e-5);
  EXPECT_NEAR(x.peak_torque_step, kRigidGain * w * std::exp(-zeta * std::acos(zeta) / rz), 1e-5 * kRigidGain);
  // ‖S‖∞ of s²/(s² + kp s + ki): |S|² = x²/((ki − x)² + kp² x), x = ω², is maximal at
  // x = 2ki²/(2ki − kp²) (zero derivative), which is positive for ζ < 1/√2.
  const double xs = 2.0 * ki * ki / (2.0 * ki - kp * kp);
  EXPECT_NEAR(x.peak_s, std::sqrt(xs * xs / ((ki - xs) * (ki - xs) + kp * kp * xs)), 1e-10);
  // 1DoF (wp = 1): the same loop, the same S and margins; T = ωm/ω*.
  const LoopIndices y = analyse(rigid_plant(), PidGains{kRigidGain * kp, kRigidGain * ki});
  EXPECT_NEAR(y.peak_s, x.peak_s, 1e-12);
  EXPECT_NEAR(y.peak_t, y.peak_tm, 1e-12);
  EXPECT_DOUBLE_EQ(y.peak_torque_step, kRigidGain * kp);  // u(0+) = wp kp: the proportional kick
}

TEST(LoopAnalysis, HfGainDefaultsAndOptions) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const PidGains g{4.634937, 0.640260};
  // |C(j·10r)| = |kp + ki/(j30)| (plant overload); |C(j∞)| = kp (loop overload without a frequency).
  EXPECT_DOUBLE_EQ(analyse(plant, g).hf_controller_gain, std::abs(Complex(g.kp, 0.0) + g.ki / Complex(0.0, 30.0)));
  EXPECT_DOUBLE_EQ(analyse(VelocityLoop(plant, g)).hf_controller_gain, g.kp);
  AnalysisOptions bad;
  bad.grid_points = 3;
  test::expect_input_error([&] { (void)analyse(plant, g, bad); }, "grid_points", "at least 16");
  bad = {};
  bad.omega_max = 1e-4;
  test::expect_input_error([&] { (void)analyse(plant, g, bad); }, "omega_max", "grid end");
  bad = {};
  bad.settling_band = 1.5;
  test::expect_input_error([&] { (void)analyse(plant, g, bad); }, "settling_band", "(0, 1)");
}

// ----------------------------------------------------------------------------- J1/J2

TEST(LoopAnalysis, J1AndJ2ScanMatchesScipy) {
  // Fixture "scan": E26 plant, ζ* = 1, J2 and J1 (peak limit 1.3, wp by the script's 201-point
  // grid + boundary brentq) at five ω*. J2 has an interior minimum near ω* = 0.2 (it is not
  // monotone: the weighted open loop peaks at the static compliance 1/r², not at the resonance).
  const nlohmann::json& s = loop_reference().at("scan");
  const NormalizedPlant plant = normalized_two_mass(s.at("r"), s.at("zeta_z"));
  std::vector<double> j1s, j2s;
  for (const nlohmann::json& row : s.at("rows")) {
    const double w = row.at("omega_star");
    const PolePlacement placed = pi_pole_placement(plant.motor(false), w, s.at("zeta_star").get<double>());
    EXPECT_NEAR(placed.gains.kp, row.at("kp").get<double>(), 1e-8);
    const LoopIndices x = analyse(plant, PidGains{placed.gains.kp, placed.gains.ki});
    expect_rel(x.j2, row.at("j2"), 1e-7, "J2 at " + std::to_string(w));
    // J1 through the choice's own wp search on a one-point range is not exposed; check the
    // reported wp's feasibility and bandwidth against the script instead.
    const double wp = row.at("wp");
    const LoopIndices at_wp = analyse(plant, PidGains{placed.gains.kp, placed.gains.ki, 0.0, 0.0, wp, 0.0});
    EXPECT_LE(at_wp.peak_tl, s.at("peak_limit").get<double>() * (1.0 + 1e-8));
    expect_rel(at_wp.bandwidth_load, row.at("j1"), 1e-6, "J1 at " + std::to_string(w));
    j1s.push_back(at_wp.bandwidth_load);
    j2s.push_back(x.j2);
  }
  // Orderings over ω* = 0.1, 0.2, 0.3, 0.45, 0.6: J1 grows (more bandwidth, the peak limit binds
  // only at 0.6 where wp < 1); J2 falls to ω* = 0.2 and rises after it.
  ASSERT_EQ(j1s.size(), 5U);
  for (std::size_t k = 1; k < j1s.size(); ++k) EXPECT_GT(j1s[k], j1s[k - 1]) << k;
  EXPECT_LT(j2s[1], j2s[0]);
  for (std::size_t k = 2; k < j2s.size(); ++k) EXPECT_GT(j2s[k], j2s[k - 1]) << k;
  EXPECT_LT(s.at("rows").at(4).at("wp").get<double>(), 1.0);
}

/// Brute force: J2 and the constrained J1 on a fine ω* grid with wp ∈ {0, 0.02, …, 1}, directly from
/// VelocityLoop with each wp (not through the wp-ratio shortcut of choose_omega_star).
struct Brute {
  double best_j1 = -1.0, omega_j1 = 0.0, best_j2 = kInf, omega_j2 = 0.0;
};

Brute brute_force(const NormalizedPlant& plant, const IndexOptions& o, double lo, double hi, std::size_t n) {
  Brute b;
  AnalysisOptions fast = o.analysis;
  fast.max_samples = 100;  // time indices unused here
  for (const double w : core::log_space(lo, hi, n)) {
    const PiGains g = pi_pole_placement(plant.motor(false), w, o.zeta_star).gains;
    const LoopIndices x = analyse(plant, PidGains{g.kp, g.ki}, fast);
    if (x.j2 < b.best_j2) b = {b.best_j1, b.omega_j1, x.j2, w};
    for (int k = 0; k <= 50; ++k) {
      const VelocityLoop loop(plant, PidGains{g.kp, g.ki, 0.0, 0.0, k / 50.0, 0.0});
      const std::vector<double> grid = core::log_space(1e-3, 1e3, 2000);
      const auto f = [&loop](double om) { return loop.load_tracking(om); };
      if (core::peak_on_grid(f, grid).value > o.peak_limit) continue;
      std::vector<double> g0{0.0};
      g0.insert(g0.end(), grid.begin(), grid.end());
      const auto fdc = [&loop](double om) { return om == 0.0 ? Complex(1.0) : loop.load_tracking(om); };
      const double bw = core::bandwidth(fdc, g0).value();
      if (bw > b.best_j1) {
        b.best_j1 = bw;
        b.omega_j1 = w;
      }
    }
  }
  return b;
}

TEST(LoopAnalysis, ChooseOmegaStarAgreesWithBruteForce) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  IndexOptions o;
  o.zeta_star = 1.0;
  o.peak_limit = 1.3;
  o.omega_star_points = 24;
  const OmegaChoice c = choose_omega_star(plant, o);
  const Brute b = brute_force(plant, o, c.range_min, c.range_max, 60);
  // J2: the golden-section optimum is at least as good as the grid's best and lies within one
  // brute-force grid step of it.
  const double step = std::pow(c.range_max / c.range_min, 1.0 / 59.0);
  EXPECT_LE(c.j2, b.best_j2 * (1.0 + 1e-9));
  EXPECT_GE(c.j2, b.best_j2 * (1.0 - 1e-3));
  EXPECT_LT(std::abs(std::log(c.omega_j2 / b.omega_j2)), std::log(step) * 1.01);
  EXPECT_GT(c.omega_j2, 0.12);  // interior minimum (fixture scan: J2(0.1) > J2(0.2) < J2(0.3))
  EXPECT_LT(c.omega_j2, 0.3);
  // J1: at least the brute-force maximum (coarser in wp and ω*), and reproduced by analyse() at the
  // returned (ω*, wp).
  EXPECT_GE(c.j1, b.best_j1 * (1.0 - 1e-6));
  EXPECT_LT(std::abs(std::log(c.omega_j1 / b.omega_j1)), std::log(step) * 1.01);
  const PiGains g = pi_pole_placement(plant.motor(false), c.omega_j1, o.zeta_star).gains;
  const LoopIndices at = analyse(plant, PidGains{g.kp, g.ki, 0.0, 0.0, c.wp, 0.0});
  EXPECT_LE(at.peak_tl, o.peak_limit * (1.0 + 1e-6));
  EXPECT_NEAR(at.bandwidth_load, c.j1, 1e-6 * c.j1);
  EXPECT_FALSE(c.interval_empty);  // [argmin J2, argmax J1] = [~0.2, ~0.6]
  EXPECT_LT(c.omega_j2, c.omega_j1);
}

TEST(LoopAnalysis, ChooseOmegaStarPidReproducedByAnalyse) {
  // E-PID plant (r = 4, Kd = 4 for r̄ = 2) with ζz = 0.01 and the filter τ = 0.01: the
  // wp shortcut of the J1 search (ωl/ω* scaled by R_wp/R_1, valid for w_d = 0) must agree with a
  // loop built with that wp, and J2 with analyse() of the returned ω*.
  const NormalizedPlant plant = normalized_two_mass(4.0, 0.01);
  IndexOptions o;
  o.zeta_star = kSqrtHalfValue;
  o.kd = 4.0;
  o.tau = 0.01;
  o.omega_star_points = 12;
  const OmegaChoice c = choose_omega_star(plant, o);
  ASSERT_TRUE(std::isfinite(c.omega_j1));
  const auto loop_at = [&](double w, double wp) {
    const PiGains g = pi_pole_placement(plant.motor(false), w, o.zeta_star, o.kd, o.tau).gains;
    return analyse(plant, PidGains{g.kp, g.ki, o.kd, o.tau, wp, 0.0});
  };
  const LoopIndices a1 = loop_at(c.omega_j1, c.wp);
  EXPECT_NEAR(a1.bandwidth_load, c.j1, 1e-6 * c.j1);
  EXPECT_LE(a1.peak_tl, o.peak_limit * (1.0 + 1e-6));
  EXPECT_NEAR(loop_at(c.omega_j2, 1.0).j2, c.j2, 1e-6 * c.j2);
  EXPECT_GE(c.omega_j1, c.range_min);
  EXPECT_LE(c.omega_j1, c.range_max);
}

TEST(LoopAnalysis, ChooseOmegaStarRefusesPlantsWithoutLoadSide) {
  NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  plant.higher_modes.push_back(fit::Mode{{6.0, 0.01}, {12.0, 0.02}});
  test::expect_input_error([&] { (void)choose_omega_star(plant); }, "plant", "J1/J2 need the load velocity");
  IndexOptions o;
  o.peak_limit = 0.0;
  test::expect_input_error([&] { (void)choose_omega_star(normalized_two_mass(3.0, 0.01), o); }, "peak_limit", "> 0");
  o = {};
  o.kd = 1.0;
  test::expect_input_error([&] { (void)choose_omega_star(normalized_two_mass(3.0, 0.01), o); }, "tau", "tau > 0");
}

}  // namespace
}  // namespace servotwin::tuning
