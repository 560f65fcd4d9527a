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

/// Asymmetric Coulomb friction with stiction. Forces oppose motion: `coulomb_pos` (>= 0) acts
/// while moving in +, `coulomb_neg` (<= 0) while moving in -. At rest the axis sticks while
/// static_neg <= K u <= static_pos. Stiction levels default to the Coulomb levels.
struct Friction {
  double coulomb_pos = 0.0;
  double coulomb_neg = 0.0;
  std::optional<double> static_pos;
  std::optional<double> static_neg;
};

/// Where the position feedback is taken when the axis has backlash.
enum class Feedback { Motor, Table };

/// Lost motion (play) of width `width` [mm] between the driven motor side and the table.
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
/// The closed-loop poles of the state feedback are placed at the z-images of a continuous pair
/// with frequency `wn_hz` and damping `zeta`; the ZPETC cancels them and the plant's well-damped
/// zeros and removes the phase of the zero near -1, using `preview` samples of the command.
struct PolePlacementController {
  double wn_hz = 30.0;
  double zeta = 0.7;
  bool zpetc = true;
  double kalman_process_noise = 1.0;      ///< disturbance random-walk intensity (relative)
  double kalman_measurement_noise = 1e-6; ///< encoder noise variance (relative)
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

/// Checks every value (positive inertia and gain, finite gains, ts > 0, unique axis names, ...)
/// and throws core::InputError with field = the offending member ("axes[0].plant.inertia").
void validate(const MachineConfig& machine);

}  // namespace servotwin::machine
