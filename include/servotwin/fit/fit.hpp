#pragma once
/// \file
/// Fitting plant models (plant_model.hpp) to measured frequency responses (catalog C5.7–C5.9),
/// physical two-mass parameters (C3.12) and automatic model-order selection.
///
/// Error measure (C5.9 implementation note): the residual of point l is the complex log ratio
///   e_l = w_l · ln(P_model(jω_l)/P_meas,l) = w_l · (ln|P_model/P_meas| + j·wrap(∠P_model − ∠P_meas)),
/// stacked as (Re, Im). Magnitudes of a drive span decades, so an absolute error would fit only the
/// largest points; the log ratio is the relative complex error (P_model − P_meas)/P_meas to first
/// order, is invariant to the units of the data (mm vs m only changes K), and stays bounded for
/// bad starts (a start with K 1000× too large costs ln 1000, not 1000). Weights: w_l =
/// √2·|P_meas,l|/std_dev_l when every point has a standard deviation (std_dev is the circular
/// complex one, E|δ|² = σ², so Re and Im of e_l then have unit variance and the covariance is
/// absolute), else w_l = 1 and the noise variance is estimated from the residual.
///
/// Parameters are fitted in a transform that keeps every pole stable: θ = (ln|K|, ln a, per mode
/// ln ωz, ln ζz, ln ωp, ln ζp, ln τ2, ln T); the sign of K is fixed by the start.

#include <Eigen/Dense>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {

/// Output kind requested by the user or detected from the data.
enum class OutputChoice { kVelocity, kPosition, kDetect };

/// Result of the output detection from the low-frequency slope.
struct OutputDetection {
  OutputKind output = OutputKind::kVelocity;
  bool detected = false;               ///< false when the user said which
  double slope_db_per_decade = 0.0;    ///< least-squares slope over the low-frequency points (NaN when not measured)
  std::string note;                    ///< e.g. "low-frequency slope -38.7 dB/dec: position output"
};

/// Velocity when the slope of the lowest points (the lowest quarter of the band in log ω, at
/// least 3 points, stopping before the first magnitude extremum) is above −30 dB/dec, position
/// otherwise. Needs 3 points (else velocity, not detected, with a note).
OutputDetection detect_output(const core::FrequencyResponse& response);

/// Fit settings shared by every model order.
struct FitOptions {
  OutputChoice output = OutputChoice::kDetect;
  RigidKind rigid = RigidKind::kRealPole;
  bool lag = false;             ///< fit the extra lag pole 1/(s + τ2)
  bool delay = false;           ///< fit a pure delay e^{-sT}
  /// Where the response was measured: kLoad fits resonances alone, each with the shaft's damping
  /// zero (plant_model.hpp), for a load encoder's response, which has no antiresonance.
  SensorSide sensor = SensorSide::kMotor;
  int max_iterations = 200;     ///< Levenberg–Marquardt iteration limit per start
  std::size_t max_modes = 4;    ///< largest n tried by automatic order selection
  /// fit_plant: after the fit, points whose weighted residual exceeds 4.5 robust standard
  /// deviations (σ from the median residual, Rayleigh; at least the points' own std, or 0.1 %
  /// relative error without std) and isolated (neither neighbour above 3 σ: a run is model
  /// misfit, not a glitch) are outliers: left out (at most a fifth of
  /// the points), listed in FitReport::left_out with their residual, and the model refitted once.
  bool reject_outliers = true;
};

/// A value with its standard deviation (NaN when not identifiable from the data).
struct Estimate {
  double value = 0.0;
  double std = 0.0;
};

/// Standard deviations of the model parameters (delta method from the covariance of θ).
struct ModeUncertainty {
  Estimate antiresonance_omega, antiresonance_zeta, resonance_omega, resonance_zeta;
};

/// Two-mass physical parameters (C3.12) from K = 1/Im (K/τ2 with a lag), ωz, ωn, ζz: Il = Im(r²−1), k = Il ωz²,
/// b = 2 ζz ωz Il, r = ωn/ωz. Units follow the data: with torque input and rad/s output the
/// inertias are in kg·m², k in N·m/rad and b in N·m·s/rad.
struct TwoMassParameters {
  Estimate motor_inertia, load_inertia, stiffness, damping, resonance_ratio;
  /// ζp/(r·ζz): 1 for the frictionless two-mass model (C3.12: ξ/ξz = r); far from 1 means the
  /// damping is not explained by a shaft damper alone.
  double damping_consistency = 0.0;
};

/// Physical parameters or why there are none ("not a two-mass system: ...").
struct PhysicalExtraction {
  std::optional<TwoMassParameters> parameters;
  std::string note;
};

/// Physical parameters of a one-mode model with the covariance of (ln K', ln ωz, ln ζz, ln ωn)
/// (4×4; NaN entries give NaN standard deviations), K' = K, or K/τ2 when the model has a lag
/// 1/(s + τ2) (the lag's DC gain belongs to 1/Im). Valid only for a one-mode model with K > 0 and
/// r = ωn/ωz > 1 (antiresonance below resonance, collocated measurement).
PhysicalExtraction two_mass_parameters(const PlantModel& model, const Eigen::Matrix4d& log_covariance);

/// Result of fitting one model order.
struct FitResult {
  PlantModel model;
  bool converged = false;
  std::string message;                ///< LM stopping reason, or why the fit failed
  std::string initialization;         ///< start that won: "three-point", "peak-picking" or "rigid"
  std::string weighting;              ///< "std_dev" or "log-relative"
  std::size_t points = 0;
  std::size_t parameters = 0;
  int iterations = 0;                 ///< LM iterations of the winning start
  double cost = 0.0;                  ///< ½ Σ |e_l|² at the solution
  double rms_log_error = 0.0;         ///< sqrt(Σ|ln(P_model/P_meas)|²/m), unweighted (0.01 ≈ 1 %)
  double sigma2 = 0.0;                ///< residual variance used for the covariance (1 when std_dev given)
  /// Factor the covariance was multiplied by so that the standard deviations reflect the misfit
  /// (issue 25 §2; 1 = the covariance of the noise alone). Rule: with measured std_dev, when the
  /// reduced χ² s = ‖r‖²/(2m − p) exceeds the noise level (s > 1 + 3·sqrt(2/(2m − p))), the model
  /// error dominates: factor = s·κ; without std_dev (the covariance already scaled by s), factor =
  /// κ when the residuals are significantly correlated (ρ1 > 2/sqrt(m)); else 1. κ = (1 + ρ1)/
  /// (1 − ρ1), ρ1 in [0, 0.98] the lag-one autocorrelation of the residuals along frequency: a
  /// smooth, systematic misfit leaves fewer independent residuals than points (the effective
  /// sample size of an AR(1) sequence, m(1 − ρ1)/(1 + ρ1)).
  double uncertainty_scale = 1.0;
  std::string uncertainty_note;       ///< why the factor is not 1 (empty when it is)
  std::vector<std::string> parameter_names;  ///< names of θ ("ln_gain", "ln_rigid_pole", "mode1.ln_wz", ...)
  Eigen::VectorXd theta;
  Eigen::MatrixXd covariance;         ///< covariance of θ (NaN where not identifiable)
  Estimate gain, rigid_pole_rad_s, lag_pole_rad_s, delay_s;
  std::vector<ModeUncertainty> mode_estimates;
  PhysicalExtraction physical;
};

/// Fits a model with `modes` flexible modes and the given output kind (not detected here).
/// Starts: the three-point interpolation (one mode) and peak picking; a rigid start for n = 0.
/// Each start is completed (K in closed form, a and τ2 on a grid, T from the phase slope) and
/// refined by LM; the lowest cost wins. Throws core::InputError for invalid data (named point and
/// field) or too few points for the model; returns converged = false with a message when LM fails.
FitResult fit_model(const core::FrequencyResponse& response, std::size_t modes, OutputKind output,
                    const FitOptions& options);

/// Refines a given start (its structure: modes, rigid kind, lag, delay, output) by LM without the
/// automatic starts, e.g. to reproduce the catalog's E10 run from a deliberately bad start.
/// Throws core::InputError for invalid data or too few points.
FitResult refine_model(const core::FrequencyResponse& response, const PlantModel& start, const FitOptions& options);

/// What the user asked for.
struct ModelRequest {
  enum class Kind { kTwoMass, kModes, kAuto } kind = Kind::kTwoMass;
  std::size_t modes = 1;  ///< for kModes
};
/// Parses "two-mass", "modes:N" (N ≥ 0) or "auto"; core::InputError naming `option` otherwise.
ModelRequest parse_model_request(const std::string& text, const std::string& option = "--model");
/// "two-mass", "modes:N", "auto".
std::string to_string(const ModelRequest& request);

/// One model order tried by the selection.
struct SelectionCandidate {
  std::size_t modes = 0;
  std::size_t parameters = 0;
  bool converged = false;
  double cost = 0.0;
  double score = 0.0;  ///< BIC or reduced χ², see `criterion`
  std::string message;
};

/// How the model order was chosen.
struct Selection {
  std::string method;        ///< "fixed" or "auto"
  std::string criterion;     ///< stated rule, e.g. "BIC = N ln(RSS/N) + p ln N over N = 2m residuals"
  std::vector<SelectionCandidate> candidates;
  std::size_t chosen = 0;
};

/// Everything `servotwin fit` reports.
struct FitReport {
  FitResult result;
  Selection selection;
  OutputDetection output;
  ModelRequest request;
  /// Points marked invalid by the measurement (FrequencyPoint::valid, issue 25 §1) or rejected by
  /// the outlier rule (FitOptions::reject_outliers), left out of the fit: "1 Hz: THD 0.39 above
  /// 0.07 ...", "3.2 Hz: outlier: residual 7.1 robust sigma ...", in frequency order.
  std::vector<std::string> left_out;
  /// The frequencies of `left_out`, in the same order (for fits that build on this one, such as
  /// the fit with Coulomb friction, which must use the same points).
  std::vector<double> left_out_hz;
};

/// Automatic order selection (kAuto) tries n = 0 .. min(max_modes, resonances found by peak
/// picking, largest n the point count allows). Criterion: when every point has a standard
/// deviation, the smallest n whose reduced χ² = 2·cost/(2m−p) is within the noise level
/// (≤ 1 + 3·sqrt(2/(2m−p))); otherwise, or when no n reaches the noise level, the smallest
/// BIC = 2m·ln(RSS/2m) + p·ln(2m) with RSS floored at 2m·1e-18 (relative errors below 1e-9 are
/// rounding). Throws core::InputError when the data are invalid, too short for the request, or
/// when the chosen fit does not converge (the message names the model and the LM status).
FitReport fit_plant(const core::FrequencyResponse& response, const ModelRequest& request,
                    const FitOptions& options = {});

/// Every fitting entry point (fit_plant, fit_model, refine_model, detect_output) uses only the
/// points marked valid; a response with fewer valid points than the model needs is refused as
/// too short.

/// Validates a response for fitting: at least one point, finite positive strictly increasing
/// frequencies, finite non-zero values, finite non-negative std_dev. core::InputError names the
/// point ("points[3].freq_hz") otherwise.
void validate_response(const core::FrequencyResponse& response);

}  // namespace servotwin::fit
