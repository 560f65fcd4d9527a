#pragma once
/// \file
/// Description of a virtual machine: per axis a rigid plant, a discrete controller and optional
/// nonlinearities; plus the CNC interpolator settings the machine runs programs with.
///
/// Units are the user's (mm in every preset): positions in mm, time in s, control signal u in V.
/// Plant: J x'' + B x' = K u - F_friction(x') (force in N, J in N s^2/mm = kg/1000,
/// B in N s/mm, K in N/V).

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace servotwin::machine {

/// Rigid axis plant J x'' + B x' = K u - friction.
struct RigidPlant {
  double inertia = 0.0;  ///< J > 0
  double damping = 0.0;  ///< B >= 0 (viscous)
  double gain = 0.0;     ///< K > 0, control signal -> force
};

/// Asymmetric Coulomb friction with stiction [N]. Forces oppose motion: `coulomb_pos` (>= 0) acts
/// while moving in +, `coulomb_neg` (<= 0) while moving in -. At rest the axis sticks while
/// static_neg <= K u <= static_pos. Stiction levels default to the Coulomb levels and must not
/// be inside them (static_pos >= coulomb_pos, static_neg <= coulomb_neg). In Eq. 3.3 terms
/// d0 = coulomb_pos / J and d1 = coulomb_neg / J.
struct Friction {
  double coulomb_pos = 0.0;
  double coulomb_neg = 0.0;
  std::optional<double> static_pos;
  std::optional<double> static_neg;
};

/// Where the position feedback is taken when the axis has backlash.
enum class Feedback { Motor, Table };

/// Lost motion (play) of width `width` [mm] between the driven motor side and the table: a play
/// operator, the table (massless, carried by the rigid plant's inertia) stays put until the motor
/// side is width/2 away and is then dragged along. Both start centred at `home`.
struct Backlash {
  double width = 0.0;
  Feedback feedback = Feedback::Motor;
};

/// Signal-chain imperfections, each off at its default.
struct Nonlinearities {
  Friction friction;
  Backlash backlash;
  double u_max = std::numeric_limits<double>::infinity();  ///< actuator saturation |u| <= u_max [V]
  int dac_bits = 0;            ///< DAC quantization over [-dac_range, dac_range]; 0 = off
  double dac_range = 10.0;     ///< [V]
  double encoder_resolution = 0.0;  ///< position quantum [mm]; 0 = off
  double encoder_noise_std = 0.0;   ///< white measurement noise [mm]
  int delay_samples = 0;       ///< computation delay: u computed at k is applied at k + delay (0 or 1)
};
// Signal chain per sample k: the encoder reads the feedback position (motor or table side),
// adds white noise and quantizes (y = q round((x + n)/q)); the controller computes u(k);
// saturation clips it to +-u_max; the DAC rounds it to its 2^bits codes over +-dac_range
// (two's complement, [-range, range - LSB]); the delay line holds it for delay_samples; the
// plant integrates the held value exactly over [k ts, (k+1) ts).

/// How every discrete controller below is sampled (period ts, sample k):
///  * command derivatives (feedforward and the reference side of derivative terms) are central
///    differences with one sample of look-ahead, x_r'(k) = (x_r(k+1) - x_r(k-1)) / (2 ts),
///    x_r''(k) = (x_r(k+1) - 2 x_r(k) + x_r(k-1)) / ts^2 (the interpolator has the next sample);
///  * the measured velocity is the backward difference of the position reading,
///    x'(k) = (y(k) - y(k-1)) / ts;
///  * integrators are backward Euler, I(k) = I(k-1) + ts e(k): the integral includes the current
///    error (no extra sample of lag), as the thesis's integrated tracking error e_i,k does;
///  * there is no anti-windup (the thesis's identification experiments avoid saturation).

/// P-PI cascade: velocity command v_c = kp (x_r - x) + vel_ff x_r';
/// u = kv (v_c - x') + ki * integral(v_c - x') + acc_ff x_r''.
struct PPiController {
  double kp = 0.0;      ///< position gain [1/s]
  double kv = 0.0;      ///< velocity proportional gain [V s/mm]
  double ki = 0.0;      ///< velocity integral gain [V/mm]
  double vel_ff = 0.0;  ///< velocity feedforward (1 = full) [-]
  double acc_ff = 0.0;  ///< acceleration feedforward [V s^2/mm]
};

/// PID on the position error e = x_r - x plus feedforward:
/// u = kp e + ki integral(e) + kd e' + vel_ff x_r' + acc_ff x_r''  (thesis Eq. 3.5: Kv, Ka).
struct PidController {
  double kp = 0.0;      ///< [V/mm]
  double ki = 0.0;      ///< [V/(mm s)]
  double kd = 0.0;      ///< [V s/mm]
  double vel_ff = 0.0;  ///< [V s/mm]
  double acc_ff = 0.0;  ///< [V s^2/mm]
};

/// Adaptive sliding-mode control with disturbance adaptation (Altintas, Erkorkmaz, Zhu 2000,
/// thesis ref. [13]): S = e' + lambda e,
/// K u = J (x_r'' + lambda e') + B (x_r' + lambda e) + K ks S + K d_hat,  d_hat' = rho S.
/// With the model equal to the plant the tracking transfer function is 1 (full pole-zero
/// cancellation). Model values default to the plant's.
struct SlidingModeController {
  double lambda = 0.0;  ///< sliding-surface bandwidth [rad/s]
  double ks = 0.0;      ///< feedback gain on S [V s/mm]
  double rho = 0.0;     ///< disturbance adaptation gain [V/mm]
  std::optional<double> model_inertia, model_damping, model_gain;
};

/// Discrete pole placement with a Kalman-filter disturbance observer and, optionally, a zero
/// phase error tracking controller (ZPETC, Tomizuka 1987) as feedforward (thesis section 3.4.2).
/// Designed in discrete time from the zero-order-hold model of the rigid plant (including the
/// axis's computation delay, whose extra poles are placed at z = 0): state feedback on [x, v]
/// places the z-images exp(s ts) of the continuous pair with frequency `wn_hz` and damping
/// `zeta`; a steady-state Kalman filter (current-estimator form) estimates [x, v, d] with a
/// random-walk disturbance d (an acceleration, like Eq. 3.3's d0, d1); the control is
/// u = N x_r* - L x_hat + (J/K) d_hat with N for unit DC gain. The ZPETC
/// x_r*/x_r = A(z) B-(1/z) / (B+ B-(1)^2) cancels the closed-loop poles and removes the phase
/// of the plant's zero near -1, using 2 + delay samples of command preview
/// (see pole_placement.hpp).
struct PolePlacementController {
  double wn_hz = 30.0;
  double zeta = 0.7;
  bool zpetc = true;
  /// Spectral density W of the disturbance random walk [(mm/s^2)^2/s]: per sample the
  /// disturbance changes with variance W ts. Default: 1000 mm/s^2 per sample at ts = 1 ms.
  double kalman_process_noise = 1e9;
  /// Variance of the position measurement [mm^2]. Default: (1 um)^2. Only the ratio of the two
  /// intensities matters, and it does not depend on the length unit.
  double kalman_measurement_noise = 1e-6;
};

using Controller = std::variant<PPiController, PidController, SlidingModeController, PolePlacementController>;

/// One axis of a virtual machine.
struct AxisConfig {
  std::string name;  ///< lower-case, e.g. "x"
  RigidPlant plant;
  Controller controller;
  Nonlinearities nonlinear;
  double home = 0.0;  ///< position at start [mm]
};

/// Interpolator settings of the machine's CNC (mapped to motion::InterpolationLimits by callers).
struct CncSettings {
  double accel = 2000.0;            ///< [mm/s^2]
  std::optional<double> jerk;       ///< [mm/s^3], empty = trapezoidal
  double rapid_feed_mm_min = 15000;
  double corner_angle_deg = 1.0;
  /// Stop exactly at the end of every block (G61), as CNCs without look-ahead do; the thesis's
  /// 22 s identification capture (Table 3.2 program) implies it.
  bool exact_stop_every_block = false;
};

/// A machine: axes sampled together at ts.
struct MachineConfig {
  std::string name;
  std::string description;
  double ts = 0.001;
  CncSettings cnc;
  std::vector<AxisConfig> axes;
  /// Axis by (case-insensitive) name or nullptr.
  [[nodiscard]] const AxisConfig* find(const std::string& axis_name) const noexcept;
};

/// Checks every value (positive inertia and gain, finite gains, ts > 0, unique lower-case axis
/// names, friction signs, ...) and throws core::InputError with field = the offending member
/// ("axes[0].plant.inertia"). Also rejects an axis whose linear sampled closed loop (plant plus
/// discrete controller plus delay) is unstable at ts, with field "axes[i].controller".
void validate(const MachineConfig& machine);
/// Checks one axis; `prefix` is prepended to field names (e.g. "axes[0]").
void validate(const AxisConfig& axis, double ts, const std::string& prefix);

}  // namespace servotwin::machine
