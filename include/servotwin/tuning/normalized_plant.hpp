#pragma once
/// \file
/// The normalized flexible plant that every chapter-7 design works on (seed catalog §0, C7.2,
/// C7.6, C7.16).
///
/// Time is scaled by the first antiresonance ωz (normalized s = s_phys/ωz) and torque by Im·ωz,
/// so that the motor-side design plant reads
///
///   Pm(s) = (1/(s + a)) · (s² + 2ζz s + 1)/(s² + 2ζp r s + r²)        (velocity ωm per torque Tm)
///
/// with r = ωn/ωz (resonance ratio), ζp the fitted pole damping (the frictionless two-mass model
/// has ζp = r·ζz) and a = a_phys/ωz (0 for an integrator). Physical quantities follow from the
/// normalized ones by the de-normalization rules of catalog §0:
/// Kp = Kp_n·Im·ωz, Ki = Ki_n·Im·ωz², Kd = Kd_n·Im, τ = τ_n/ωz, Kpp = Kpp_n·ωz, ω = ω_n·ωz.
/// Because the plant's gain and time scale are divided out, a design in normalized units does
/// not change with the user's units (mm or m, N·m or mN·m, rad/s or Hz).

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::tuning {

/// Known high-frequency dynamics of the loop ("designed without, evaluated with"):
/// current (torque) loop lag, velocity-measurement filter, pure delay and a unit-DC-gain lag
/// p/(s + p) (the fitted model's lag, catalog A6). Absent members contribute 1.
/// Units are seconds and rad/s, or normalized time inside a NormalizedPlant.
struct HfDynamics {
  std::optional<double> current_lag_s;      ///< time constant τc of 1/(τc s + 1) (torque path)
  std::optional<double> feedback_filter_s;  ///< time constant τf of 1/(τf s + 1) (measurement path)
  std::optional<double> delay_s;            ///< pure delay T of e^{−sT} (torque path)
  std::optional<double> lag_pole_rad_s;     ///< pole p of the unit-DC-gain lag p/(s + p) (torque path)

  /// True when no member is set.
  [[nodiscard]] bool empty() const noexcept;
  /// Torque-path response at s = jω: current lag · lag · delay, the delay evaluated exactly.
  [[nodiscard]] std::complex<double> actuator_response(double omega) const noexcept;
  /// Measurement-path response at s = jω (the feedback filter).
  [[nodiscard]] std::complex<double> feedback_response(double omega) const noexcept;
  /// Loop-gain contribution at s = jω: actuator_response · feedback_response.
  [[nodiscard]] std::complex<double> response(double omega) const noexcept;
  /// Rational torque-path part (current lag · lag), unit DC gain; the delay is not rational.
  [[nodiscard]] core::TransferFunction actuator_rational() const;
  /// Rational measurement-path part (the feedback filter), unit DC gain.
  [[nodiscard]] core::TransferFunction feedback_rational() const;
  /// The same dynamics on a time axis scaled by omega_z (time constants and delay times omega_z,
  /// pole divided by omega_z): physical → normalized for omega_z = ωz.
  [[nodiscard]] HfDynamics time_scaled(double omega_z) const;
};

/// Checks every set member (finite, time constants and pole > 0, delay >= 0) and throws
/// core::InputError naming the field under `prefix` (e.g. "hf.delay_s") otherwise.
void validate(const HfDynamics& hf, const std::string& prefix = "hf");

/// The normalized plant (catalog §0, C7.6, C7.16). Build it with normalize() or
/// normalized_two_mass(); the fields are public for analysis code.
struct NormalizedPlant {
  double omega_z = 1.0;        ///< physical time scale ωz [rad/s] (first antiresonance)
  double motor_inertia = 1.0;  ///< physical torque scale Im (from the design model's HF asymptote)
  double r = 0.0;              ///< resonance ratio ωn/ωz of the first mode (> 1: collocated)
  double zeta_z = 0.0;         ///< antiresonance damping ζz of the first mode
  double zeta_p = 0.0;         ///< resonance (pole) damping ζp of the first mode, as fitted
  double a = 0.0;              ///< normalized rigid pole a_phys/ωz (0: integrator)
  /// Modes 2, 3, … in normalized frequency (ω/ωz); empty for a two-mass plant.
  std::vector<fit::Mode> higher_modes;
  fit::OutputKind output = fit::OutputKind::kVelocity;  ///< what the fitted model measured
  HfDynamics hf;  ///< known HF dynamics in normalized time
  /// The higher modes lie in the drive train between motor and load (a chain of inertias: a test
  /// bed, a ball screw with a coupling), so load_estimate() reads them as couplings. False (the
  /// default): where the higher modes sit is unknown (a frame, a machine structure) and a plant
  /// with higher modes has no load side.
  bool chain_load = false;

  /// Motor velocity per motor torque ωm/Tm in normalized units. Without higher modes this is the
  /// design model Pm above. With them, each higher mode enters as the unit-DC-gain factor
  /// (ωi²/ωzi²)(s² + 2ζzi ωzi s + ωzi²)/(s² + 2ζi ωi s + ωi²): their DC gain is already in Im,
  /// so both agree at low frequency. HF dynamics are never included.
  [[nodiscard]] core::TransferFunction motor(bool with_higher_modes = true) const;
  /// Load velocity per motor torque ωl/Tm of the two-mass realization (with viscous friction when
  /// a > 0 or ζp ≠ r ζz): (b s + k)/(k (s + a)(s² + 2ζp r s + r²)), from two_mass_realization()
  /// (an estimate when that is not passive). std::nullopt when there are higher modes or no
  /// two-mass realization exists.
  [[nodiscard]] std::optional<core::TransferFunction> load() const;
  /// Load velocity per motor torque ωl/Tm with the higher modes, over the denominator of
  /// motor(true): load() without higher modes; with them and `chain_load`, load() times, for each
  /// higher mode, the unit-DC-gain factor ωi²(2ζzi s/ωzi + 1)/(s² + 2ζi ωi s + ωi²), which reads
  /// the mode's antiresonance as a coupling toward the load with all its damping in the coupling
  /// (the two-mass shaft relation ωl/ωm = (2ζz ωz s + ωz²)/(s² + 2ζz ωz s + ωz²) applied per mode).
  /// An estimate: a motor-side fit does not say how the chain's modes share the load. std::nullopt
  /// when the first mode has no two-mass realization, or with higher modes and !chain_load.
  [[nodiscard]] std::optional<core::TransferFunction> load_estimate() const;
  /// The plant of the first mode alone: a copy without the higher modes (the known HF dynamics
  /// kept), whose two-mass realization the load side, the LQG and the position loop rest on.
  [[nodiscard]] NormalizedPlant first_mode() const;
  /// The measured output per torque at normalized frequency ω, with higher modes and HF
  /// dynamics: motor(true)(jω) · hf.response(ω), times 1/(jω) for a position output. The
  /// physical response is this divided by Im·ωz (velocity) or Im·ωz² (position) at ω = ω_phys/ωz.
  [[nodiscard]] std::complex<double> measured_response(double omega) const;
  /// The frictionless model's relations hold within `rel`: |ζp − r ζz| <= rel·max(ζp, r ζz) and
  /// the rigid pole is small against the modal decay rate, a <= rel·ζp·r. Only then are the
  /// closed forms of eqs. 7.36/7.63 meaningful for this plant; the numeric pole placement is not
  /// restricted.
  [[nodiscard]] bool frictionless_consistent(double rel = 0.05) const noexcept;
  /// Normalized → physical frequency [rad/s] (ω·ωz).
  [[nodiscard]] double physical_frequency(double omega) const noexcept { return omega * omega_z; }
  /// Normalized → physical time [s] (t/ωz).
  [[nodiscard]] double physical_time(double t) const noexcept { return t / omega_z; }
};

/// One higher mode's unit-DC-gain factor (ωi²/ωzi²)(s² + 2ζzi ωzi s + ωzi²)/(s² + 2ζi ωi s + ωi²),
/// as NormalizedPlant::motor(true) multiplies it in (numerator and denominator as they enter).
[[nodiscard]] core::TransferFunction mode_factor(const fit::Mode& mode);

/// Normalizes a fitted plant model. The first mode (lowest resonance) gives ωz, r,
/// ζz, ζp; the modes are sorted by resonance frequency. Im = 1/(K·Π_{i≥2}(ωzi/ωi)²·g_lag), where
/// g_lag = 1/p is the DC gain of the model's lag 1/(s + p): the lag itself moves into `hf` as
/// p/(s + p), and the model's delay too (added to `hf.delay_s`). `hf` holds further known
/// dynamics in physical units (seconds, rad/s).
///
/// Throws core::InputError (field named) for: a non-positive or non-finite gain; no mode ("not a
/// flexible plant: use a rigid-body tuning"); an unstable pole or a non-minimum-phase zero pair
/// (named with its location); r <= 1.05 ("antiresonance above resonance: non-collocated or
/// mis-fitted"); an unknown output kind; bad `hf` members; a lag pole both in the model and in
/// `hf`.
[[nodiscard]] NormalizedPlant normalize(const fit::PlantModel& model, const HfDynamics& hf = {});

/// A normalized two-mass plant given directly (ωz = Im = 1): the analysis plants of chapter 7.
/// `zeta_p` defaults to the frictionless r·ζz. Same checks (InputError) as normalize().
[[nodiscard]] NormalizedPlant normalized_two_mass(double r, double zeta_z, std::optional<double> zeta_p = {},
                                                  double a = 0.0);

/// Two-mass parameters with viscous friction in normalized units (Im = 1), catalog C3.12/C7.6:
/// Im ω̇m = Tm − bm ωm − b(ωm − ωl) − k∫(ωm − ωl), Il ω̇l = b(ωm − ωl) + k∫(ωm − ωl) − bl ωl.
struct FrictionTwoMass {
  double load_inertia = 0.0;   ///< Il (= k in normalized units)
  double stiffness = 0.0;      ///< k
  double damping = 0.0;        ///< b (shaft)
  double motor_viscous = 0.0;  ///< bm
  double load_viscous = 0.0;   ///< bl

  /// True when every friction term b, bm, bl is >= 0: a passive two-mass system. A realization
  /// that is not passive is still exact for the motor side; its load side is an estimate.
  [[nodiscard]] bool passive() const noexcept;
};

/// Physical two-mass parameters (units of the fitted model: inertia, N·m/rad, N·m·s/rad).
struct PhysicalTwoMass {
  double motor_inertia = 0.0, load_inertia = 0.0, stiffness = 0.0, damping = 0.0, motor_viscous = 0.0,
         load_viscous = 0.0;
};

/// The two-mass realization of the design model Pm (replacing the garbled eqs.
/// 7.73–7.74): k = Il = f, α = (a(r²−1) + 2ζz − 2ζp r)/2, bl = α + ζz f, b = 2ζz f − bl,
/// bm = a r² − bl, with f the positive root of (1−ζz²) f² + (1 − r² + 2aζz r² − 2aζp r − 2αζz) f − α² = 0
/// (the product of the roots is <= 0, so one root is >= 0). b, bl, bm within ±1e-10·(1 + f) of 0
/// are rounding and reported as 0. The realization is unique and exact for Pm whatever the signs
/// of bm and bl: a fit whose antiresonance is damped more than its rigid pole allows (the test
/// beds of catalog A6: ζz = 0.19 with ζp = 0.02 and a ≈ 0) comes out with bl > 0 and bm ≈ −bl.
/// Such a realization is not passive (FrictionTwoMass::passive()) and its load side is an
/// estimate: a motor-side measurement cannot tell where the damping sits. std::nullopt when
/// ζz >= 1, when the plant has higher modes, or when the shaft damping b would be negative (the
/// load would respond with a non-minimum-phase zero: no two-mass reading of the fit at all).
[[nodiscard]] std::optional<FrictionTwoMass> two_mass_realization(const NormalizedPlant& plant);

/// two_mass_realization() when it is passive (b, bl, bm >= 0), else std::nullopt ("not a
/// two-mass system with viscous friction").
[[nodiscard]] std::optional<FrictionTwoMass> physical_parameters_with_friction(const NormalizedPlant& plant);

/// De-normalizes a two-mass realization: Il = f·Im, k = f·Im·ωz², b, bm, bl times Im·ωz.
[[nodiscard]] PhysicalTwoMass to_physical(const FrictionTwoMass& normalized, const NormalizedPlant& plant) noexcept;

}  // namespace servotwin::tuning
