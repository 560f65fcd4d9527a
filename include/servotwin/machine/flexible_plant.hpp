#pragma once
/// \file
/// Torque-driven flexible plants to identify and control: a chain of n masses (n = 2 is the
/// two-mass plant of seed2 catalog C3.12, n = 1 a rigid axis) with shaft stiffness and damping
/// between neighbours, viscous friction per mass, Karnopp Coulomb friction with stiction per mass
/// (C5.10), backlash as a dead zone in any shaft (C5.10), a first-order current-loop lag on the
/// torque command (C3.2), a pure input delay, and encoder quantization plus seeded Gaussian noise
/// on the measured output; or a plant given only as a rational transfer function (the 5th-order
/// demo plant of E14, the test-bed models of E37) with the same actuator and sensor chain.
///
/// Units are SI and rotary (kg m^2, N m/rad, N m s/rad, N m, rad, rad/s, s); the linear-motion
/// equivalents (kg, N/m, N s/m, N, m, m/s) work unchanged (C3.12: m<->I, F<->T, x<->phi).
///
/// Sign conventions. Mass i has angle phi_i and velocity w_i; the torque command drives mass 1
/// (the motor); the last mass is the load. Shaft i couples mass i and i+1 with the twist
/// u_i = phi_i - phi_{i+1}; its torque T_i acts as -T_i on mass i and +T_i on mass i+1:
///   without backlash   T_i = k_i u_i + b_i u_i'
///   with backlash D_i  T_i = k_i (u_i - D_i/2) + b_i u_i'  for u_i >  D_i/2 (contact +)
///                      T_i = 0                             for |u_i| <= D_i/2 (gap)
///                      T_i = k_i (u_i + D_i/2) + b_i u_i'  for u_i < -D_i/2 (contact -)
/// (the dead zone of C5.10; the shaft damper acts only in contact, a free gap transmits nothing).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <Eigen/Dense>

#include "servotwin/core/state_space.hpp"
#include "servotwin/machine/flexible_frame.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace servotwin::machine {

namespace detail {
class GaussianSource;
}  // namespace detail

/// Which signal the plant measures (and which signal a transfer-function plant produces).
enum class PlantOutput { MotorVelocity, MotorPosition, LoadVelocity, LoadPosition };

/// "motor_velocity", "motor_position", "load_velocity", "load_position".
std::string_view to_string(PlantOutput output) noexcept;
/// Inverse of to_string; std::nullopt for any other text.
std::optional<PlantOutput> plant_output_from_string(std::string_view text) noexcept;

/// Karnopp friction of one mass (C5.10), with Te = every other torque acting on the mass:
///   |w| <= stick_band and |Te| <  stiction: the mass sticks (w = 0 exactly, friction = Te);
///   |w| <= stick_band and |Te| >= stiction: breakaway, friction = stiction sign(Te) opposing Te;
///   |w| >  stick_band:                    sliding, friction = coulomb sign(w) opposing w.
/// stiction >= coulomb >= 0; stiction defaults to coulomb. stick_band = 0 is allowed: a sliding
/// mass whose velocity reverses inside an integration step is stopped there and the stick test
/// decides, so the velocity never chatters around zero.
struct KarnoppFriction {
  double coulomb = 0.0;                 ///< TC [N m], >= 0
  std::optional<double> stiction;       ///< TS [N m], >= coulomb; empty = coulomb
  double stick_band = 0.0;              ///< dv [rad/s], >= 0

  [[nodiscard]] double static_level() const noexcept { return stiction.value_or(coulomb); }
  [[nodiscard]] bool active() const noexcept { return static_level() > 0.0; }
};

/// The mechanics of a chain of n >= 1 masses (index 0 = motor, n-1 = load).
struct MassChain {
  std::vector<double> inertia;    ///< n values > 0
  std::vector<double> stiffness;  ///< n-1 shaft stiffnesses > 0
  std::vector<double> damping;    ///< n-1 shaft dampings >= 0 (empty = all 0)
  std::vector<double> viscous;    ///< n viscous frictions to ground >= 0 (empty = all 0)
  std::vector<KarnoppFriction> friction;  ///< n Karnopp frictions (empty = none)
  std::vector<double> backlash;   ///< n-1 dead-zone widths D >= 0 (empty = none)

  [[nodiscard]] std::size_t masses() const noexcept { return inertia.size(); }
  /// Each optional vector read with 0 / no friction for its missing entries.
  [[nodiscard]] double damping_of(std::size_t shaft) const noexcept;
  [[nodiscard]] double viscous_of(std::size_t mass) const noexcept;
  [[nodiscard]] double backlash_of(std::size_t shaft) const noexcept;
  [[nodiscard]] KarnoppFriction friction_of(std::size_t mass) const noexcept;
};

/// Builds the two-mass chain of C3.12: motor Im, load Il, shaft k and b, viscous bm and bl.
MassChain two_mass(double motor_inertia, double load_inertia, double stiffness, double damping,
                   double motor_viscous = 0.0, double load_viscous = 0.0);

/// A plant known only by its rational transfer function from torque command to `output`
/// (proper; stable or with poles on the imaginary axis, e.g. the integrator of a position output).
struct TransferFunctionModel {
  core::TransferFunction tf{core::Polynomial{1.0}, core::Polynomial{1.0}};
};

/// Actuator, sampling and sensor settings shared by both plant kinds.
struct PlantSettings {
  double ts = 0.0;                 ///< sample period [s] > 0; the command is held over each period
  double current_lag = 0.0;        ///< first-order current-loop time constant tau_i [s] >= 0 (0 = none): T/T* = 1/(tau_i s + 1)
  int delay_samples = 0;           ///< pure input delay [samples] >= 0 (at most 100000)
  PlantOutput output = PlantOutput::MotorVelocity;  ///< the measured signal y
  double noise_std = 0.0;          ///< white Gaussian noise on y (output units) >= 0
  double quantization = 0.0;       ///< step of y (output units) >= 0; 0 = off: y = q round((x + n)/q)
  std::uint64_t seed = 1;          ///< noise seed; equal seeds give equal noise
  int substeps = 0;                ///< integration steps per sample when friction or backlash is present; 0 = automatic
};

/// A complete plant description (what the plant JSON file holds).
struct PlantConfig {
  std::string name;
  std::string description;
  std::variant<MassChain, TransferFunctionModel> model;
  PlantSettings settings;
  /// The four-mass frame a transfer-function model was made from (flexible_frame.hpp: the model is
  /// its rotor velocity, eq. 7.172): what the frame's load- and stator-force test needs. Empty for
  /// every other plant.
  std::optional<FlexibleFrame> frame;
};

/// Checks every field; throws core::InputError naming the field (e.g. "inertia[1]",
/// "settings.ts", "den") and the expectation. Called by FlexiblePlant's constructor.
void validate(const PlantConfig& config);

// ---- linear models -------------------------------------------------------------------------

/// Linear state space of the chain (backlash closed, Coulomb friction left out, no current lag):
/// states [phi_1, w_1, ..., phi_n, w_n], input the motor torque, outputs
/// [motor position, motor velocity, load position, load velocity]. Throws core::InputError for
/// an invalid chain.
core::StateSpace mass_chain_state_space(const MassChain& chain);

/// Transfer function from motor torque to `output` of the linear chain (as above), computed
/// exactly with polynomials from the tridiagonal dynamic stiffness matrix
/// Z(s) = M s^2 + B s + K by the continuant recursion: phi_j / T = prod_{i<j} (b_i s + k_i)
/// * det Z_{j+1..n} / det Z. No mass is tied to ground by a spring, so det Z(0) = det K = 0 and
/// det Z = s Q(s) exactly: the factor s is removed by construction (not by numerical
/// cancellation), so phi/T = N/(s Q) and w/T = N/Q carry no s/s pair.
core::TransferFunction mass_chain_transfer_function(const MassChain& chain, PlantOutput output);

/// The closed-form two-mass quantities of C3.12 (frictionless formulas; shaft damping b only).
struct TwoMassParameters {
  double omega_n = 0.0;  ///< resonance sqrt(k (Il + Im) / (Il Im)) [rad/s]
  double omega_z = 0.0;  ///< antiresonance sqrt(k / Il) [rad/s]
  double zeta = 0.0;     ///< resonance damping sqrt(b^2 (Il + Im) / (4 k Il Im))
  double zeta_z = 0.0;   ///< antiresonance damping sqrt(b^2 / (4 k Il))
  double r = 0.0;        ///< resonance ratio omega_n / omega_z = sqrt(1 + Il/Im)
  double k1 = 0.0;       ///< motor-side gain 1/Im
  double k2 = 0.0;       ///< load-side gain b / (Im Il)
};
/// From Im, Il, k > 0 and b >= 0 (throws core::InputError otherwise).
TwoMassParameters two_mass_parameters(double motor_inertia, double load_inertia, double stiffness, double damping);
/// From a chain of exactly two masses (throws core::InputError otherwise).
TwoMassParameters two_mass_parameters(const MassChain& chain);

/// One mode of the chain (C3.13).
struct ChainMode {
  double omega = 0.0;      ///< undamped natural frequency [rad/s] (0 for the rigid-body mode)
  double zeta = 0.0;       ///< modal damping phi^T B phi / (2 omega) (0 for the rigid-body mode)
  Eigen::VectorXd shape;   ///< mass-normalised shape: phi^T M phi = 1, first nonzero entry > 0
};
/// Modes from det(K - omega^2 M) = 0 (generalized symmetric eigenproblem, ascending omega).
/// B = shaft dampings + viscous frictions. The modal damping is exact when B is Rayleigh
/// (B = alpha M + beta K: then phi^T B phi is diagonal); otherwise it is the usual
/// diagonal-projection estimate, and the exact damped poles are the eigenvalues of
/// mass_chain_state_space(chain).A.
std::vector<ChainMode> chain_modes(const MassChain& chain);

// ---- the sampled plant ---------------------------------------------------------------------

/// What the plant reports after a sample.
struct PlantMeasurement {
  double y = 0.0;         ///< measured output: exact value + noise, then quantized
  double y_exact = 0.0;   ///< noise-free, unquantized value of the output
  /// True physical states at the sample instant (NaN for a transfer-function plant).
  double motor_position = 0.0, motor_velocity = 0.0, load_position = 0.0, load_velocity = 0.0;
};

/// A sampled plant: step(u) holds the torque command u over one period and returns the
/// measurement at the end of the period.
///
/// Integration. The linear part is exact: with no friction and no backlash one step is the
/// zero-order-hold transition exp(A ts) of the whole linear system (chain + current lag), as
/// core::discretize_zoh computes it, so the samples equal scipy.signal.cont2discrete/dlsim.
/// With Karnopp friction or backlash the dynamics are piecewise linear: between switching
/// events each mass is either stuck (pinned: phi, w constant) or sliding under a constant
/// friction torque, and each backlash shaft is either in contact (linear spring with a constant
/// offset torque k D/2) or in its gap (no coupling). Every combination of these regimes is a
/// linear system with constant inputs, which is integrated exactly by its own precomputed
/// zero-order-hold matrices. The sample is split into `substeps` equal steps; at the start of
/// each the regime is determined from the state (stick test, gap test), and within it the
/// solution is exact unless a switch happens inside it, so the only error is the timing of
/// switching events (at most one sub-step). Compared with a general ODE solver on the
/// discontinuous right-hand side this keeps linear accuracy regardless of step size, holds a
/// stuck mass exactly still (no chatter, no drift), keeps a load exactly still while the
/// backlash gap is open, needs no step-size control on the hot path, and costs one small
/// matrix-vector product per sub-step. A velocity sign reversal of a sliding mass inside a
/// sub-step stops it (w = 0) for the stick test of the next sub-step.
///
/// Automatic sub-steps: none for a linear plant; otherwise the smallest count with
/// omega_max h <= 0.05 (h = ts / substeps, omega_max the highest undamped chain frequency) and
/// at least 8, at most 4096.
///
/// Measurement: y of the configured output, plus N(0, noise_std^2) noise (std::mt19937_64
/// seeded via splitmix64 of `seed`, Box-Muller, as machine/simulator.hpp documents), then
/// quantized to `quantization`. Delay: the command given at step k reaches the current loop at
/// step k + delay_samples (zero before).
///
/// step() is allocation-free and exception-free; construction validates (core::InputError)
/// and precomputes everything.
class FlexiblePlant {
 public:
  explicit FlexiblePlant(const PlantConfig& config);
  ~FlexiblePlant();
  FlexiblePlant(FlexiblePlant&&) noexcept;
  FlexiblePlant& operator=(FlexiblePlant&&) noexcept;
  FlexiblePlant(const FlexiblePlant&) = delete;
  FlexiblePlant& operator=(const FlexiblePlant&) = delete;

  /// Holds the torque command over one period [k ts, (k+1) ts) and returns the measurement at
  /// (k+1) ts. Non-finite commands are treated as 0 (the hot path has no error channel).
  ///
  /// `load_torque` is an external torque Tl on the last mass (the load), held over the period
  /// like the command and not delayed; it opposes the motion as the dissertation writes it:
  /// I_n w_n' = T_shaft - Tl - friction (so a positive Tl decelerates a load moving forward).
  /// A transfer-function plant has no load and ignores it.
  PlantMeasurement step(double torque_command, double load_torque = 0.0) noexcept;

  /// Measurement of the current state without advancing (draws new noise).
  PlantMeasurement measure() noexcept;

  /// Back to rest at zero (positions, velocities, lag, delay line); the noise stream restarts.
  void reset() noexcept;

  /// Sets the chain state (n angles, n velocities; current-lag torque to 0). Masses with
  /// friction whose velocity is inside the stick band are treated by the stick test at the next
  /// step. Throws core::InputError for wrong sizes or a transfer-function plant.
  void set_chain_state(const Eigen::VectorXd& angles, const Eigen::VectorXd& velocities);

  /// Torque transmitted by shaft i at the current state (dead zone included): T_i of the
  /// header comment. Throws core::InputError for a bad index or a transfer-function plant.
  [[nodiscard]] double shaft_torque(std::size_t shaft) const;

  /// Linear model from torque command to the configured output, including the current-loop lag
  /// (not the pure delay, which is not rational: it is delay_samples() whole samples).
  [[nodiscard]] core::TransferFunction transfer_function() const;
  /// Same for any output of a mass chain (throws core::InputError for a TF plant).
  [[nodiscard]] core::TransferFunction transfer_function(PlantOutput output) const;

  [[nodiscard]] const PlantConfig& config() const noexcept { return config_; }
  [[nodiscard]] double ts() const noexcept { return config_.settings.ts; }
  [[nodiscard]] int delay_samples() const noexcept { return config_.settings.delay_samples; }
  [[nodiscard]] bool is_linear() const noexcept { return !nonlinear_; }
  [[nodiscard]] int substeps() const noexcept { return substeps_; }
  /// Masses currently stuck by friction (bit i = mass i); 0 for linear plants.
  [[nodiscard]] std::uint64_t stuck_mask() const noexcept { return stuck_; }

 private:
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  void build_mass_chain(const MassChain& chain);
  void build_transfer_function(const core::TransferFunction& tf);
  void advance_linear(double u, double load) noexcept;
  void advance_nonlinear(double u, double load) noexcept;
  [[nodiscard]] double external_torque(std::size_t mass, double u, double load) const noexcept;
  [[nodiscard]] double exact_output() const noexcept;
  [[nodiscard]] PlantMeasurement make_measurement(double y_exact) noexcept;
  [[nodiscard]] double next_noise() noexcept;

  PlantConfig config_;
  bool chain_ = false;        // mass chain (else transfer function)
  bool nonlinear_ = false;
  std::size_t n_ = 0;         // masses
  Eigen::Index states_ = 0;   // 2n (+1 with current lag) or TF order
  Eigen::Index lag_index_ = -1;
  int substeps_ = 1;

  // Linear step: x <- ab_ [x; u] (one period); a chain's ab_ has a last column for the load torque.
  RowMatrix ab_;
  Eigen::RowVectorXd c_;      // output row (TF plant; chain outputs are read from the state)
  double d_ = 0.0;            // TF feedthrough

  // Nonlinear sub-step: per regime r, x <- phi_[r] x + gamma_[r] [u; f_1..f_n].
  std::vector<RowMatrix> regime_;     // [Phi Gamma] per regime
  std::vector<std::size_t> friction_masses_;  // masses with active friction (regime bits 0..)
  std::vector<std::size_t> backlash_shafts_;  // shafts with backlash (regime bits after friction)
  std::vector<double> inertia_, stiffness_, shaft_damping_, viscous_, half_gap_;
  std::vector<KarnoppFriction> friction_;

  // Run-time state.
  Eigen::VectorXd x_, xw_, next_;
  std::vector<double> delay_line_;
  std::size_t delay_pos_ = 0;
  std::uint64_t stuck_ = 0;
  double last_u_ = 0.0;       // command held over the last period (TF feedthrough)

  // Noise source (splitmix64-seeded mt19937_64 + Box-Muller, src/machine/gaussian.hpp).
  std::unique_ptr<detail::GaussianSource> noise_;
};

}  // namespace servotwin::machine
