#pragma once
/// \file
/// The 11-state harmonic observer's model and gain designs (dissertation C5.2–C5.4).
///
/// The observer tracks y(t) = z11 + sum_{i=1..5} a_i sin(i*theta + phi_i), theta' = omega, with
/// the internal model A_o(omega) = blockdiag([[0, i omega], [-i omega, 0]] for i = 1..5, 0) and
/// output row C_o = [1 0 1 0 1 0 1 0 1 0 1] (state pair (z_{2i-1}, z_{2i}) = (sin, cos) part of
/// harmonic i, z11 = DC). Its error dynamics are A_o - k C_o (the standard sign; the document's
/// Butterworth section uses A_o + k C_o, so its printed gains are the negatives of these).
///
/// Both gain designs are linear in omega: A_o(omega) = omega A_o(1) and k(omega) = omega k(1), so
/// only the unit-frequency gain k(1) is stored and the observer's shape is the same at every
/// excitation frequency.

#include <Eigen/Dense>
#include <complex>

namespace servotwin::frf {

inline constexpr int kHarmonicCount = 5;    ///< harmonics 1..5 tracked besides the DC level
inline constexpr int kObserverStates = 11;  ///< 2 per harmonic + DC
inline constexpr int kDcState = 10;         ///< index of z11 (0-based)

using ObserverVector = Eigen::Matrix<double, kObserverStates, 1>;
using ObserverMatrix = Eigen::Matrix<double, kObserverStates, kObserverStates>;
using ObserverRow = Eigen::Matrix<double, 1, kObserverStates>;

/// A_o(omega): the internal model of DC plus harmonics 1..5 of omega [rad/s].
ObserverMatrix internal_model(double omega);
/// C_o = [1 0 1 0 1 0 1 0 1 0 1].
ObserverRow output_row();

/// How the unit-frequency gain k(1) is designed.
enum class GainDesign {
  kKalman,       ///< Kalman–Bucy weighting scheme (C5.4), the document's preferred design
  kButterworth,  ///< 11th-order Butterworth pole pattern of radius alpha0 (C5.3)
};

/// Observer design parameters: the estimator bandwidth knob of the RFID block.
struct ObserverDesign {
  GainDesign design = GainDesign::kKalman;
  /// Kalman: measurement-noise intensity V(1) (smaller = wider band). The document's
  /// correspondences V = 0.5, 0.06, 0.02, 0.0085, 0.005 ~ alpha0 = 1, 2, 2.8, 4, 5.
  double v = 0.02;
  /// Butterworth: pole radius relative to omega (recommended 2.8, good range 2.8–3.2).
  double alpha0 = 2.8;
};

/// The document's Kalman weights W = diag{0.4, 0.4, 0.6, 0.6, 0.8, 0.8, 0.9, 0.9, 1, 1, 0.6}
/// (harmonic 1 pair, ..., harmonic 5 pair, DC), with G = I.
ObserverVector default_kalman_weights();

/// k(1) placing the eigenvalues of A_o(1) - k C_o at alpha0 exp(j (2m + 10) pi / 22), m = 1..11.
/// Exact partial-fraction pole placement: the characteristic polynomial is
/// a(s) + sum_i (s k_{2i-1} + i k_{2i}) a(s)/(s^2 + i^2) + k11 a(s)/s with a(s) = s prod(s^2 + i^2),
/// so each gain pair follows from the desired polynomial evaluated at s = j i (and k11 at s = 0).
/// Throws core::InputError (field "alpha0") unless 0 < alpha0 <= 50 and finite.
ObserverVector butterworth_gains(double alpha0);

/// k(1) = Y C_o^T / V with Y the stabilizing solution of
/// A_o(1) Y + Y A_o(1)^T - Y C_o^T V^-1 C_o Y + diag(weights) = 0.
/// With V(omega) = V/omega^2 the gain scales as k(omega) = omega k(1) (C5.4).
/// Throws core::InputError (field "v" or "weights") unless V > 0 and every weight > 0, all finite.
ObserverVector kalman_gains(double v, const ObserverVector& weights = default_kalman_weights());

/// k(1) of a design (validates like the two functions above).
ObserverVector design_gains(const ObserverDesign& design);

/// Transfer functions of the continuous observer at omega = 1 (scale s by 1/omega for others):
/// channel -1 is the output estimate F_yhat_y(s) = C_o (sI - A_o + k C_o)^-1 k; channel 0 is the
/// DC state z11 / y; channel i = 1..5 is the "sin" state z_{2i-1} / y of harmonic i.
std::complex<double> observer_response(const ObserverVector& k1, int channel, std::complex<double> s);

/// Peak gain sup_w |channel(jw)| (the document's J indices: J_yhat, J_DC, J_iw) over
/// [w_min, w_max], found on a log grid of `points` frequencies and refined by golden-section
/// search around the best grid point.
double observer_peak_gain(const ObserverVector& k1, int channel, double w_min = 1e-2, double w_max = 1e3,
                          int points = 20001);

}  // namespace servotwin::frf
