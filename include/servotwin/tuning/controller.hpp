#pragma once
/// \file
/// The tuned controller as the library hands it to users (and io::controller_json writes it):
/// physical and normalized gains, the 2-DoF controller as a continuous and a discretized state
/// space, the design parameters and the predicted indices (issue-7 plan §3.2 controller.hpp).
///
/// The cascade structures of chapter 7 (C7.3–C7.5, C7.10):
///   pi    u = (wp kp + ki/s) ω* − (kp + ki/s) ωm
///   pid   the same plus kd s/(τ s + 1) on the measurement (wd = 0: no torque kick on steps)
///   pi+p  a P position loop ω* = kpp (φ* − φ) over the PI velocity loop

#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/state_space.hpp"
#include "servotwin/tuning/loop_analysis.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

/// Controller structure offered by the tuner.
enum class Structure { kPi, kPid, kPiP };

/// "pi", "pid", "pi+p".
[[nodiscard]] std::string to_string(Structure structure);
/// Inverse of to_string; std::nullopt for an unknown name.
[[nodiscard]] std::optional<Structure> structure_from_string(const std::string& name);

/// The normalization of the plant the controller was designed for (catalog §0).
struct PlantScales {
  double omega_z = 1.0;        ///< first antiresonance [rad/s]
  double motor_inertia = 1.0;  ///< Im in the model's units
  double r = 0.0, zeta_z = 0.0, zeta_p = 0.0, a = 0.0;
};

/// The design choices behind the gains (normalized units; frequencies relative to ωz).
struct DesignParameters {
  double omega_star = 0.0;            ///< assigned pair's natural frequency ω*/ωz
  double zeta_star = 0.0;             ///< assigned pair's damping
  std::optional<double> r_target;     ///< PID: virtual resonance ratio r̄
  std::optional<double> ms, mt;       ///< peak limits the design respected
  std::string omega_star_source;      ///< "given", "J1 (load bandwidth)", "limited by ‖S‖ <= Ms", ...
};

/// Robustness numbers of the design (absent when not evaluated).
struct RobustnessSummary {
  std::optional<double> rs;  ///< ‖W2 T‖∞ (robust stability when < 1)
  std::optional<double> np;  ///< ‖W1 S‖∞ with W1 = 1/Ms (nominal performance when < 1)
  std::optional<double> rp;  ///< sup(|W1 S| + |W2 T|) (robust performance when < 1)
};

/// The P position loop of a pi+p design (C7.10), normalized units (gains in units of ωz).
struct PositionSummary {
  double kpp_nominal = 0.0;     ///< largest Kpp without overshoot of the load position (‖φl/φ*‖∞ <= 1)
  std::optional<double> kpp_rs;        ///< largest robustly stable Kpp (with W2)
  std::optional<double> kpp_rp_exact;  ///< largest Kpp with the worst-case motor position peak <= 1 (with W2)
  double bandwidth_load = 0.0;  ///< −3 dB bandwidth of φl/φ* at the chosen Kpp (J1)
  double j2 = 0.0;              ///< ‖φl/Tl‖∞ at the chosen Kpp
  double peak_load_tracking = 0.0;  ///< ‖φl/φ*‖∞ at the chosen Kpp
};

/// A tuned cascade controller.
struct Controller {
  Structure structure = Structure::kPi;
  PidGains normalized;                  ///< velocity-loop gains, normalized (kd = tau = 0 for PI)
  PidGains physical;                    ///< the same in the model's units (to_physical)
  std::optional<double> kpp_normalized;  ///< pi+p: position gain, normalized
  std::optional<double> kpp_physical;    ///< pi+p: position gain [1/s]
  PlantScales plant;
  DesignParameters design;
  LoopIndices predicted;                ///< velocity-loop indices, normalized units
  RobustnessSummary robustness;
  std::optional<PositionSummary> position;           ///< pi+p only
  std::optional<core::DiscreteStateSpace> discrete;  ///< the velocity controller at the drive's period
  std::optional<double> prewarp_rad_s;               ///< Tustin prewarp frequency (physical)
  std::vector<std::string> notes;       ///< warnings and facts a user must see
};

/// The 2-DoF velocity controller as a state space with inputs [ω*, ωm] and output u (physical or
/// normalized, as the gains): a PI has the integrator state, a PID also the derivative filter's.
[[nodiscard]] core::StateSpace controller_state_space(const PidGains& gains);

/// Tustin discretization of controller_state_space at the drive period ts [s] (physical gains),
/// prewarped at `prewarp_rad_s` when given (it must lie below π/ts). Throws core::InputError
/// (field "ts") when ts is not finite and > 0 or the prewarp frequency lies at or above Nyquist.
[[nodiscard]] core::DiscreteStateSpace discretize_controller(const PidGains& physical, double ts,
                                                             std::optional<double> prewarp_rad_s = std::nullopt);

}  // namespace servotwin::tuning
