#pragma once
/// \file
/// A P position loop over a closed velocity loop (seed catalog C7.10). The
/// position controller ω* = Kpp (φ* − φm) feeds the velocity reference of any velocity loop given by
/// its closed-loop functions (a PI/PID VelocityLoop here; an LQG or H∞ loop later):
///
///   Lpn = Kpp Tvn/s,  Spn = 1/(1 + Lpn),  Tpn = Lpn Spn  (motor position φm/φ*),
///   φl/φ* = Kpp Tvl/s · Spn,   φl/Tl = (Gld − Tvl (Kpp/s) Gmd Spn)/s,
///
/// with Tvn = ωm/ω*, Tvl = ωl/ω*, Gmd = ωm/Tl, Gld = ωl/Tl of the velocity loop and T its
/// complementary sensitivity (T = Tvn for a 1-DoF loop).
///
/// Uncertainty P = Pn(1 + Δ W2), ‖Δ‖∞ < 1, as in uncertainty.hpp. With it the motor-position loop is
///
///   Tp(Δ) = Kpp Tvn (1 + Δ W2) / (s + Kpp Tvn + Δ W2 (s T + Kpp Tvn)),
///
/// so the cascade is robustly stable iff it is nominally stable and ‖W2 (T Spn + Tpn)‖∞ < 1. The
/// catalog prints ‖W2 Tvn Spn − W2 Tpn‖∞; for a 1-DoF loop (Tvn = T) the two are W2 T (s ± Kpp)/(s +
/// Kpp T) and have the same modulus on s = jω, so the sign slip is harmless there; for a 2-DoF loop
/// only the derived form is right. The printed sufficient RP test Kpp(|Tvn| + |W2 Tvn|) <=
/// |jω + Kpp Tvn| − |W2 Tvn|·|jω + Kpp| is the triangle-inequality bound of |Tp(Δ)| <= 1 (1-DoF);
/// worst_case_motor_tracking() evaluates sup_{|Δ|<=1} |Tp(Δ)| exactly (the image of the unit disk
/// under the Möbius map Δ ↦ Tp(Δ) is a disk).
///
/// Note on the sufficient test: with integral action and W2 = k s/(s + p) it holds with equality at
/// ω = 0 and its margin is −2 (k/p) Kpp ω + ω²/(2 Kpp) + … near 0, so it fails for EVERY Kpp > 0 at
/// small enough ω (and everywhere near 0 when W2(0) > 0); the largest passing Kpp is set by the grid's
/// lower end, ≈ sqrt(ω_min p/(4k)). It is implemented as printed, on the grid [omega_min, omega_max];
/// the exact worst case has no such artefact.

#include <complex>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {

/// A closed velocity loop as the position loop sees it (normalized frequency ω >= 0).
struct VelocityLoopFunctions {
  std::function<std::complex<double>(double)> motor_tracking;  ///< Tvn = ωm/ω*
  std::function<std::complex<double>(double)> complementary;   ///< T (= Tvn for 1-DoF)
  /// Load side (std::function empty when the loop has none).
  std::function<std::complex<double>(double)> load_tracking;           ///< Tvl = ωl/ω*
  std::function<std::complex<double>(double)> motor_from_load_torque;  ///< Gmd = ωm/Tl
  std::function<std::complex<double>(double)> load_from_load_torque;   ///< Gld = ωl/Tl
  /// Rational Tvn (delays as Padé approximants) for the Routh stability test of the cascade.
  core::TransferFunction motor_tracking_rational{core::Polynomial{1.0}, core::Polynomial{1.0}};
  /// Frequencies to add to every grid (lightly damped closed-loop poles).
  std::vector<double> critical_frequencies;
};

/// The functions of a VelocityLoop (it must outlive the result: the functions refer to it).
[[nodiscard]] VelocityLoopFunctions functions_of(const VelocityLoop& loop);

/// Grid and search settings.
struct PositionLoopOptions {
  double omega_min = 1e-3;  ///< normalized grid start (matters for the sufficient RP test, see above)
  double omega_max = 1e3;
  std::size_t grid_points = 800;
  double rel_tol = 1e-7;       ///< peak refinement
  double peak_limit = 1.0;     ///< J1 constraint ‖φl/φ*‖∞ <= peak_limit (1: no overshoot)
  double kpp_min = 1e-4;       ///< Kpp scan range (normalized, units of ωz)
  double kpp_max = 1e2;
  std::size_t scan_points = 60;
};

/// Largest gains found (0 when even kpp_min fails) and the indices at the nominal one.
struct PositionLoopDesign {
  double kpp_nominal = 0.0;      ///< largest Kpp with a stable cascade and ‖φl/φ*‖∞ <= peak_limit
  double kpp_rs = 0.0;           ///< largest robustly stable Kpp (needs W2)
  double kpp_rp = 0.0;           ///< largest Kpp passing the printed sufficient RP test (grid-bound, see file note)
  double kpp_rp_exact = 0.0;     ///< largest Kpp with sup_ω sup_Δ |Tp(Δ)| <= 1 (exact worst case)
  double j1 = 0.0;               ///< −3 dB bandwidth of φl/φ* at kpp_nominal (0 when none)
  double j2 = 0.0;               ///< ‖φl/Tl‖∞ at kpp_nominal
  double peak_load_tracking = 0.0;  ///< ‖φl/φ*‖∞ at kpp_nominal
};

/// The P position loop over one velocity loop, with an optional uncertainty weight (normalized time).
class PositionLoop {
 public:
  /// InputError naming "w2" for an improper or unstable weight, and "options.*" for a bad grid or
  /// scan range.
  PositionLoop(VelocityLoopFunctions velocity, std::optional<core::TransferFunction> w2,
               const PositionLoopOptions& options = {});

  [[nodiscard]] bool has_load() const noexcept { return static_cast<bool>(v_.load_tracking); }

  [[nodiscard]] std::complex<double> loop_gain(double omega, double kpp) const;        ///< Lpn
  [[nodiscard]] std::complex<double> motor_tracking(double omega, double kpp) const;   ///< Tpn = φm/φ*
  [[nodiscard]] std::complex<double> load_tracking(double omega, double kpp) const;    ///< φl/φ* (NaN without load)
  [[nodiscard]] std::complex<double> load_from_load_torque(double omega, double kpp) const;  ///< φl/Tl
  /// W2 (T Spn + Tpn) (NaN without W2).
  [[nodiscard]] std::complex<double> robust_stability_function(double omega, double kpp) const;
  /// The printed form W2 Tvn Spn − W2 Tpn (for comparison with the catalog only).
  [[nodiscard]] std::complex<double> printed_robust_stability_function(double omega, double kpp) const;
  /// RHS − LHS of the printed sufficient RP inequality at ω (>= 0: passes there).
  [[nodiscard]] double sufficient_rp_margin(double omega, double kpp) const;
  /// sup_{|Δ|<=1} |Tp(Δ)(jω)|; +inf when some Δ makes the loop singular there (|D| >= |C|).
  [[nodiscard]] double worst_case_motor_tracking(double omega, double kpp) const;

  /// Routh test of s·den(Tvn) + Kpp·num(Tvn).
  [[nodiscard]] bool stable(double kpp) const;
  [[nodiscard]] double load_tracking_peak(double kpp) const;   ///< ‖φl/φ*‖∞
  [[nodiscard]] double load_disturbance_peak(double kpp) const;  ///< ‖φl/Tl‖∞ (J2)
  [[nodiscard]] std::optional<double> load_bandwidth(double kpp) const;  ///< −3 dB of φl/φ* (J1)
  [[nodiscard]] double robust_stability_peak(double kpp) const;  ///< ‖W2 (T Spn + Tpn)‖∞
  [[nodiscard]] double sufficient_rp_min_margin(double kpp) const;  ///< min over the grid of the margin
  [[nodiscard]] double worst_case_peak(double kpp) const;  ///< sup_ω worst_case_motor_tracking

  /// The largest Kpp of each criterion: scan of the log grid [kpp_min, kpp_max] upwards to the first
  /// failure, then bisection to 1e-6 relative. kpp_rs, kpp_rp, kpp_rp_exact are 0 without W2;
  /// kpp_nominal, j1, j2 are 0 without a load side.
  [[nodiscard]] PositionLoopDesign design() const;
  /// One of the searches: the largest Kpp in the scan range where pass(Kpp) holds, as design().
  [[nodiscard]] double largest_kpp(const std::function<bool(double)>& pass) const;

 private:
  [[nodiscard]] std::vector<double> grid() const;
  [[nodiscard]] double peak(const std::function<std::complex<double>(double)>& f) const;

  VelocityLoopFunctions v_;
  std::optional<core::TransferFunction> w2_;
  PositionLoopOptions options_;
  std::vector<double> grid_;
};

/// Rational position-loop transfer functions by TF algebra on the velocity loop's rational closed
/// loop (all over the velocity loop's Δ; no common factor cancelled):
/// φl/φ* = Kpp nl/(s Δ + Kpp nm) and φl/Tl = [nld (s Δ + Kpp nm) − Kpp nl nmd]/(s Δ (s Δ + Kpp nm)).
struct PositionClosedLoop {
  core::Polynomial characteristic;            ///< s Δ + Kpp nm
  core::TransferFunction motor_tracking;      ///< φm/φ*
  core::TransferFunction load_tracking;       ///< φl/φ*
  core::TransferFunction load_from_load_torque;  ///< φl/Tl (Tl opposes the motion)
};
/// std::invalid_argument when the closed loop has no load side.
[[nodiscard]] PositionClosedLoop position_closed_loop(const ClosedLoopTransfer& velocity, double kpp);

/// Eq. 7.110 (catalog C7.10) in the two-mass parameters with friction (normalized: Im = 1) for a
/// PI velocity loop (kd = 0) with proportional setpoint weight wp, no HF dynamics:
///   φl/φ* = Kpp (b s + k)(wp Kp s + Ki) / Σ a_i s^i,
///   φl/Tl = −(Im s³ + (b + bm + Kp) s² + (k + wp Kpp Kp + Ki) s + Ki Kpp) / Σ a_i s^i,
/// with the printed a5 … a0 in which every product Kpp·Kp carries the weight wp (the printed a_i are
/// the wp = 1 case, although the printed numerator has wp) and the sign of φl/Tl negative because Tl
/// opposes the motion (Il ω̇l = Ts − Tl). Derivation: with Z = b s + k and Q = Kp s² + (wp Kpp Kp + Ki) s
/// + Ki Kpp the equations of motion give φl/Tl = −(s M)/((Il s² + bl s + Z)(s M) − s Z²), s M = Im s³
/// + bm s² + Z s + Q; the tests compare both against position_closed_loop().
struct PositionClosedForm {
  core::TransferFunction load_tracking;
  core::TransferFunction load_from_load_torque;
};
[[nodiscard]] PositionClosedForm position_closed_form(const FrictionTwoMass& plant, const PidGains& gains, double kpp);

}  // namespace servotwin::tuning
