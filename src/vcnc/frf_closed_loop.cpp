// The real-time identification block run inside a velocity loop (frf_experiment.hpp): the block
// excites the reference, the known controller closes the loop, and the measured closed loop is
// turned back into the plant.
#include <cmath>
#include <limits>
#include <complex>
#include <fmt/format.h>
#include <numbers>

#include "frf_run.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/vcnc/frf_experiment.hpp"

namespace servotwin::vcnc {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

core::InputError controller_error(const std::string& message) {
  return core::InputError(core::at_field("controller"), message);
}

/// The largest |z| of the loop of the plant's ZOH-discretized linear part (strictly proper) and the
/// controller: x_p+ = Ap x_p + Bp u, y = Cp x_p; x_c+ = Ac x_c + Bc [r; y], u = Cc x_c + Dc [r; y].
double loop_spectral_radius(const machine::FlexiblePlant& plant, const core::DiscreteStateSpace& c) {
  const core::DiscreteStateSpace p = core::discretize_zoh(core::to_state_space(plant.transfer_function()), plant.ts());
  const Eigen::Index np = p.states(), nc = c.states();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(np + nc, np + nc);
  const double dy = c.D(0, 1);
  a.topLeftCorner(np, np) = p.A + p.B * dy * p.C;
  if (nc > 0) {
    a.topRightCorner(np, nc) = p.B * c.C;
    a.bottomLeftCorner(nc, np) = c.B.col(1) * p.C;
    a.bottomRightCorner(nc, nc) = c.A;
  }
  // The power iteration's limit without an eigen-solver: ρ(A) = lim ‖A^k‖^{1/k}, here by repeated
  // squaring of the scaled matrix (ρ < 1 exactly when the powers die out).
  Eigen::MatrixXd power = a;
  double log_norm = 0.0;  // ln of the scale taken out of `power` so far, per unit exponent
  double exponent = 1.0;
  for (int i = 0; i < 40; ++i) {
    const double n = power.norm();
    if (!(n > 0.0) || !std::isfinite(n)) return n > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
    power /= n;
    log_norm += std::log(n) / exponent;
    power = power * power;
    exponent *= 2.0;
  }
  return std::exp(log_norm);
}

void check_loop(const machine::FlexiblePlant& plant, const core::DiscreteStateSpace& c) {
  if (c.B.cols() != 2 || c.C.rows() != 1 || c.D.rows() != 1 || c.D.cols() != 2)
    throw controller_error("the closed-loop measurement needs a velocity controller with the inputs [reference, "
                           "measured velocity] and one output (not a position or two-encoder controller)");
  if (std::abs(c.ts - plant.ts()) > 1e-9 * plant.ts())
    throw controller_error(fmt::format("discretized at {} s, but the plant samples at {} s", c.ts, plant.ts()));
  const machine::PlantOutput out = plant.config().settings.output;
  if (out != machine::PlantOutput::MotorVelocity && out != machine::PlantOutput::LoadVelocity)
    throw controller_error("the plant must measure a velocity for a velocity loop");
  if (plant.config().settings.delay_samples == 0) {
    const double radius = loop_spectral_radius(plant, c);
    if (!(radius < 1.0))
      throw controller_error(fmt::format("the loop of this controller and the plant's linear part is unstable (a "
                                         "closed-loop pole at |z| = {:.6g})",
                                         radius));
  }
}

/// One sample of the controller: u = Cc x + Dc [r; y], x+ = Ac x + Bc [r; y]. Allocation-free.
class ControllerStepper {
 public:
  explicit ControllerStepper(const core::DiscreteStateSpace& c)
      : c_(c), x_(Eigen::VectorXd::Zero(c.states())), next_(x_) {}
  double step(double r, double y) noexcept {
    const double u = c_.C.row(0).dot(x_) + c_.D(0, 0) * r + c_.D(0, 1) * y;
    next_.noalias() = c_.A * x_;
    next_ += c_.B.col(0) * r + c_.B.col(1) * y;
    x_.swap(next_);
    return u;
  }

 private:
  const core::DiscreteStateSpace& c_;
  Eigen::VectorXd x_, next_;
};

}  // namespace

FrfExperiment run_frf_experiment_closed_loop(machine::FlexiblePlant& plant, const frf::RfidParameters& parameters,
                                             double max_time_s, const core::DiscreteStateSpace& controller,
                                             bool keep_trace, const FrfProgress& progress) {
  check_loop(plant, controller);
  FrfExperiment out;
  out.parameters = parameters;
  frf::RfidBlock block(parameters);
  plant.reset();
  ControllerStepper loop(controller);
  const double ts = plant.ts();
  const auto max_samples = static_cast<long>(std::ceil(max_time_s / ts));
  const long report_every = std::max(1L, std::lround(1.0 / ts));
  if (keep_trace) out.trace.reserve(static_cast<std::size_t>(std::min(max_samples, 20'000'000L)));
  double y = plant.measure().y;
  long k = 0;
  for (; k < max_samples; ++k) {
    const frf::RfidOutput o = block.step(true, y, 0.0);
    if (keep_trace) out.trace.push_back({static_cast<double>(k) * ts, o.mv, y, o.omega / kTwoPi, o.amplitude, o.thd, o.state});
    if (o.state == frf::RfidState::kDone || o.state == frf::RfidState::kAborted) break;
    y = plant.step(loop.step(o.mv, y)).y;
    if (progress && k % report_every == 0) progress(static_cast<double>(k) * ts, block.points().size(), o.omega / kTwoPi);
  }
  detail::collect_results(block, k >= max_samples, out);
  // T -> P with the controller's own responses (the block measured y over its reference).
  for (core::FrequencyPoint& p : out.response.points) {
    const Eigen::MatrixXcd c = core::frequency_response(controller, kTwoPi * p.freq_hz);
    const std::complex<double> t = p.value;
    p.value = t / (c(0, 0) + t * c(0, 1));
  }
  for (frf::MeasuredPoint& m : out.points) {
    const Eigen::MatrixXcd c = core::frequency_response(controller, m.omega);
    m.response = m.response / (c(0, 0) + m.response * c(0, 1));
  }
  return out;
}

}  // namespace servotwin::vcnc
