#include "servotwin/machine/simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "gaussian.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/pole_placement.hpp"
#include "servotwin/machine/rigid_axis.hpp"

namespace servotwin::machine {

namespace {

// ---- discrete control laws (axis_config.hpp documents the sampling conventions) ----------------
// compute(y, r): y = reading y(k), r points at x_r(k) with r[-1] ... r[preview] valid.
// commit(u): the value actually sent to the amplifier (after saturation and DAC).

// The signals both PID-form laws differentiate: the command by central differences (the
// interpolator provides one sample of look-ahead), the reading by a backward difference.
class SampledDerivatives {
 public:
  struct Values {
    double ref_v, ref_a, meas_v;
  };
  explicit SampledDerivatives(double ts) : inv_ts_(1.0 / ts), inv_ts2_(1.0 / (ts * ts)) {}
  void reset(double y0) noexcept { y_prev_ = y0; }
  Values update(double y, const double* r) noexcept {
    const Values v{0.5 * (r[1] - r[-1]) * inv_ts_, (r[1] - 2.0 * r[0] + r[-1]) * inv_ts2_, (y - y_prev_) * inv_ts_};
    y_prev_ = y;
    return v;
  }

 private:
  double inv_ts_, inv_ts2_;
  double y_prev_ = 0.0;
};

class PidLaw {
 public:
  PidLaw(const PidController& c, double ts) : c_(c), ts_(ts), d_(ts) {}
  void reset(double y0) noexcept { d_.reset(y0); }
  double compute(double y, const double* r) noexcept {
    const double e = r[0] - y;
    integral_ += ts_ * e;
    const auto d = d_.update(y, r);
    return c_.kp * e + c_.ki * integral_ + c_.kd * (d.ref_v - d.meas_v) + c_.vel_ff * d.ref_v + c_.acc_ff * d.ref_a;
  }
  void commit(double) noexcept {}

 private:
  PidController c_;
  double ts_;
  SampledDerivatives d_;
  double integral_ = 0.0;
};

class PPiLaw {
 public:
  PPiLaw(const PPiController& c, double ts) : c_(c), ts_(ts), d_(ts) {}
  void reset(double y0) noexcept { d_.reset(y0); }
  double compute(double y, const double* r) noexcept {
    const auto d = d_.update(y, r);
    const double velocity_command = c_.kp * (r[0] - y) + c_.vel_ff * d.ref_v;
    const double velocity_error = velocity_command - d.meas_v;
    integral_ += ts_ * velocity_error;
    return c_.kv * velocity_error + c_.ki * integral_ + c_.acc_ff * d.ref_a;
  }
  void commit(double) noexcept {}

 private:
  PPiController c_;
  double ts_;
  SampledDerivatives d_;
  double integral_ = 0.0;
};

class SlidingModeLaw {
 public:
  SlidingModeLaw(const SlidingModeController& c, const RigidPlant& plant, double ts)
      : lambda_(c.lambda),
        ks_(c.ks),
        rho_ts_(c.rho * ts),
        jm_(c.model_inertia.value_or(plant.inertia) / c.model_gain.value_or(plant.gain)),
        bm_(c.model_damping.value_or(plant.damping) / c.model_gain.value_or(plant.gain)),
        d_(ts) {}
  void reset(double y0) noexcept { d_.reset(y0); }
  double compute(double y, const double* r) noexcept {
    const auto d = d_.update(y, r);
    const double e = r[0] - y;
    const double e_rate = d.ref_v - d.meas_v;
    const double surface = e_rate + lambda_ * e;
    disturbance_ += rho_ts_ * surface;  // adaptation d_hat' = rho S, backward Euler
    return jm_ * (d.ref_a + lambda_ * e_rate) + bm_ * (d.ref_v + lambda_ * e) + ks_ * surface + disturbance_;
  }
  void commit(double) noexcept {}

 private:
  double lambda_, ks_, rho_ts_, jm_, bm_;
  SampledDerivatives d_;
  double disturbance_ = 0.0;
};

class PolePlacementLaw {
 public:
  static constexpr int kMaxStates = 4;  // [x, v, u(k-1), d]
  static constexpr int kMaxTaps = 6;

  explicit PolePlacementLaw(const PolePlacementDesign& d)
      : n_(static_cast<int>(d.phi_a.rows())),
        preview_(d.preview),
        zpetc_(d.zpetc),
        reference_gain_(d.reference_gain) {
    for (int i = 0; i < n_; ++i) {
      m_[i] = d.kalman_gain(i);
      gamma_[i] = d.gamma_a(i);
      for (int j = 0; j < n_; ++j) phi_[i * kMaxStates + j] = d.phi_a(i, j);
      k_[i] = i + 1 < n_ ? d.feedback(i) : -d.disturbance_gain;
    }
    taps_count_ = static_cast<int>(d.zpetc_taps.size());
    for (int j = 0; j < taps_count_; ++j) taps_[j] = d.zpetc_taps[static_cast<std::size_t>(j)];
  }
  void reset(double y0) noexcept {
    xh_.fill(0.0);
    xh_[0] = y0;
  }
  double compute(double y, const double* r) noexcept {
    double reference = r[0];
    if (zpetc_) {
      reference = 0.0;
      for (int j = 0; j < taps_count_; ++j) reference += taps_[j] * r[preview_ - j];
    }
    const double innovation = y - xh_[0];
    double u = reference_gain_ * reference;
    for (int i = 0; i < n_; ++i) {
      xh_[i] += m_[i] * innovation;
      u -= k_[i] * xh_[i];
    }
    return u;
  }
  void commit(double u) noexcept {
    std::array<double, kMaxStates> next{};
    for (int i = 0; i < n_; ++i) {
      double acc = gamma_[i] * u;
      for (int j = 0; j < n_; ++j) acc += phi_[i * kMaxStates + j] * xh_[j];
      next[i] = acc;
    }
    xh_ = next;
  }

 private:
  int n_, preview_;
  bool zpetc_;
  double reference_gain_;
  int taps_count_ = 0;
  std::array<double, kMaxTaps> taps_{};
  std::array<double, kMaxStates> m_{}, gamma_{}, k_{}, xh_{};
  std::array<double, kMaxStates * kMaxStates> phi_{};
};

// ---- the signal chain around the law ----------------------------------------------------------

struct Chain {
  bool backlash = false, table_feedback = false;
  double half_play = 0.0;
  double noise_std = 0.0;
  double resolution = 0.0, inv_resolution = 0.0;
  double u_max = 0.0;
  bool dac = false;
  double lsb = 0.0, inv_lsb = 0.0, code_min = 0.0, code_max = 0.0;
  int delay = 0;
};

Chain make_chain(const Nonlinearities& nl, bool ideal) {
  Chain c;
  c.u_max = std::numeric_limits<double>::infinity();
  if (ideal) return c;
  c.backlash = nl.backlash.width > 0.0;
  c.table_feedback = c.backlash && nl.backlash.feedback == Feedback::Table;
  c.half_play = 0.5 * nl.backlash.width;
  c.noise_std = nl.encoder_noise_std;
  c.resolution = nl.encoder_resolution;
  c.inv_resolution = c.resolution > 0.0 ? 1.0 / c.resolution : 0.0;
  c.u_max = nl.u_max;
  c.dac = nl.dac_bits > 0;
  if (c.dac) {
    const double half_codes = std::ldexp(1.0, nl.dac_bits - 1);
    c.lsb = nl.dac_range / half_codes;
    c.inv_lsb = 1.0 / c.lsb;
    c.code_min = -half_codes;
    c.code_max = half_codes - 1.0;
  }
  c.delay = nl.delay_samples;
  return c;
}

bool friction_active(const Friction& f) {
  return f.coulomb_pos != 0.0 || f.coulomb_neg != 0.0 || f.static_pos.value_or(0.0) != 0.0 ||
         f.static_neg.value_or(0.0) != 0.0;
}

template <class Law>
void run(Law law, const AxisConfig& axis, double ts, std::span<const double> padded, std::size_t n,
         const SimulationOptions& options, std::uint64_t stream, AxisRun& out) {
  const Chain chain = make_chain(axis.nonlinear, options.ideal);
  RigidAxisDynamics plant(axis.plant, axis.nonlinear.friction,
                          !options.ideal && friction_active(axis.nonlinear.friction), ts);
  plant.reset(axis.home);
  double table = axis.home;
  detail::GaussianSource gauss(options.seed, stream);
  const bool noisy = chain.noise_std > 0.0;
  double pending = 0.0;                  // the delay line (delay_samples <= 1, validated)
  const double* r = padded.data() + 1;  // x_r(0); padded[0] = x_r(-1)

  auto read = [&]() noexcept {
    double y = chain.table_feedback ? table : plant.position();
    if (noisy) y += chain.noise_std * gauss();
    if (chain.resolution > 0.0) y = chain.resolution * std::floor(y * chain.inv_resolution + 0.5);
    return y;
  };
  auto play = [&](double motor) noexcept {
    if (motor - table > chain.half_play) {
      table = motor - chain.half_play;
    } else if (motor - table < -chain.half_play) {
      table = motor + chain.half_play;
    }
  };

  double y = read();
  law.reset(y);
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) y = read();
    out.act[k] = y;
    double u = law.compute(y, r + k);
    u = std::clamp(u, -chain.u_max, chain.u_max);
    if (chain.dac) u = chain.lsb * std::clamp(std::floor(u * chain.inv_lsb + 0.5), chain.code_min, chain.code_max);
    law.commit(u);
    double applied = u;
    if (chain.delay > 0) {
      applied = pending;
      pending = u;
    }
    if (options.record_u) out.u[k] = applied;
    if (options.record_states) {
      out.motor[k] = plant.position();
      out.table[k] = chain.backlash ? table : plant.position();
      out.velocity[k] = plant.velocity();
    }
    const RigidAxisDynamics::Step step = plant.step(applied);
    if (chain.backlash) {
      if (step.turned) play(step.turn_position);
      play(plant.position());
    }
  }
}

void check_commands(std::span<const double> command, const std::string& field) {
  for (std::size_t k = 0; k < command.size(); ++k)
    if (!std::isfinite(command[k]))
      throw core::InputError(core::SourceLocation{"", 0, 0, field + "[" + std::to_string(k) + "]"},
                             "command positions must be finite");
}

AxisRun run_axis(const AxisConfig& axis, double ts, std::span<const double> command, const SimulationOptions& options,
                 std::uint64_t stream) {
  const std::size_t n = command.size();
  const int preview = command_preview(axis);
  AxisRun out;
  out.act.resize(n);
  if (options.record_u) out.u.resize(n);
  if (options.record_states) {
    out.motor.resize(n);
    out.table.resize(n);
    out.velocity.resize(n);
  }
  if (n == 0) return out;
  // Padded copy: x_r(-1) = x_r(0) before the start, the last value held after the end.
  std::vector<double> padded;
  padded.reserve(n + 1 + static_cast<std::size_t>(std::max(preview, 1)));
  padded.push_back(command.front());
  padded.insert(padded.end(), command.begin(), command.end());
  padded.resize(padded.capacity(), command.back());

  std::visit(
      [&](const auto& c) {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, PidController>) {
          run(PidLaw(c, ts), axis, ts, padded, n, options, stream, out);
        } else if constexpr (std::is_same_v<T, PPiController>) {
          run(PPiLaw(c, ts), axis, ts, padded, n, options, stream, out);
        } else if constexpr (std::is_same_v<T, SlidingModeController>) {
          run(SlidingModeLaw(c, axis.plant, ts), axis, ts, padded, n, options, stream, out);
        } else {
          const PolePlacementDesign design = design_pole_placement(axis.plant, c, ts, axis.nonlinear.delay_samples);
          run(PolePlacementLaw(design), axis, ts, padded, n, options, stream, out);
        }
      },
      axis.controller);
  return out;
}

}  // namespace

AxisRun simulate_axis(const AxisConfig& axis, double ts, std::span<const double> command,
                      const SimulationOptions& options, std::uint64_t stream) {
  validate(axis, ts, axis.name.empty() ? std::string("axis") : axis.name);
  check_commands(command, "command");
  return run_axis(axis, ts, command, options, stream);
}

core::Capture simulate(const MachineConfig& machine, const std::vector<std::vector<double>>& commands,
                       const SimulationOptions& options) {
  validate(machine);
  if (commands.size() != machine.axes.size())
    throw core::InputError(core::SourceLocation{"", 0, 0, "commands"},
                           "expected " + std::to_string(machine.axes.size()) + " command vectors (one per axis of '" +
                               machine.name + "'), found " + std::to_string(commands.size()));
  for (std::size_t i = 0; i < commands.size(); ++i) {
    if (commands[i].size() != commands.front().size())
      throw core::InputError(core::SourceLocation{"", 0, 0, "commands[" + std::to_string(i) + "]"},
                             "expected " + std::to_string(commands.front().size()) + " samples like axis " +
                                 machine.axes.front().name + ", found " + std::to_string(commands[i].size()));
    check_commands(commands[i], "commands[" + std::to_string(i) + "]");
  }
  core::Capture capture;
  capture.t0 = 0.0;
  capture.ts = machine.ts;
  for (std::size_t i = 0; i < machine.axes.size(); ++i) {
    const auto& axis = machine.axes[i];
    SimulationOptions axis_options = options;
    axis_options.record_states = false;
    AxisRun run = run_axis(axis, machine.ts, commands[i], axis_options, i);
    core::AxisTrace trace;
    trace.name = axis.name;
    trace.cmd = commands[i];
    trace.act = std::move(run.act);
    trace.u = std::move(run.u);
    capture.axes.push_back(std::move(trace));
  }
  return capture;
}

}  // namespace servotwin::machine
