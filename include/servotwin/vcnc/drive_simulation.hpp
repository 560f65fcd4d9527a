#pragma once
/// \file
/// Verification of a tuned cascade controller by simulation on the machine plant with its
/// nonlinearities (issue 7 §5): the controller of tuning::Controller, discretized at the plant's
/// sample period exactly as a drive would run it, closes the loop around machine::FlexiblePlant
/// (Karnopp friction, backlash, current-loop lag, input delay, encoder quantization and noise) with
/// an optional torque limit. The same discrete loop also runs on the plant's linear part (friction,
/// backlash, noise, quantization and the torque limit removed), so every nonlinear response comes
/// with its linear twin and the difference is the nonlinearities' doing, not the discretization's.
///
/// Sampling, as in a drive's cyclic task: at t_k = k ts the controller reads the measurement taken
/// at t_k, computes the torque command u_k, and the plant holds u_k over [t_k, t_{k+1}) (plus the
/// plant's own delay_samples). The controller is the Tustin form of tuning::discretize_controller
/// at the plant's ts (prewarped at the controller's prewarp frequency when it lies below Nyquist).
///
/// Feedback signals: a motor_velocity plant output is the velocity feedback (the position of a
/// pi+p loop or of a position controller is its trapezoidal integral); a motor_position output (an
/// encoder) is the position feedback and its backward difference the velocity, so encoder
/// quantization reaches the loop as a drive sees it. Load-side outputs are refused for controllers
/// that feed back the motor; a load-measuring controller (hinf-load, C7.17) reads the load's output
/// (a plant that measures the motor is run with its encoder moved to the load, and a note says so).
/// A full-order position controller (lqg-pos, hinf-pos) reads [φ*, φm].
///
/// Signs: the load torque Tl opposes the motion (Il ω̇l = T_shaft − Tl − friction), the
/// dissertation's convention and tuning::VelocityLoop's.
///
/// Anti-windup: while the torque command is limited, the controller's states are held when the
/// unlimited command lies beyond the limit (conditional integration), so the integrator does not
/// wind up; without a limit the controller is the exact discrete state space.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/tuning/controller.hpp"

namespace servotwin::vcnc {

/// The test signal (C7.8's two tests).
enum class DriveTest {
  kSetpointStep,  ///< velocity step (pi, pid, lqg, hinf) or position step (pi+p, lqg+p, lqg-pos, hinf-pos) at t = 0
  kLoadStep,      ///< load-torque step at t = 0, reference 0
};

/// "step", "load-step".
[[nodiscard]] std::string_view to_string(DriveTest test) noexcept;
/// Inverse of to_string; std::nullopt for any other text.
[[nodiscard]] std::optional<DriveTest> drive_test_from_string(std::string_view text) noexcept;

/// What to simulate. Units are the plant's (rad/s, rad, N m for a rotary plant).
struct DriveSimulationSettings {
  DriveTest test = DriveTest::kSetpointStep;
  /// Step height: velocity (pi, pid) or position (pi+p) reference, or load torque. > 0.
  double amplitude = 1.0;
  /// Simulated time [s]; 0: automatic: the settling horizon of the tuner's analysis (for pi+p at
  /// least 15/Kpp, always at least 200 samples), doubled up to 4 times until the loop on the plant's
  /// linear part has settled into the band. At most 10^7 samples.
  double duration_s = 0.0;
  /// Torque-command limit |u| <= torque_limit (> 0); empty: no limit.
  std::optional<double> torque_limit;
  /// Settling band of the step metrics, relative to the step (0.02 = 2 %).
  double settling_band = 0.02;
};

/// One sample of a run (plant units).
struct DriveSample {
  double t = 0.0;
  double reference = 0.0;       ///< ω* (pi, pid) or φ* (pi+p)
  double load_torque = 0.0;     ///< Tl applied over the sample
  double torque_command = 0.0;  ///< u after the limit
  double motor_velocity = 0.0, load_velocity = 0.0;  ///< true states at t
  double motor_position = 0.0, load_position = 0.0;
  double measured = 0.0;        ///< the plant's measured output y at t (noise, quantization)
};

/// The variable a run's metrics judge: the load velocity (pi, pid) or load position (pi+p) when
/// the plant has a load, else the motor's.
struct ControlledVariable {
  bool position = false;  ///< position (pi+p) rather than velocity
  bool load = false;      ///< the load rather than the motor
  [[nodiscard]] double operator()(const DriveSample& s) const noexcept {
    if (position) return load ? s.load_position : s.motor_position;
    return load ? s.load_velocity : s.motor_velocity;
  }
};

/// Step-response and disturbance numbers of one run. The controlled variable is the load velocity
/// (pi, pid) or load position (pi+p) when the plant has a load, else the motor's.
struct DriveMetrics {
  // setpoint step
  double rise_time = 0.0;        ///< 10 % -> 90 % of the step [s] (+inf: not reached)
  double overshoot = 0.0;        ///< controlled variable: max/step − 1, >= 0
  double overshoot_motor = 0.0;  ///< the same for the motor
  double settling_time = 0.0;    ///< last exit from the settling band [s] (+inf: not settled)
  // load-torque step
  double peak_deviation = 0.0;        ///< max |controlled variable| [plant units]
  double peak_deviation_motor = 0.0;  ///< max |motor velocity or position|
  /// Last time the controlled variable is farther than band x peak deviation from its final value
  /// (the mean of the last 10 %) [s]. The final value is 0 for velocities; a load position under
  /// motor-position feedback keeps the shaft's static twist −Tl/k (final_error says how much).
  double recovery_time = 0.0;
  // both
  double itae = 0.0;              ///< ∫ t |e| dt of the controlled variable's error [unit s^2]
  double final_error = 0.0;       ///< mean error over the last 10 % of the run
  double residual_oscillation = 0.0;  ///< peak-to-peak of the controlled variable over the last 10 % (hunting, limit cycles)
  double peak_torque = 0.0;       ///< max |u|
  double saturated_fraction = 0.0;  ///< share of samples with the limit active
};

/// A run on the plant and on its linear part.
struct DriveSimulation {
  DriveTest test = DriveTest::kSetpointStep;
  tuning::Structure structure = tuning::Structure::kPi;
  double ts = 0.0;
  double amplitude = 0.0;
  std::optional<double> torque_limit;  ///< as simulated
  double settling_band = 0.0;          ///< as simulated
  tuning::PidGains gains;              ///< the physical velocity-loop gains (cascade structures)
  std::optional<tuning::FullOrderSummary> full_order;  ///< lqg: the compensator's design (normalized)
  std::optional<double> kpp;           ///< pi+p: the physical position gain [1/s]
  bool load_side = false;           ///< the plant is a mass chain with a load (metrics on the load)
  std::vector<DriveSample> samples;         ///< the plant with its nonlinearities
  std::vector<DriveSample> linear_samples;  ///< the same loop on the plant's linear part
  DriveMetrics metrics;
  DriveMetrics linear_metrics;
  core::DiscreteStateSpace controller;  ///< the discrete velocity controller used
  std::vector<std::string> notes;       ///< what a user must know (mismatched scales, limits hit, ...)
};

/// The controlled variable of `simulation` (its structure and whether the plant has a load).
[[nodiscard]] ControlledVariable controlled_variable(const DriveSimulation& simulation) noexcept;

/// The plant's linear part: friction, backlash, noise and quantization removed (inertias,
/// stiffnesses, shaft damping, viscous friction, current lag and delay kept).
[[nodiscard]] machine::PlantConfig linear_part(const machine::PlantConfig& plant);

/// True when `plant` has a load-torque input for DriveTest::kLoadStep (a mass chain; a
/// transfer-function plant has none).
[[nodiscard]] bool has_load_torque_input(const machine::PlantConfig& plant) noexcept;

/// Runs `settings.test` on `plant` closed by `controller` (and on its linear part). Throws
/// core::InputError naming the field when the plant cannot be run with this controller: a
/// load-side output, a load step on a transfer-function plant, a pi+p controller without its
/// position gain, invalid settings (field "amplitude", "duration_s", "torque_limit",
/// "settling_band").
[[nodiscard]] DriveSimulation simulate_drive(const machine::PlantConfig& plant, const tuning::Controller& controller,
                                             const DriveSimulationSettings& settings = {});

}  // namespace servotwin::vcnc
