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

/// The largest |z| of the loop of the plant's ZOH-discretized linear part (strictly proper), its
/// input delay of d samples (a shift register z_1 … z_d) and the controller:
///   x_p+ = Ap x_p + Bp v, y = Cp x_p, v = z_d (v = u without delay), z_1+ = u, z_i+1+ = z_i,
///   x_c+ = Ac x_c + Bc [r; y], u = Cc x_c + Dc [r; y].
double loop_spectral_radius(const machine::FlexiblePlant& plant, const core::DiscreteStateSpace& c) {
  const core::DiscreteStateSpace p = core::discretize_zoh(core::to_state_space(plant.transfer_function()), plant.ts());
  const Eigen::Index np = p.states(), nc = c.states();
  const auto nd = static_cast<Eigen::Index>(plant.config().settings.delay_samples);
  const Eigen::Index n = np + nd + nc;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  // u as a row over the state [x_p, z, x_c].
  Eigen::RowVectorXd u = Eigen::RowVectorXd::Zero(n);
  u.head(np) = c.D(0, 1) * p.C;
  if (nc > 0) u.tail(nc) = c.C;
  a.topLeftCorner(np, np) = p.A;
  if (nd == 0) {
    a.topRows(np) += p.B * u;
  } else {
    a.block(0, np + nd - 1, np, 1) = p.B;
    a.row(np) = u;
    for (Eigen::Index i = 1; i < nd; ++i) a(np + i, np + i - 1) = 1.0;
  }
  if (nc > 0) {
    a.block(np + nd, 0, nc, np) = c.B.col(1) * p.C;
    a.bottomRightCorner(nc, nc) = c.A;
  }
  // The power iteration's limit without an eigen-solver: ρ(A) = lim ‖A^k‖^{1/k}, here by repeated
  // squaring of the scaled matrix (ρ < 1 exactly when the powers die out).
  Eigen::MatrixXd power = a;
  double log_norm = 0.0;  // ln of the scale taken out of `power` so far, per unit exponent
  double exponent = 1.0;
  for (int i = 0; i < 40; ++i) {
    const double norm = power.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return norm > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
    power /= norm;
    log_norm += std::log(norm) / exponent;
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
  // Beyond this many loop states (a long input delay) the check would cost seconds of dense
  // products; such a loop is not checked before the run, and the block's output-range abort stops
  // an unstable one.
  constexpr int kMaxCheckedStates = 200;
  if (plant.config().settings.delay_samples + static_cast<int>(c.states()) > kMaxCheckedStates) return;
  const double radius = loop_spectral_radius(plant, c);
  if (!(radius < 1.0))
    throw controller_error(fmt::format("the loop of this controller and the plant's linear part is unstable (a "
                                       "closed-loop pole at |z| = {:.6g})",
                                       radius));
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
  ControllerStepper loop(controller);
  detail::run_block(
      block, plant, max_time_s, keep_trace, progress, out, [](const frf::RfidOutput&) { return 0.0; },
      [&loop](const frf::RfidOutput& o, double y) { return loop.step(o.mv, y); });
  // T -> P with the controller's own responses (the block measured y over its reference).
  for (core::FrequencyPoint& p : out.response.points) {
    const Eigen::MatrixXcd c = core::frequency_response(controller, kTwoPi * p.freq_hz);
    const std::complex<double> t = p.value;
    p.value = t / (c(0, 0) + t * c(0, 1));
    // δP/P = (δT/T)·(1 − P·C_y): where the loop's sensitivity is small the plant estimate is
    // noisier than the measured T by 1/|S|.
    const double sensitivity = 1.0 / std::abs(1.0 - p.value * c(0, 1));
    p.snr *= sensitivity;
    if (p.valid && p.snr < frf::RfidBlock::kMinimumSnr) {
      p.valid = false;
      p.note = fmt::format("SNR of the plant estimate {:.3g} below {:.3g}: the loop's sensitivity {:.3g} hides "
                           "the plant there",
                           p.snr, frf::RfidBlock::kMinimumSnr, sensitivity);
    }
  }
  for (frf::MeasuredPoint& m : out.points) {
    const Eigen::MatrixXcd c = core::frequency_response(controller, m.omega);
    m.response = m.response / (c(0, 0) + m.response * c(0, 1));
    m.snr /= std::abs(1.0 - m.response * c(0, 1));
  }
  return out;
}

}  // namespace servotwin::vcnc
