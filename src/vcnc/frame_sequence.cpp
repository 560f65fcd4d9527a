#include "servotwin/vcnc/frame_sequence.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numeric>
#include <stdexcept>

#include "servotwin/core/error.hpp"

namespace servotwin::vcnc {

namespace {

using Eigen::Index;
using Eigen::MatrixXd;

constexpr double kMaxSamples = 1e7;

[[noreturn]] void fail(const std::string& field, const std::string& message) {
  throw core::InputError(core::at_field(field), message);
}

void require(bool ok, const std::string& field, const std::string& message) {
  if (!ok) fail(field, message);
}

void check_shaper(const FrameSequenceSettings& s) {
  if (s.shaper_times.empty() && s.shaper_amplitudes.empty()) return;
  require(s.shaper_times.size() == s.shaper_amplitudes.size(), "shaper_amplitudes",
          "expected one amplitude per impulse time");
  require(s.shaper_times.front() == 0.0, "shaper_times[0]", "the first impulse must be at t = 0");
  for (std::size_t i = 1; i < s.shaper_times.size(); ++i)
    require(std::isfinite(s.shaper_times[i]) && s.shaper_times[i] > s.shaper_times[i - 1],
            fmt::format("shaper_times[{}]", i), "expected finite, increasing impulse times");
  for (std::size_t i = 0; i < s.shaper_amplitudes.size(); ++i)
    require(std::isfinite(s.shaper_amplitudes[i]), fmt::format("shaper_amplitudes[{}]", i), "expected a finite number");
  const double sum = std::accumulate(s.shaper_amplitudes.begin(), s.shaper_amplitudes.end(), 0.0);
  require(std::abs(sum - 1.0) <= 1e-9, "shaper_amplitudes", fmt::format("the amplitudes must sum to 1, not {}", sum));
  require(s.shaper_times.back() < s.load_step_time, "shaper_times",
          "the shaped setpoint must be complete before the load step");
}

void check_settings(const FrameSequenceSettings& s) {
  require(std::isfinite(s.setpoint) && s.setpoint != 0.0, "setpoint", "expected a finite step height != 0");
  require(std::isfinite(s.load_force), "load_force", "expected a finite force");
  require(std::isfinite(s.stator_force), "stator_force", "expected a finite force");
  require(std::isfinite(s.ts) && s.ts > 0.0, "ts", "expected a sample period > 0");
  require(std::isfinite(s.load_step_time) && s.load_step_time > 0.0, "load_step_time", "expected a time > 0");
  require(std::isfinite(s.stator_step_time) && s.stator_step_time > s.load_step_time, "stator_step_time",
          "expected a time after load_step_time");
  require(std::isfinite(s.duration) && s.duration > s.stator_step_time, "duration",
          "expected a time after stator_step_time");
  require(s.duration / s.ts <= kMaxSamples, "duration", fmt::format("at most {:g} samples", kMaxSamples));
  const double shortest = std::min({s.load_step_time, s.stator_step_time - s.load_step_time, s.duration - s.stator_step_time});
  require(std::isfinite(s.residual_window) && s.residual_window > 0.0 && s.residual_window < shortest,
          "residual_window", fmt::format("expected a time > 0 and shorter than the shortest phase ({:g} s)", shortest));
  check_shaper(s);
}

void check_controller(const core::StateSpace& k) {
  require(k.inputs() == 2 && k.outputs() == 1 && k.B.rows() == k.states() && k.C.cols() == k.states() &&
              k.D.rows() == 1 && k.D.cols() == 2,
          "controller", "expected a state space with inputs [setpoint, rotor velocity] and one output (the motor force)");
  require(k.A.allFinite() && k.B.allFinite() && k.C.allFinite() && k.D.allFinite(), "controller",
          "the controller's matrices must be finite");
}

/// The shaped (or plain) setpoint at sample k: the sum of the impulses already applied.
std::vector<double> setpoint_samples(const FrameSequenceSettings& s, std::size_t n) {
  std::vector<double> r(n, 0.0);
  const std::vector<double> times = s.shaper_times.empty() ? std::vector<double>{0.0} : s.shaper_times;
  const std::vector<double> amplitudes = s.shaper_amplitudes.empty() ? std::vector<double>{1.0} : s.shaper_amplitudes;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const auto first = static_cast<std::size_t>(std::ceil(times[i] / s.ts - 1e-9));
    for (std::size_t k = first; k < n; ++k) r[k] += s.setpoint * amplitudes[i];
  }
  return r;
}

double rms(const std::vector<double>& x, std::size_t from, std::size_t to, double offset = 0.0) {
  double sum = 0.0;
  for (std::size_t k = from; k < to; ++k) sum += (x[k] - offset) * (x[k] - offset);
  return to > from ? std::sqrt(sum / static_cast<double>(to - from)) : 0.0;
}

FramePhase phase_metrics(const FrameSequence& run, const FrameSequenceSettings& s, std::string name, double start,
                         double end) {
  FramePhase p;
  p.name = std::move(name);
  p.start = start;
  p.end = end;
  const auto index = [&](double t) { return std::min(run.time.size(), static_cast<std::size_t>(std::ceil(t / s.ts - 1e-9))); };
  const std::size_t a = index(start), b = index(end), window = index(end - s.residual_window);
  const double target = s.setpoint;
  for (std::size_t k = a; k < b; ++k) p.peak_stator = std::max(p.peak_stator, std::abs(run.stator_velocity[k]));
  p.residual_stator = rms(run.stator_velocity, window, b);
  p.residual_rotor = rms(run.rotor_velocity, window, b, target);
  if (start == 0.0) {
    for (std::size_t k = a; k < b; ++k) p.peak_rotor_error = std::max(p.peak_rotor_error, (run.rotor_velocity[k] - target) / target);
    p.peak_rotor_error = std::max(p.peak_rotor_error, 0.0);
  } else {
    for (std::size_t k = a; k < b; ++k) p.peak_rotor_error = std::max(p.peak_rotor_error, std::abs(run.rotor_velocity[k] - target));
  }
  return p;
}

/// Modal decomposition of the closed loop: its eigenvectors V and W = V^-1, and the equilibrium
/// map -A^-1 B (A is Hurwitz once the loop is stable).
struct Modes {
  Eigen::VectorXcd poles;
  Eigen::MatrixXcd v, w;
  MatrixXd equilibrium;

  explicit Modes(const core::StateSpace& cl) {
    Eigen::EigenSolver<MatrixXd> eig(cl.A);
    poles = eig.eigenvalues();
    v = eig.eigenvectors();
    w = v.inverse();
    equilibrium = -cl.A.partialPivLu().solve(cl.B);
  }

  /// The oscillatory modes in the state x with the inputs u held from now on.
  std::vector<FrameMode> excited(const core::StateSpace& cl, const Eigen::VectorXd& x, const Eigen::Vector3d& u) const {
    const Eigen::VectorXcd transient = (x - equilibrium * u).cast<std::complex<double>>();
    std::vector<FrameMode> out;
    for (Index i = 0; i < poles.size(); ++i) {
      if (poles(i).imag() <= 0.0) continue;
      const std::complex<double> coordinate = (w.row(i) * transient).value();
      const Eigen::VectorXcd shape = cl.C.topRows(3).cast<std::complex<double>>() * v.col(i);
      FrameMode m;
      m.pole = poles(i);
      m.damping = core::modal_info(poles(i)).zeta;
      m.rotor = 2.0 * std::abs(shape(0) * coordinate);
      m.load = 2.0 * std::abs(shape(1) * coordinate);
      m.stator = 2.0 * std::abs(shape(2) * coordinate);
      out.push_back(m);
    }
    std::sort(out.begin(), out.end(), [](const FrameMode& a, const FrameMode& b) { return std::abs(a.pole) < std::abs(b.pole); });
    return out;
  }
};

}  // namespace

core::StateSpace frame_closed_loop(const machine::FlexibleFrame& frame, const core::StateSpace& controller) {
  check_controller(controller);
  const core::StateSpace plant = machine::flexible_frame_velocity_state_space(frame);
  const Index n = plant.states(), m = controller.states();
  const MatrixXd cy = plant.C.row(machine::kRotorVelocityOut);
  const MatrixXd bm = plant.B.col(machine::kMotorForce);
  const double d_ref = controller.D(0, 0), d_fb = controller.D(0, 1);
  // u = Ck xk + D_ref r + D_fb y, y = Cy x (the plant has no feedthrough: no algebraic loop).
  core::StateSpace cl;
  cl.A = MatrixXd::Zero(n + m, n + m);
  cl.A.topLeftCorner(n, n) = plant.A + d_fb * bm * cy;
  cl.A.topRightCorner(n, m) = bm * controller.C;
  cl.A.bottomLeftCorner(m, n) = controller.B.col(1) * cy;
  cl.A.bottomRightCorner(m, m) = controller.A;
  cl.B = MatrixXd::Zero(n + m, 3);
  cl.B.block(0, 0, n, 1) = d_ref * bm;
  cl.B.block(0, 1, n, 1) = plant.B.col(machine::kLoadForce);
  cl.B.block(0, 2, n, 1) = plant.B.col(machine::kStatorForce);
  cl.B.block(n, 0, m, 1) = controller.B.col(0);
  cl.C = MatrixXd::Zero(5, n + m);
  cl.C.topLeftCorner(4, n) = plant.C;
  cl.C.block(4, 0, 1, n) = d_fb * cy;
  cl.C.block(4, n, 1, m) = controller.C;
  cl.D = MatrixXd::Zero(5, 3);
  cl.D(4, 0) = d_ref;
  return cl;
}

FrameSequence simulate_frame_sequence(const machine::FlexibleFrame& frame, const core::StateSpace& controller,
                                      const FrameSequenceSettings& settings) {
  check_settings(settings);
  const core::StateSpace cl = frame_closed_loop(frame, controller);
  FrameSequence out;
  out.ts = settings.ts;
  const Eigen::VectorXcd poles = cl.A.eigenvalues();
  out.closed_loop_poles.assign(poles.begin(), poles.end());
  out.min_damping = 1.0;
  std::string unstable;
  for (const auto& p : out.closed_loop_poles) {
    out.min_damping = std::min(out.min_damping, core::modal_info(p).zeta);
    if (p.real() >= 0.0) unstable += fmt::format(" {:.4g}{:+.4g}j", p.real(), p.imag());
  }
  if (!unstable.empty()) throw std::domain_error("the closed loop on the flexible frame is unstable; poles:" + unstable);

  const auto n = static_cast<std::size_t>(std::floor(settings.duration / settings.ts + 1e-9)) + 1;
  const std::vector<double> r = setpoint_samples(settings, n);
  core::DiscreteSimulator sim(core::discretize_zoh(cl, settings.ts));
  for (auto* v : {&out.time, &out.setpoint, &out.rotor_velocity, &out.load_velocity, &out.stator_velocity,
                  &out.frame_velocity, &out.motor_force})
    v->resize(n);
  const auto sample_of = [&](double t) { return static_cast<std::size_t>(std::ceil(t / settings.ts - 1e-9)); };
  const std::size_t load_start = sample_of(settings.load_step_time), stator_start = sample_of(settings.stator_step_time);
  const std::array<std::size_t, 3> events{settings.shaper_times.empty() ? 0 : sample_of(settings.shaper_times.back()),
                                          load_start, stator_start};
  const Modes modes(cl);
  std::array<std::vector<FrameMode>, 3> excited;
  std::array<double, 3> u{};
  std::array<double, 5> y{};
  for (std::size_t k = 0; k < n; ++k) {
    u = {r[k], k >= load_start ? settings.load_force : 0.0, k >= stator_start ? settings.stator_force : 0.0};
    for (std::size_t e = 0; e < events.size(); ++e)
      if (k == events[e]) excited[e] = modes.excited(cl, sim.state(), Eigen::Vector3d(u[0], u[1], u[2]));
    sim.step(u, y);
    out.time[k] = static_cast<double>(k) * settings.ts;
    out.setpoint[k] = r[k];
    out.rotor_velocity[k] = y[0];
    out.load_velocity[k] = y[1];
    out.stator_velocity[k] = y[2];
    out.frame_velocity[k] = y[3];
    out.motor_force[k] = y[4];
  }
  out.phases = {phase_metrics(out, settings, "setpoint", 0.0, settings.load_step_time),
                phase_metrics(out, settings, "load force", settings.load_step_time, settings.stator_step_time),
                phase_metrics(out, settings, "stator force", settings.stator_step_time, settings.duration)};
  for (std::size_t e = 0; e < events.size(); ++e) out.phases[e].modes = std::move(excited[e]);
  return out;
}

}  // namespace servotwin::vcnc
