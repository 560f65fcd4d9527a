// controller.json (io/controller_json.hpp): round trips of PI, PID and PI+P controllers, the
// written state spaces against the controller formula, and the reader's error messages.
//
// References: the physical gains of the test controllers are de-normalized here with the rules of
// catalog §0 (Kp = Kp_n·Im·ωz, Ki = Ki_n·Im·ωz², Kd = Kd_n·Im, τ = τ_n/ωz, Kpp = Kpp_n·ωz), not
// with tuning::to_physical; the written continuous state space is checked against the 2-DoF law
// u = (wp kp + ki/s + wd kd s/(τs+1)) ω* − (kp + ki/s + kd s/(τs+1)) ωm evaluated directly, and
// the discrete one against the same law at the Tustin image s = j (2/T) tan(ωT/2) of z = e^{jωT}
// (with prewarping at ωp: s = j ωp tan(ωT/2)/tan(ωp T/2)). The round trip's reference is the
// written controller itself.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/io/controller_json.hpp"
#include "servotwin/tuning/tune.hpp"

namespace servotwin::io {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace controller_json_test {

using tuning::Controller;
using tuning::PidGains;
using tuning::Structure;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kTs = 1.0 / 8000.0;  // a drive's velocity-loop period

/// A plant like the docs' motor bench: antiresonance 53 Hz, Im = 4.9e-3 kg·m².
tuning::PlantScales bench_plant() {
  tuning::PlantScales p;
  p.omega_z = kTwoPi * 52.993;
  p.motor_inertia = 0.0049256;
  p.r = 1.4308;
  p.zeta_z = 0.0205;
  p.zeta_p = 0.0274;
  p.a = 0.0031;
  return p;
}

/// Catalog §0 de-normalization, written out independently of tuning::to_physical.
PidGains denormalize(const PidGains& n, const tuning::PlantScales& p) {
  const double im = p.motor_inertia, wz = p.omega_z;
  return {n.kp * im * wz, n.ki * im * wz * wz, n.kd * im, n.tau / wz, n.wp, n.wd};
}

tuning::LoopIndices indices(bool infinite_margins) {
  tuning::LoopIndices i;
  i.closed_loop_stable = true;
  i.bandwidth_motor = 0.83;
  i.bandwidth_load = infinite_margins ? kNan : 0.61;  // NaN: no load side
  i.peak_s = 1.42;
  i.peak_s_omega = 1.7;
  i.peak_t = 1.13;
  i.peak_tm = 1.21;
  i.peak_tl = infinite_margins ? kNan : 1.07;
  i.peak_load_disturbance = infinite_margins ? kNan : 3.3;
  i.j2 = 0.47;
  i.gain_margin_db = infinite_margins ? kInf : 11.7;  // +inf: the phase never crosses −180°
  i.phase_crossover = infinite_margins ? kInf : 4.2;
  i.phase_margin_deg = 52.3;
  i.gain_crossover = 0.95;
  i.modulus_margin = 1.0 / 1.42;
  i.overshoot = 0.043;
  i.settling_time = 9.1;
  i.overshoot_motor = 0.12;
  i.settling_time_motor = infinite_margins ? kInf : 7.4;  // +inf: not settled within the horizon
  i.itae_load_step = 41.5;
  i.peak_torque_step = 1.9;
  i.hf_controller_gain = 2.6;
  i.min_damping = 0.53;
  i.sample_time = 0.01;
  i.horizon = 60.0;
  i.closed_loop_poles = {{-0.4, 0.3}, {-0.4, -0.3}, {-1.1, 0.0}};
  return i;
}

Controller make_controller(Structure structure, bool discrete, bool infinite_margins,
                           std::optional<double> prewarp_hz = std::nullopt) {
  Controller c;
  c.structure = structure;
  c.plant = bench_plant();
  c.normalized =
      structure == Structure::kPid ? PidGains{5.2, 1.3, 1.047, 0.1, 0.7, 0.0} : PidGains{1.6, 0.4, 0.0, 0.0, 0.9, 0.0};
  c.physical = denormalize(c.normalized, c.plant);
  if (structure == Structure::kPiP) {
    c.kpp_normalized = 0.25;
    c.kpp_physical = 0.25 * c.plant.omega_z;
    tuning::PositionSummary p;
    p.kpp_nominal = 0.25;
    p.kpp_rs = 2.6;  // kpp_rp_exact left unevaluated (null)
    p.bandwidth_load = 0.43;
    p.j2 = 1.1;
    p.peak_load_tracking = 1.0;
    c.position = p;
  }
  c.design.omega_star = 0.5;
  c.design.zeta_star = 0.8;
  if (structure == Structure::kPid) c.design.r_target = 2.0;
  c.design.ms = 1.5;
  if (structure == Structure::kPi) c.design.min_damping = 0.15;
  c.design.omega_star_source = "J1 (load bandwidth)";
  c.predicted = indices(infinite_margins);
  c.robustness.rs = 0.62;
  c.robustness.np = infinite_margins ? std::optional<double>(kInf) : std::nullopt;
  if (discrete) {
    if (prewarp_hz) c.prewarp_rad_s = kTwoPi * *prewarp_hz;
    c.discrete = tuning::discretize_controller(c.physical, kTs, c.prewarp_rad_s);
  }
  c.notes = {"r = 1.43 < sqrt(3): the second pair cannot be damped to 0.707 by a PI"};
  return c;
}

/// Same value, NaN equal to NaN.
void expect_same(double a, double b, const char* what) {
  if (std::isnan(b)) {
    EXPECT_TRUE(std::isnan(a)) << what;
  } else {
    EXPECT_EQ(a, b) << what;
  }
}

void expect_round_trip(const Controller& c, const Controller& b) {
  EXPECT_EQ(b.structure, c.structure);
  for (const auto& [x, y] : {std::pair{b.physical, c.physical}, std::pair{b.normalized, c.normalized}}) {
    // Shortest round-trip formatting: the gains come back bit for bit.
    EXPECT_EQ(x.kp, y.kp);
    EXPECT_EQ(x.ki, y.ki);
    EXPECT_EQ(x.kd, y.kd);
    EXPECT_EQ(x.tau, y.tau);
    EXPECT_EQ(x.wp, y.wp);
    EXPECT_EQ(x.wd, y.wd);
  }
  EXPECT_EQ(b.kpp_physical, c.kpp_physical);
  EXPECT_EQ(b.kpp_normalized, c.kpp_normalized);
  ASSERT_EQ(b.position.has_value(), c.position.has_value());
  if (c.position) {
    EXPECT_EQ(b.position->kpp_nominal, c.position->kpp_nominal);
    EXPECT_EQ(b.position->kpp_rs, c.position->kpp_rs);
    EXPECT_EQ(b.position->kpp_rp_exact, c.position->kpp_rp_exact);
    EXPECT_EQ(b.position->bandwidth_load, c.position->bandwidth_load);
    EXPECT_EQ(b.position->j2, c.position->j2);
    EXPECT_EQ(b.position->peak_load_tracking, c.position->peak_load_tracking);
  }
  // ωz is stored in Hz: one rounding each way.
  EXPECT_NEAR(b.plant.omega_z, c.plant.omega_z, 4e-16 * c.plant.omega_z);
  EXPECT_EQ(b.plant.motor_inertia, c.plant.motor_inertia);
  EXPECT_EQ(b.plant.r, c.plant.r);
  EXPECT_EQ(b.plant.zeta_z, c.plant.zeta_z);
  EXPECT_EQ(b.plant.zeta_p, c.plant.zeta_p);
  EXPECT_EQ(b.plant.a, c.plant.a);
  EXPECT_EQ(b.design.omega_star, c.design.omega_star);
  EXPECT_EQ(b.design.zeta_star, c.design.zeta_star);
  EXPECT_EQ(b.design.r_target, c.design.r_target);
  EXPECT_EQ(b.design.ms, c.design.ms);
  EXPECT_EQ(b.design.mt, c.design.mt);
  EXPECT_EQ(b.design.min_damping, c.design.min_damping);
  EXPECT_EQ(b.design.omega_star_source, c.design.omega_star_source);
  const tuning::LoopIndices &p = b.predicted, &q = c.predicted;
  EXPECT_EQ(p.closed_loop_stable, q.closed_loop_stable);
  expect_same(p.bandwidth_motor, q.bandwidth_motor, "bandwidth_motor");
  expect_same(p.bandwidth_load, q.bandwidth_load, "bandwidth_load");
  expect_same(p.peak_s, q.peak_s, "peak_s");
  expect_same(p.peak_s_omega, q.peak_s_omega, "peak_s_omega");
  expect_same(p.peak_t, q.peak_t, "peak_t");
  expect_same(p.peak_tm, q.peak_tm, "peak_tm");
  expect_same(p.peak_tl, q.peak_tl, "peak_tl");
  expect_same(p.peak_load_disturbance, q.peak_load_disturbance, "peak_load_disturbance");
  expect_same(p.j2, q.j2, "j2");
  expect_same(p.gain_margin_db, q.gain_margin_db, "gain_margin_db");
  expect_same(p.phase_crossover, q.phase_crossover, "phase_crossover");
  expect_same(p.gain_crossover, q.gain_crossover, "gain_crossover");
  expect_same(p.phase_margin_deg, q.phase_margin_deg, "phase_margin_deg");
  expect_same(p.modulus_margin, q.modulus_margin, "modulus_margin");
  expect_same(p.overshoot, q.overshoot, "overshoot");
  expect_same(p.settling_time, q.settling_time, "settling_time");
  expect_same(p.overshoot_motor, q.overshoot_motor, "overshoot_motor");
  expect_same(p.settling_time_motor, q.settling_time_motor, "settling_time_motor");
  expect_same(p.min_damping, q.min_damping, "min_damping");
  expect_same(p.sample_time, q.sample_time, "sample_time");
  expect_same(p.horizon, q.horizon, "horizon");
  expect_same(p.itae_load_step, q.itae_load_step, "itae_load_step");
  expect_same(p.peak_torque_step, q.peak_torque_step, "peak_torque_step");
  expect_same(p.hf_controller_gain, q.hf_controller_gain, "hf_controller_gain");
  EXPECT_EQ(p.closed_loop_poles, q.closed_loop_poles);
  EXPECT_EQ(b.robustness.rs, c.robustness.rs);
  EXPECT_EQ(b.robustness.np, c.robustness.np);
  EXPECT_EQ(b.robustness.rp, c.robustness.rp);
  EXPECT_EQ(b.robustness.rp_tracking, c.robustness.rp_tracking);
  ASSERT_EQ(b.full_order.has_value(), c.full_order.has_value());
  if (c.full_order) {
    const tuning::FullOrderSummary &f = *b.full_order, &g = *c.full_order;
    EXPECT_EQ(f.weights.kbw, g.weights.kbw);
    EXPECT_EQ(f.weights.feedforward, g.weights.feedforward);
    EXPECT_EQ(f.weights.q_load_velocity, g.weights.q_load_velocity);
    EXPECT_EQ(f.weights.q_integral, g.weights.q_integral);
    EXPECT_EQ(f.weights.noise_motor, g.weights.noise_motor);
    EXPECT_EQ(f.weights.noise_load_torque, g.weights.noise_load_torque);
    EXPECT_EQ(f.weights.measurement_noise, g.weights.measurement_noise);
    EXPECT_EQ(f.weights.raw_motor_velocity, g.weights.raw_motor_velocity);
    EXPECT_EQ(f.kbw_source, g.kbw_source);
    EXPECT_EQ(f.feedforward_source, g.feedforward_source);
    EXPECT_EQ(f.compensator.A, g.compensator.A);
    EXPECT_EQ(f.compensator.B, g.compensator.B);
    EXPECT_EQ(f.compensator.C, g.compensator.C);
    EXPECT_EQ(f.compensator.D, g.compensator.D);
    EXPECT_EQ(f.controller_poles, g.controller_poles);
    EXPECT_EQ(f.controller_stable, g.controller_stable);
    ASSERT_EQ(f.hinf.has_value(), g.hinf.has_value());
    if (g.hinf) {
      EXPECT_EQ(f.hinf->omega_0s, g.hinf->omega_0s);
      EXPECT_EQ(f.hinf->omega_0t, g.hinf->omega_0t);
      EXPECT_EQ(f.hinf->xi_v, g.hinf->xi_v);
      EXPECT_EQ(f.hinf->gamma_optimal, g.hinf->gamma_optimal);
      EXPECT_EQ(f.hinf->gamma, g.hinf->gamma);
      EXPECT_EQ(f.hinf->omega_0s_source, g.hinf->omega_0s_source);
      EXPECT_EQ(f.hinf->modes, g.hinf->modes);
      EXPECT_EQ(f.hinf->full_order, g.hinf->full_order);
      EXPECT_EQ(f.hinf->hankel, g.hinf->hankel);
      EXPECT_EQ(f.hinf->reduction_error_bound, g.hinf->reduction_error_bound);
    }
  }
  ASSERT_EQ(b.discrete.has_value(), c.discrete.has_value());
  if (c.discrete) {
    EXPECT_EQ(b.discrete->ts, c.discrete->ts);
    EXPECT_EQ(b.discrete->A, c.discrete->A);
    EXPECT_EQ(b.discrete->B, c.discrete->B);
    EXPECT_EQ(b.discrete->C, c.discrete->C);
    EXPECT_EQ(b.discrete->D, c.discrete->D);
  }
  ASSERT_EQ(b.prewarp_rad_s.has_value(), c.prewarp_rad_s.has_value());
  if (c.prewarp_rad_s) {
    EXPECT_NEAR(*b.prewarp_rad_s, *c.prewarp_rad_s, 4e-16 * *c.prewarp_rad_s);
  }
  EXPECT_EQ(b.notes, c.notes);
}

TEST(ControllerJsonRoundTrip, PiPidAndPiPWithAndWithoutDiscretePart) {
  for (Structure s : {Structure::kPi, Structure::kPid, Structure::kPiP}) {
    for (bool discrete : {false, true}) {
      for (bool infinite : {false, true}) {
        SCOPED_TRACE(tuning::to_string(s) + (discrete ? " discrete" : "") + (infinite ? " inf" : ""));
        const Controller c =
            make_controller(s, discrete, infinite, infinite ? std::optional<double>(400.0) : std::nullopt);
        const nlohmann::json j = controller_to_json(c, "bench_plant_model.json");
        const LoadedController back = parse_controller_json(j.dump(2), "c.json");
        EXPECT_EQ(back.plant_source, "bench_plant_model.json");
        expect_round_trip(c, back.controller);
      }
    }
  }
}

TEST(ControllerJsonRoundTrip, DocumentShape) {
  const Controller c = make_controller(Structure::kPiP, true, true, 400.0);
  const nlohmann::json j = controller_to_json(c, "m.json");
  EXPECT_EQ(j["format"], "servotwin.controller/1");
  EXPECT_EQ(j["structure"], "pi+p");
  EXPECT_EQ(j["loop"], "position");
  EXPECT_EQ(j["feedback"], "motor");
  EXPECT_DOUBLE_EQ(j["plant"]["omega_z_hz"].get<double>(), 52.993);
  EXPECT_DOUBLE_EQ(j["gains"]["kpp"].get<double>(), 0.25 * kTwoPi * 52.993);
  EXPECT_EQ(j["normalized"]["kpp"], 0.25);
  EXPECT_EQ(j["state_space"]["inputs"], nlohmann::json({"velocity_reference", "motor_velocity"}));
  EXPECT_EQ(j["discrete"]["method"], "tustin");
  EXPECT_DOUBLE_EQ(j["discrete"]["prewarp_hz"].get<double>(), 400.0);
  EXPECT_DOUBLE_EQ(j["design"]["omega_star_hz"].get<double>(), 0.5 * 52.993);
  EXPECT_TRUE(j["design"]["mt"].is_null());
  // Documented encodings: +infinity as "inf", NaN (undefined) as null, not evaluated as null.
  EXPECT_EQ(j["predicted"]["gain_margin_db"], "inf");
  EXPECT_EQ(j["predicted"]["phase_crossover"], "inf");
  EXPECT_EQ(j["predicted"]["phase_crossover_hz"], "inf");
  EXPECT_EQ(j["predicted"]["settling_time_motor_s"], "inf");
  EXPECT_DOUBLE_EQ(j["predicted"]["gain_crossover_hz"].get<double>(), 0.95 * 52.993);
  EXPECT_DOUBLE_EQ(j["predicted"]["horizon_s"].get<double>(), 60.0 / (kTwoPi * 52.993));
  EXPECT_TRUE(j["predicted"]["bandwidth_load"].is_null());
  EXPECT_TRUE(j["predicted"]["bandwidth_load_hz"].is_null());
  EXPECT_DOUBLE_EQ(j["predicted"]["bandwidth_motor_hz"].get<double>(), 0.83 * 52.993);
  EXPECT_DOUBLE_EQ(j["predicted"]["settling_time_s"].get<double>(), 9.1 / (kTwoPi * 52.993));
  EXPECT_EQ(j["predicted"]["closed_loop_poles"][1], nlohmann::json({-0.4, -0.3}));
  EXPECT_EQ(j["robustness"]["np"], "inf");
  EXPECT_TRUE(j["robustness"]["rp"].is_null());
  // A PI has no derivative and no position gain.
  const nlohmann::json pi = controller_to_json(make_controller(Structure::kPi, false, false), "");
  EXPECT_EQ(pi["gains"]["kd"], 0.0);
  EXPECT_EQ(pi["gains"]["tau"], 0.0);
  EXPECT_TRUE(pi["gains"]["kpp"].is_null());
  EXPECT_TRUE(pi["discrete"].is_null());
  EXPECT_EQ(pi["loop"], "velocity");
}

TEST(ControllerJsonRoundTrip, ThroughAFile) {
  const Controller c = make_controller(Structure::kPid, true, false);
  const auto path = std::filesystem::temp_directory_path() / "servotwin_test_controller_json.json";
  {
    std::ofstream out(path);
    out << controller_to_json(c, "plant.json").dump(2) << "\n";
  }
  const LoadedController back = load_controller(path.string());
  std::filesystem::remove(path);
  expect_round_trip(c, back.controller);
  EXPECT_THROW(load_controller("/nonexistent/controller.json"), core::InputError);
}

TEST(ControllerJsonRoundTrip, ControllersFromTheTuner) {
  // What `servotwin tune` writes must read back: a PI with the uncertainty weight (robustness
  // filled) and a PID, each discretized at a drive period, on a frictionless two-mass model
  // (r = 2.2, ωz = 2π·30 rad/s, Im = 0.01).
  fit::PlantModel model;
  model.rigid = fit::RigidKind::kIntegrator;
  model.gain = 100.0;
  const double wz = kTwoPi * 30.0;
  model.modes = {{{wz, 0.02}, {2.2 * wz, 2.2 * 0.02}}};
  for (Structure s : {Structure::kPi, Structure::kPid, Structure::kPiP}) {
    SCOPED_TRACE(tuning::to_string(s));
    tuning::TuneOptions o;
    o.structure = s;
    o.ts = 1.0 / 4000.0;
    if (s == Structure::kPi)
      o.w2 = core::TransferFunction(core::Polynomial{2.6 / wz, 0.0}, core::Polynomial{1.0 / wz, 15.0});
    if (s == Structure::kPid) {
      o.omega_star = 0.5;
      o.target_r = 1.8;
    }
    const Controller c = tuning::tune(model, o).controller;
    ASSERT_TRUE(c.discrete.has_value());
    const LoadedController back = parse_controller_json(controller_to_json(c, "two_mass.json").dump(), "c.json");
    expect_round_trip(c, back.controller);
  }
}

/// A full-order controller from the tuner (r = 3, 40 Hz antiresonance, Im = 4 g·m², 8 kHz); lqg
/// with W2 so that the robust-tracking number is filled.
Controller full_order_controller(Structure structure) {
  fit::PlantModel model;
  model.rigid = fit::RigidKind::kIntegrator;
  model.gain = 250.0;
  const double wz = kTwoPi * 40.0;
  model.modes = {{{wz, 0.01}, {3.0 * wz, 3.0 * 0.01}}};
  tuning::TuneOptions o;
  o.structure = structure;
  o.ts = kTs;
  if (structure == Structure::kLqg)
    o.w2 = core::TransferFunction(core::Polynomial{1.0 / (3.0 * wz), 0.1}, core::Polynomial{1.0 / (3.0 * wz), 1.0});
  return tuning::tune(model, o).controller;
}

Controller lqg_controller() { return full_order_controller(Structure::kLqg); }

/// The H-infinity controller of full_order_controller with a 400 Hz roll-off.
Controller rolled_off_hinf_controller() {
  fit::PlantModel model;
  model.rigid = fit::RigidKind::kIntegrator;
  model.gain = 250.0;
  const double wz = kTwoPi * 40.0;
  model.modes = {{{wz, 0.01}, {3.0 * wz, 3.0 * 0.01}}};
  tuning::TuneOptions o;
  o.structure = Structure::kHinf;
  o.rolloff_rad_s = kTwoPi * 400.0;
  return tuning::tune(model, o).controller;
}

TEST(ControllerJsonRoundTrip, LqgFromTheTuner) {
  const Controller c = lqg_controller();
  ASSERT_TRUE(c.full_order.has_value());
  ASSERT_TRUE(c.robustness.rp_tracking.has_value());
  const nlohmann::json j = controller_to_json(c, "two_mass.json");
  EXPECT_TRUE(j["gains"].is_null());
  EXPECT_TRUE(j["normalized"].is_null());
  EXPECT_TRUE(j["design"]["omega_star"].is_null());
  EXPECT_EQ(j["lqg"]["compensator"]["A"].size(), 5U);
  const LoadedController back = parse_controller_json(j.dump(), "lqg.json");
  expect_round_trip(c, back.controller);
  // The physical state space is the normalized compensator with time by ωz, torque by Im ωz (§0).
  const double wz = c.plant.omega_z, torque = c.plant.motor_inertia * wz;
  for (const double w : {0.3 * wz, wz, 3.0 * wz}) {
    const Eigen::MatrixXcd n = core::frequency_response(c.full_order->compensator, w / wz);
    for (Eigen::Index k = 0; k < 2; ++k) {
      const std::complex<double> physical = [&] {
        const auto& ss = j["state_space"];
        Eigen::MatrixXd a(5, 5), b(5, 2), cc(1, 5), d(1, 2);
        for (int r = 0; r < 5; ++r) {
          for (int q = 0; q < 5; ++q) a(r, q) = ss["A"][r][q];
          for (int q = 0; q < 2; ++q) b(r, q) = ss["B"][r][q];
          cc(0, r) = ss["C"][0][r];
        }
        d << ss["D"][0][0].get<double>(), ss["D"][0][1].get<double>();
        return core::frequency_response(core::StateSpace{a, b, cc, d}, w)(0, k);
      }();
      EXPECT_LE(std::abs(physical - torque * n(0, k)), 1e-9 * std::abs(physical)) << w;
    }
  }
}

// ---------------------------------------------------------------- state spaces against the formula

Eigen::MatrixXd matrix(const nlohmann::json& rows) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows[0].size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      m(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)].get<double>();
  return m;
}

/// C (xI − A)⁻¹ B + D of the matrices in a JSON section (x = s or z).
Eigen::MatrixXcd response(const nlohmann::json& section, std::complex<double> x) {
  const Eigen::MatrixXcd a = matrix(section["A"]).cast<std::complex<double>>();
  const Eigen::MatrixXcd b = matrix(section["B"]).cast<std::complex<double>>();
  const Eigen::MatrixXcd c = matrix(section["C"]).cast<std::complex<double>>();
  const Eigen::MatrixXcd d = matrix(section["D"]).cast<std::complex<double>>();
  const Eigen::MatrixXcd m = x * Eigen::MatrixXcd::Identity(a.rows(), a.cols()) - a;
  return c * m.fullPivLu().solve(b) + d;
}

/// [R(s), −C(s)]: the 2-DoF law from [ω*, ωm] to u.
std::array<std::complex<double>, 2> law(const nlohmann::json& g, std::complex<double> s) {
  const double kp = g["kp"], ki = g["ki"], kd = g["kd"], tau = g["tau"], wp = g["wp"], wd = g["wd"];
  const std::complex<double> derivative = kd * s / (tau * s + 1.0);
  return {wp * kp + ki / s + wd * derivative, -(kp + ki / s + derivative)};
}

void expect_close(std::complex<double> got, std::complex<double> expected, double rel, const std::string& what) {
  EXPECT_LE(std::abs(got - expected), rel * std::abs(expected)) << what << ": " << got << " vs " << expected;
}

TEST(ControllerJsonStateSpace, ContinuousPartIsThePidLaw) {
  for (Structure s : {Structure::kPi, Structure::kPid, Structure::kPiP}) {
    const nlohmann::json j = controller_to_json(make_controller(s, false, false), "");
    for (double w : {0.3, 3.0, 33.0, 333.0, 3333.0, 33333.0}) {
      const std::complex<double> jw(0.0, w);
      const Eigen::MatrixXcd got = response(j["state_space"], jw);
      const auto expected = law(j["gains"], jw);
      ASSERT_EQ(got.rows(), 1);
      ASSERT_EQ(got.cols(), 2);
      for (Eigen::Index k = 0; k < 2; ++k)
        expect_close(got(0, k), expected[static_cast<std::size_t>(k)], 1e-12,
                     tuning::to_string(s) + " at " + std::to_string(w));
    }
  }
}

TEST(ControllerJsonStateSpace, DiscretePartIsTheTustinImageOfTheLaw) {
  for (std::optional<double> prewarp_hz : {std::optional<double>(), std::optional<double>(400.0)}) {
    for (Structure s : {Structure::kPi, Structure::kPid}) {
      const nlohmann::json j = controller_to_json(make_controller(s, true, false, prewarp_hz), "");
      const double ts = j["discrete"]["ts"];
      ASSERT_EQ(ts, kTs);
      for (double f : {1.0, 50.0, 400.0, 1500.0, 3500.0}) {
        const double w = kTwoPi * f;
        const double warp = prewarp_hz ? kTwoPi * *prewarp_hz / std::tan(kTwoPi * *prewarp_hz * ts / 2.0) : 2.0 / ts;
        const std::complex<double> image(0.0, warp * std::tan(w * ts / 2.0));
        const Eigen::MatrixXcd got = response(j["discrete"], std::exp(std::complex<double>(0.0, w * ts)));
        const auto expected = law(j["gains"], image);
        for (Eigen::Index k = 0; k < 2; ++k)
          expect_close(got(0, k), expected[static_cast<std::size_t>(k)], 1e-9,
                       tuning::to_string(s) + " at " + std::to_string(f) + " Hz");
        // At the prewarp frequency the discrete response equals the continuous one.
        if (prewarp_hz && f == *prewarp_hz) {
          const auto continuous = law(j["gains"], std::complex<double>(0.0, w));
          for (Eigen::Index k = 0; k < 2; ++k)
            expect_close(got(0, k), continuous[static_cast<std::size_t>(k)], 1e-9, "prewarp point");
        }
      }
    }
  }
}

// ---------------------------------------------------------------- errors

/// The error of reading `text` as "c.json": its field and message ("no error" when it reads).
struct ReadError {
  std::string field;
  std::string message;
};

ReadError error_of(const std::string& text) {
  try {
    parse_controller_json(text, "c.json");
  } catch (const core::InputError& e) {
    return {e.where().field, e.what()};
  }
  return {"", "no error"};
}

class ControllerJsonErrors : public ::testing::Test {
 protected:
  /// The error after editing a copy of `document`.
  template <typename Edit>
  static ReadError edited_copy(const nlohmann::json& document, Edit edit) {
    nlohmann::json copy = document;
    edit(copy);
    return error_of(copy.dump());
  }
  /// The error after editing a PID (with discrete part) or PI+P document.
  template <typename Edit>
  ReadError with(Edit edit, Structure s = Structure::kPid) const {
    return edited_copy(controller_to_json(make_controller(s, true, false), "p.json"), edit);
  }
  static void expect(const ReadError& e, const std::string& field, const std::string& fragment) {
    EXPECT_EQ(e.field, field) << e.message;
    EXPECT_NE(e.message.find(fragment), std::string::npos) << e.message;
    EXPECT_NE(e.message.find("c.json"), std::string::npos) << e.message;
  }
};

TEST_F(ControllerJsonErrors, UnmodifiedDocumentsRead) {
  for (Structure s : {Structure::kPi, Structure::kPid, Structure::kPiP})
    EXPECT_EQ(with([](auto&) {}, s).message, "no error");
  // Files written before --min-damping existed have no design.min_damping: still read.
  EXPECT_EQ(with([](auto& c) { c["design"].erase("min_damping"); }, Structure::kPi).message, "no error");
}

TEST_F(ControllerJsonErrors, WrongFormat) {
  expect(with([](auto& c) { c["format"] = "servotwin.controller/2"; }), "format", "unsupported version");
  expect(with([](auto& c) { c["format"] = "servotwin.shaper/1"; }), "format", "servotwin.shaper/1");
  expect(with([](auto& c) { c.erase("format"); }), "format", "missing");
  expect(error_of("{\"format\": "), "", "invalid JSON");
}

TEST_F(ControllerJsonErrors, UnknownMembers) {
  expect(with([](auto& c) { c["gain"] = 1; }), "gain", "unknown field");
  expect(with([](auto& c) { c["gains"]["kq"] = 1; }), "gains.kq", "unknown field");
  expect(with([](auto& c) { c["predicted"]["bandwidth"] = 1; }), "predicted.bandwidth", "unknown field");
  expect(with([](auto& c) { c["discrete"]["prewarp"] = 1; }), "discrete.prewarp", "unknown field");
  expect(with([](auto& c) { c["robustness"]["kharitonov"] = true; }), "robustness.kharitonov", "unknown field");
}

TEST_F(ControllerJsonErrors, MissingAndMistypedMembers) {
  expect(with([](auto& c) { c["plant"].erase("motor_inertia"); }), "plant.motor_inertia", "missing");
  expect(with([](auto& c) { c.erase("predicted"); }), "predicted", "missing");
  expect(with([](auto& c) { c["gains"]["kp"] = "12"; }), "gains.kp", "expected a number");
  expect(with([](auto& c) { c["predicted"]["closed_loop_stable"] = 1; }), "predicted.closed_loop_stable",
         "true or false");
  expect(with([](auto& c) { c["notes"] = {1}; }), "notes[0]", "expected a string");
  expect(with([](auto& c) { c["predicted"]["closed_loop_poles"][2] = {1.0}; }), "predicted.closed_loop_poles[2]",
         "[re, im]");
}

TEST_F(ControllerJsonErrors, NonFiniteValues) {
  // JSON has no infinity; a number too large for a double is refused by the parser, and the
  // strings "inf"/"-inf" are accepted only where the format allows them (indices, robustness).
  nlohmann::json j = controller_to_json(make_controller(Structure::kPid, false, false), "");
  std::string text = j.dump();
  const std::string kp = nlohmann::json(j["gains"]["kp"]).dump();
  text.replace(text.find("\"kp\":" + kp), 5 + kp.size(), "\"kp\":1e999");
  expect(error_of(text), "", "does not fit a double");
  expect(with([](auto& c) { c["gains"]["kp"] = "inf"; }), "gains.kp", "expected a number");
  expect(with([](auto& c) { c["gains"]["ki"] = nullptr; }), "gains.ki", "expected a number");
  expect(with([](auto& c) { c["state_space"]["A"][0][0] = nullptr; }), "state_space.A[0][0]", "finite number");
  expect(with([](auto& c) { c["predicted"]["peak_s"] = "nan"; }), "predicted.peak_s", "\"inf\", \"-inf\" or null");
  expect(with([](auto& c) { c["predicted"]["closed_loop_poles"][0][1] = "inf"; }), "predicted.closed_loop_poles[0]",
         "finite");
  expect(with([](auto& c) { c["design"]["omega_star"] = "inf"; }), "design.omega_star", "expected a number");
}

TEST_F(ControllerJsonErrors, PhysicalGainsMustBeTheNormalizedOnesDenormalized) {
  expect(with([](auto& c) { c["gains"]["kp"] = c["gains"]["kp"].template get<double>() * 1.001; }), "gains.kp",
         "normalized.kp");
  expect(with([](auto& c) { c["normalized"]["ki"] = c["normalized"]["ki"].template get<double>() * 1.001; }),
         "gains.ki", "Ki = Ki_n·Im·ωz²");
  expect(with([](auto& c) { c["normalized"]["tau"] = 0.2; }), "gains.tau", "τ = τ_n/ωz");
  expect(with([](auto& c) { c["normalized"]["wp"] = 0.5; }), "gains.wp", "normalized.wp");
  expect(with([](auto& c) { c["plant"]["motor_inertia"] = 0.005; }), "gains.kp", "Kp = Kp_n·Im·ωz");
  expect(with([](auto& c) { c["normalized"]["kpp"] = 0.3; }, Structure::kPiP), "gains.kpp", "Kpp = Kpp_n·ωz");
}

TEST_F(ControllerJsonErrors, StateSpaceMustRealizeTheGains) {
  expect(
      with([](auto& c) { c["state_space"]["D"][0][1] = c["state_space"]["D"][0][1].template get<double>() * 1.0001; }),
      "state_space", "does not realize");
  expect(with([](auto& c) { c["state_space"]["A"][1][1] = c["state_space"]["A"][1][1].template get<double>() * 1.01; }),
         "state_space", "motor_velocity");
  expect(with([](auto& c) { c["discrete"]["C"][0][0] = c["discrete"]["C"][0][0].template get<double>() * 1.0001; }),
         "discrete", "does not realize");
  expect(with([](auto& c) { c["state_space"]["B"][0] = {1.0}; }), "state_space.B", "2x2");  // wrong width
  expect(with([](auto& c) { c["state_space"]["C"][0].push_back(0.0); }), "state_space.C", "1x2");
  expect(with([](auto& c) { c["state_space"]["A"] = {{0.0, 0.0}}; }), "state_space.A", "square");
  expect(with([](auto& c) {
           c["state_space"]["inputs"] = {"motor_velocity", "velocity_reference"};
         }),
         "state_space.inputs", "velocity_reference");
  expect(with([](auto& c) { c["state_space"]["output"] = "current"; }), "state_space.output", "torque");
  expect(with([](auto& c) { c["discrete"]["method"] = "zoh"; }), "discrete.method", "tustin");
}

TEST_F(ControllerJsonErrors, AnyRealizationOfTheGainsIsAccepted) {
  // Scaling the states (x → T x with T = diag(2, −3)) changes the matrices, not the controller.
  const Controller c = make_controller(Structure::kPid, false, false);
  nlohmann::json j = controller_to_json(c, "");
  const Eigen::Vector2d t(2.0, -3.0);
  Eigen::MatrixXd a = matrix(j["state_space"]["A"]), b = matrix(j["state_space"]["B"]),
                  cm = matrix(j["state_space"]["C"]);
  a = t.asDiagonal() * a * t.cwiseInverse().asDiagonal();
  b = t.asDiagonal() * b;
  cm = cm * t.cwiseInverse().asDiagonal();
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k) {
      j["state_space"]["A"][static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = a(i, k);
      j["state_space"]["B"][static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = b(i, k);
    }
  for (int k = 0; k < 2; ++k) j["state_space"]["C"][0][static_cast<std::size_t>(k)] = cm(0, k);
  ASSERT_NE(j["state_space"]["B"][1][1].get<double>(),
            controller_to_json(c, "")["state_space"]["B"][1][1].get<double>());
  EXPECT_EQ(error_of(j.dump()).message, "no error");
}

TEST_F(ControllerJsonErrors, SamplePeriodAndPrewarp) {
  expect(with([](auto& c) { c["discrete"]["ts"] = 0.0; }), "discrete.ts", "> 0");
  expect(with([](auto& c) { c["discrete"]["ts"] = -kTs; }), "discrete.ts", "> 0");
  expect(with([](auto& c) { c["discrete"]["prewarp_hz"] = 4000.0; }), "discrete.prewarp_hz", "Nyquist");
  // A different period with the old matrices is another controller.
  expect(with([](auto& c) { c["discrete"]["ts"] = 2.0 * kTs; }), "discrete", "does not realize");
}

TEST_F(ControllerJsonErrors, StructureAndLoop) {
  expect(with([](auto& c) { c["structure"] = "PI"; }), "structure", "\"hinf-load\" or \"lqg-load\"");
  expect(with([](auto& c) { c["position"]["kpp"] = 1.0; c["position"]["kpp_normalized"] = 1.0; }, Structure::kPiP),
         "position.kpp", "de-normalized");
  expect(with([](auto& c) { c["structure"] = "lqg"; }), "gains", "expected null for an \"lqg\" controller");
  expect(with([](auto& c) { c["loop"] = "position"; }), "loop", "velocity loop");
  expect(with([](auto& c) { c["loop"] = "velocity"; }, Structure::kPiP), "loop", "position loop");
  expect(with([](auto& c) { c["loop"] = "current"; }), "loop", "\"velocity\" or \"position\"");
  expect(with([](auto& c) { c["feedback"] = "load"; }), "feedback", "motor");
  expect(with([](auto& c) { c["gains"]["kpp"] = nullptr; }, Structure::kPiP), "gains.kpp", "position gain > 0");
  expect(with([](auto& c) { c["gains"]["kpp"] = 3.0; }), "gains.kpp", "null");
  expect(with([](auto& c) { c["position"] = nullptr; }, Structure::kPiP), "position", "needs its position-loop section");
  expect(with([](auto& c) { c["position"] = {{"kpp_nominal", 1.0}}; }), "position", "expected null");
  expect(with([](auto& c) { c["position"]["bandwidth_load_hz"] = 99.0; }, Structure::kPiP), "position.bandwidth_load_hz",
         "gives");
  expect(with([](auto& c) { c["position"]["kpp_rs"] = -1.0; }, Structure::kPiP), "position.kpp_rs", ">= 0");
  expect(with([](auto& c) { c["structure"] = "pi"; }), "gains.kd", "only \"pid\" has a derivative");
  expect(with([](auto& c) { c["gains"]["tau"] = 0.0; }), "gains.tau", "derivative filter time constant > 0");
  expect(with([](auto& c) { c["gains"]["wd"] = 1.5; }), "gains.wd", "[0, 1]");
}

TEST(ControllerJsonRoundTrip, LqgPlusPCarriesItsPositionGainInThePositionSection) {
  const Controller c = full_order_controller(Structure::kLqgP);
  const nlohmann::json j = controller_to_json(c, "two_mass.json");
  EXPECT_EQ(j["loop"], "position");
  EXPECT_TRUE(j["gains"].is_null());
  EXPECT_EQ(j["position"]["kpp"].get<double>(), *c.kpp_physical);
  const LoadedController back = parse_controller_json(j.dump(), "lqgp.json");
  expect_round_trip(c, back.controller);
  nlohmann::json edited = j;
  edited["position"].erase("kpp");
  EXPECT_EQ(error_of(edited.dump()).field, "position.kpp");
  edited = j;
  edited["position"]["kpp"] = 2.0 * j["position"]["kpp"].get<double>();
  EXPECT_EQ(error_of(edited.dump()).field, "position.kpp");
  edited = j;
  edited["loop"] = "velocity";
  EXPECT_EQ(error_of(edited.dump()).field, "loop");
}

TEST_F(ControllerJsonErrors, LqgDocuments) {
  static const nlohmann::json lqg = controller_to_json(lqg_controller(), "p.json");
  const auto edited = [](auto edit) { return edited_copy(lqg, edit); };
  EXPECT_EQ(edited([](auto&) {}).message, "no error");
  expect(edited([](auto& c) { c["lqg"]["controller_poles"][0][0] = 99.0; }), "lqg.controller_poles[0]",
         "not an eigenvalue");
  expect(edited([](auto& c) { c["lqg"]["compensator"]["B"][1][1] = 7.0; }), "state_space", "does not realize");
  expect(edited([](auto& c) { c["state_space"]["D"][0][0] = 0.0; }), "state_space", "does not realize");
  expect(edited([](auto& c) { c["discrete"]["C"][0][2] = 0.0; }), "discrete", "does not realize");
  expect(edited([](auto& c) { c["lqg"]["controller_stable"] = !c["lqg"]["controller_stable"].template get<bool>(); }),
         "lqg.controller_stable", "contradicts");
  expect(edited([](auto& c) { c["lqg"] = nullptr; }), "lqg", "needs its compensator");
  expect(edited([](auto& c) { c["lqg"]["kbw"] = 0.0; }), "lqg.kbw", "> 0");
  expect(edited([](auto& c) { c["lqg"]["compensator"]["inputs"] = {"a", "b"}; }), "lqg.compensator.inputs",
         "velocity_reference");
  expect(edited([](auto& c) { c["design"]["omega_star"] = 0.5; }), "design.omega_star", "expected null");
  expect(edited([](auto& c) { c["gains"] = c["state_space"]; }), "gains", "expected null");
  expect(with([](auto& c) { c["lqg"] = {{"kbw", 1.0}}; }), "lqg", "only lqg, lqg+p, lqg-pos and lqg-load controllers");
}

TEST(ControllerJsonRoundTrip, HinfFromTheTuner) {
  const Controller c = full_order_controller(Structure::kHinf);
  ASSERT_TRUE(c.full_order && c.full_order->hinf);
  const nlohmann::json j = controller_to_json(c, "two_mass.json");
  EXPECT_TRUE(j["lqg"].is_null());
  EXPECT_TRUE(j["gains"].is_null());
  EXPECT_EQ(j["hinf"]["compensator"]["A"].size(), 5U);  // the minimal realization (C7.14: 5th order)
  EXPECT_EQ(j["hinf"]["full_order"], 9);
  EXPECT_EQ(j["hinf"]["modes"], "first");
  // The Hankel values belong to the stable part: all states but the integrator and unstable poles
  // (the truncation keeps those, so they are among the compensator's).
  std::size_t unstable = 0;
  for (const auto& p : c.full_order->controller_poles) unstable += p.real() > -1e-6 ? 1U : 0U;
  EXPECT_EQ(j["hinf"]["hankel_singular_values"].size(), 9U - unstable);
  EXPECT_EQ(j["structure"], "hinf");
  EXPECT_EQ(j["loop"], "velocity");
  const LoadedController back = parse_controller_json(j.dump(), "hinf.json");
  expect_round_trip(c, back.controller);
}

TEST(ControllerJsonRoundTrip, HinfWithARollOff) {
  // The roll-off's corner (normalized: 400 Hz / 40 Hz = 10) is written and read back; the written
  // controller is strictly proper; files without the member read as no roll-off.
  const Controller c = rolled_off_hinf_controller();
  const nlohmann::json j = controller_to_json(c, "two_mass.json");
  EXPECT_NEAR(j["hinf"]["rolloff"].get<double>(), 10.0, 1e-12);
  EXPECT_EQ(j["state_space"]["D"][0][0].get<double>(), 0.0);
  const LoadedController back = parse_controller_json(j.dump(), "hinf.json");
  expect_round_trip(c, back.controller);
  EXPECT_EQ(back.controller.full_order->hinf->rolloff, c.full_order->hinf->rolloff);
  nlohmann::json old = controller_to_json(full_order_controller(Structure::kHinf), "two_mass.json");
  EXPECT_TRUE(old["hinf"]["rolloff"].is_null());
  old["hinf"].erase("rolloff");
  EXPECT_FALSE(parse_controller_json(old.dump(), "old.json").controller.full_order->hinf->rolloff.has_value());
}

TEST_F(ControllerJsonErrors, HinfDocuments) {
  static const nlohmann::json hinf = controller_to_json(full_order_controller(Structure::kHinf), "p.json");
  const auto edited = [](auto edit) { return edited_copy(hinf, edit); };
  EXPECT_EQ(edited([](auto&) {}).message, "no error");
  expect(edited([](auto& c) { c["hinf"] = nullptr; }), "hinf", "needs its compensator");
  expect(edited([](auto& c) { c["hinf"]["gamma"] = 0.5 * c["hinf"]["gamma_optimal"].template get<double>(); }),
         "hinf.gamma", "below gamma_optimal");
  expect(edited([](auto& c) { c["hinf"]["omega_0s"] = -1.0; }), "hinf.omega_0s", "> 0");
  expect(edited([](auto& c) { c["hinf"]["controller_poles"][0][0] = 99.0; }), "hinf.controller_poles[0]",
         "not an eigenvalue");
  expect(edited([](auto& c) { c["hinf"]["compensator"]["B"][1][1] = 7.0; }), "state_space", "does not realize");
  expect(edited([](auto& c) { c["hinf"]["modes"] = "both"; }), "hinf.modes", "\"active\"");
  expect(edited([](auto& c) { c["hinf"]["full_order"] = 3; }), "hinf.full_order", ">= the compensator's 5");
  expect(edited([](auto& c) { c["hinf"]["full_order"] = 9.5; }), "hinf.full_order", "whole number");
  expect(edited([](auto& c) { c["hinf"]["hankel_singular_values"][1] = 1e9; }), "hinf.hankel_singular_values[1]",
         "descending");
  expect(edited([](auto& c) { c["hinf"]["reduction_error_bound"] = -1.0; }), "hinf.reduction_error_bound", ">= 0");
  expect(edited([](auto& c) { c["hinf"]["rolloff"] = -3.0; }), "hinf.rolloff", "> 0 or null");
  // Files written before C7.16 (no modes, order or Hankel values) read as a first-mode design.
  EXPECT_EQ(edited([](auto& c) {
              for (const char* k : {"modes", "full_order", "hankel_singular_values", "reduction_error_bound"})
                c["hinf"].erase(k);
            }).message,
            "no error");
  expect(edited([](auto& c) { c["lqg"] = c["hinf"]; }), "lqg", "only lqg, lqg+p, lqg-pos and lqg-load controllers");
  expect(with([](auto& c) { c["hinf"] = {{"omega_0s", 1.0}}; }), "hinf", "only hinf and hinf-pos controllers");
}

TEST(ControllerJsonRoundTrip, PositionControllersFromTheTuner) {
  // lqg-pos and hinf-pos: inputs [φ*, φm], the prefilter's τ and state, the position weights of
  // C7.13 for the LQG. The physical state space is the normalized compensator with time by ωz,
  // torque by Im ωz and, the inputs being positions, one more ωz on B and D: a normalized position
  // is ωz times the physical one (catalog §0: velocities unscaled, time by ωz).
  for (const Structure structure : {Structure::kLqgPos, Structure::kHinfPos}) {
    SCOPED_TRACE(tuning::to_string(structure));
    const Controller c = full_order_controller(structure);
    ASSERT_TRUE(c.full_order.has_value());
    ASSERT_GT(c.full_order->prefilter_tau, 0.0);
    const nlohmann::json j = controller_to_json(c, "two_mass.json");
    const std::string section = structure == Structure::kLqgPos ? "lqg" : "hinf";
    EXPECT_EQ(j["loop"], "position");
    EXPECT_TRUE(j["position"].is_null());
    EXPECT_EQ(j["state_space"]["inputs"], nlohmann::json({"position_reference", "motor_position"}));
    EXPECT_EQ(j[section]["compensator"]["inputs"], nlohmann::json({"position_reference", "motor_position"}));
    EXPECT_DOUBLE_EQ(j[section]["prefilter_tau"].get<double>(), c.full_order->prefilter_tau);
    if (structure == Structure::kLqgPos) {
      EXPECT_EQ(j["lqg"]["q"].size(), 5U);
    }
    const LoadedController back = parse_controller_json(j.dump(), "position.json");
    expect_round_trip(c, back.controller);
    EXPECT_EQ(back.controller.full_order->prefilter_tau, c.full_order->prefilter_tau);
    const double wz = c.plant.omega_z, torque = c.plant.motor_inertia * wz;
    const nlohmann::json& ss = j["state_space"];
    for (const double w : {0.1 * wz, wz, 3.0 * wz}) {
      const Eigen::MatrixXcd n = core::frequency_response(c.full_order->compensator, w / wz);
      const Eigen::MatrixXcd physical = response(ss, std::complex<double>(0.0, w));
      for (Eigen::Index k = 0; k < 2; ++k)
        EXPECT_LE(std::abs(physical(0, k) - torque * wz * n(0, k)), 1e-9 * std::abs(physical(0, k))) << w;
    }
  }
}

TEST(ControllerJsonRoundTrip, LoadMeasuringHinf) {
  // hinf-load: "feedback": "load", inputs [velocity_reference, load_velocity]; a file claiming the
  // motor is refused.
  const Controller c = full_order_controller(Structure::kHinfLoad);
  const nlohmann::json j = controller_to_json(c, "two_mass.json");
  EXPECT_EQ(j["feedback"], "load");
  EXPECT_EQ(j["loop"], "velocity");
  EXPECT_EQ(j["state_space"]["inputs"], nlohmann::json({"velocity_reference", "load_velocity"}));
  const LoadedController back = parse_controller_json(j.dump(), "hinf-load.json");
  expect_round_trip(c, back.controller);
  nlohmann::json motor = j;
  motor["feedback"] = "motor";
  EXPECT_EQ(error_of(motor.dump()).field, "feedback");
}

TEST_F(ControllerJsonErrors, LoadSideLqgMeasuringBothVelocities) {
  // lqg-load: "feedback": "both", inputs [velocity_reference, motor_velocity, load_velocity]; the
  // third channel of the physical state space is checked like the others.
  const Controller c = full_order_controller(Structure::kLqgLoad);
  const nlohmann::json j = controller_to_json(c, "two_mass.json");
  EXPECT_EQ(j["feedback"], "both");
  EXPECT_EQ(j["state_space"]["inputs"], nlohmann::json({"velocity_reference", "motor_velocity", "load_velocity"}));
  EXPECT_EQ(j["discrete"]["B"][0].size(), 3u);
  expect_round_trip(c, parse_controller_json(j.dump(), "lqg-load.json").controller);
  const auto edited = [&](auto edit) { return edited_copy(j, edit); };
  expect(edited([](auto& d) { d["feedback"] = "load"; }), "feedback", "\"both\"");
  expect(edited([](auto& d) { d["state_space"]["inputs"] = {"velocity_reference", "load_velocity"}; }),
         "state_space.inputs", "motor_velocity");
  expect(edited([](auto& d) {
           for (auto& row : d["state_space"]["B"]) row[2] = 1.01 * row[2].template get<double>();
         }),
         "state_space", "from load_velocity");
  expect(edited([](auto& d) { d["discrete"]["D"][0][2] = 2.0 * d["discrete"]["D"][0][2].template get<double>(); }),
         "discrete", "from load_velocity");
  expect(edited([](auto& d) { d["lqg"]["compensator"]["B"][0].erase(2); }), "lqg.compensator.B", "3");
  expect(edited([](auto& d) { d["lqg"]["raw_motor_velocity"] = true; }), "lqg.raw_motor_velocity", "expected false");
}

TEST_F(ControllerJsonErrors, PositionControllerDocuments) {
  static const nlohmann::json lqg = controller_to_json(full_order_controller(Structure::kLqgPos), "p.json");
  const auto edited = [](auto edit) { return edited_copy(lqg, edit); };
  EXPECT_EQ(edited([](auto&) {}).message, "no error");
  expect(edited([](auto& c) { c["lqg"]["compensator"]["inputs"] = {"velocity_reference", "motor_velocity"}; }),
         "lqg.compensator.inputs", "[\"position_reference\",\"motor_position\"]");
  expect(edited([](auto& c) { c["lqg"]["prefilter_tau"] = 2.0 * c["lqg"]["prefilter_tau"].template get<double>(); }),
         "lqg.prefilter_tau", "not the prefilter");
  expect(edited([](auto& c) { c["lqg"]["prefilter_tau"] = -1.0; }), "lqg.prefilter_tau", ">= 0");
  expect(edited([](auto& c) { c["lqg"]["q"] = {1.0, 1.0}; }), "lqg.q", "5 state weights");
  expect(edited([](auto& c) { c["lqg"]["q"][2] = -20.0; }), "lqg.q[2]", ">= 0");
  expect(edited([](auto& c) { c["lqg"].erase("process_noise"); }), "lqg.process_noise", "missing");
  expect(edited([](auto& c) { c["lqg"]["feedforward"] = 1.0; }), "lqg.feedforward", "unknown field");
  expect(edited([](auto& c) { c["loop"] = "velocity"; }), "loop", "position loop");
  expect(edited([](auto& c) { c["structure"] = "lqg"; }), "loop", "velocity loop");
}

TEST_F(ControllerJsonErrors, PlantDesignAndDerivedMembers) {
  expect(with([](auto& c) { c["plant"]["omega_z_hz"] = 0.0; }), "plant.omega_z_hz", "> 0");
  expect(with([](auto& c) { c["plant"]["r"] = 0.9; }), "plant.r", "resonance ratio > 1");
  expect(with([](auto& c) { c["plant"]["zeta_z"] = -0.01; }), "plant.zeta_z", ">= 0");
  expect(with([](auto& c) { c["design"]["omega_star_hz"] = 30.0; }), "design.omega_star_hz", "omega_star");
  expect(with([](auto& c) { c["design"]["zeta_star"] = 0.0; }), "design.zeta_star", "> 0");
  expect(with([](auto& c) { c["design"]["ms"] = 0.8; }), "design.ms", ">= 1");
  expect(with([](auto& c) { c["design"]["min_damping"] = 1.0; }), "design.min_damping", "(0, 1)");
  expect(with([](auto& c) { c["design"]["r_target"] = 1.0; }), "design.r_target", "> 1");
  expect(with([](auto& c) { c["predicted"]["bandwidth_motor_hz"] = 44.1; }), "predicted.bandwidth_motor_hz",
         "bandwidth_motor");
  expect(with([](auto& c) { c["predicted"]["settling_time_s"] = nullptr; }), "predicted.settling_time_s",
         "settling_time");
  expect(with([](auto& c) { c["predicted"]["phase_crossover_hz"] = "inf"; }), "predicted.phase_crossover_hz",
         "phase_crossover");
  expect(with([](auto& c) { c["predicted"].erase("horizon_s"); }), "predicted.horizon_s", "missing");
  expect(with([](auto& c) { c["robustness"]["rs"] = -0.1; }), "robustness.rs", ">= 0");
  expect(with([](auto& c) { c["robustness"]["rp"] = "big"; }), "robustness.rp", "\"inf\"");
}

TEST(ControllerJsonWriter, RefusesControllersThatCannotBeWritten) {
  Controller c = make_controller(Structure::kPi, false, false);
  c.physical.kp = kNan;
  EXPECT_THROW((void)controller_to_json(c, ""), std::invalid_argument);
  c = make_controller(Structure::kPiP, false, false);
  c.kpp_physical.reset();
  EXPECT_THROW((void)controller_to_json(c, ""), std::invalid_argument);
  c = make_controller(Structure::kPi, false, false);
  c.kpp_normalized = 1.0;
  EXPECT_THROW((void)controller_to_json(c, ""), std::invalid_argument);
  c = make_controller(Structure::kPiP, false, false);
  c.position.reset();
  EXPECT_THROW((void)controller_to_json(c, ""), std::invalid_argument);
  c = make_controller(Structure::kPi, false, false);
  c.robustness.rp = kNan;
  EXPECT_THROW((void)controller_to_json(c, ""), std::invalid_argument);
  c = make_controller(Structure::kPid, false, false);
  c.physical.tau = 0.0;  // ideal derivative: no state space
  EXPECT_THROW((void)controller_to_json(c, ""), std::invalid_argument);
}

}  // namespace controller_json_test
}  // namespace
}  // namespace servotwin::io
