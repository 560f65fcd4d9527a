#pragma once
/// \file
/// The rapid-identification regression (thesis Eq. 3.9-3.11): from commanded and actual position
/// x_r, x sampled at ts, the closed-loop axis model of Eq. 3.3 is linear in
///   theta = (alpha_i, alpha_1, alpha_2, beta_0, beta_1, beta_2, delta+, delta-)
/// with regressor columns, in this order and sign,
///   e_i, -xdot, -xddot, x_r, xdot_r, xddot_r, -PV, -NV      and output y = x,
/// where e_i = ts * sum(x_r - x) is the integrated tracking error, derivatives are central
/// differences (xdot_k = (x_{k+1} - x_{k-1})/(2 ts), xddot_k = (xdot_{k+1} - xdot_{k-1})/(2 ts)) and
/// PV/NV are 1 while the measured velocity is above +deadband / below -deadband. (The printed
/// Eq. 3.11 lost x_r and repeats xdot_r; the order above is the right one.)
///
/// The problem is accumulated in one streaming pass into the upper-triangular factor U of the
/// augmented matrix [Phi y] (U^T U = [Phi y]^T [Phi y]) by blocked Householder QR updates, so the
/// squared condition number of the normal equations is never formed on raw data. The normal
/// equations P = Phi^T Phi, R = Phi^T y, Gamma = y^T y are derived from U for export.

#include <Eigen/Dense>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/core/capture.hpp"

namespace servotwin::rapid {

inline constexpr int kParameterCount = 8;
/// Regressor names in column order, as in the normal-equations JSON.
inline constexpr std::array<std::string_view, kParameterCount> kRegressorNames{
    "e_i", "-xdot", "-xddot", "x_r", "xdot_r", "xddot_r", "-PV", "-NV"};

using Vector8 = Eigen::Matrix<double, kParameterCount, 1>;
using Matrix8 = Eigen::Matrix<double, kParameterCount, kParameterCount>;
using Matrix9 = Eigen::Matrix<double, kParameterCount + 1, kParameterCount + 1>;

/// Sufficient statistics of y ~ Phi theta (the exchange format "servotwin.normal-equations/1").
struct NormalEquations {
  Matrix8 P = Matrix8::Zero();  ///< Phi^T Phi
  Vector8 R = Vector8::Zero();  ///< Phi^T y
  double gamma = 0.0;           ///< y^T y
  std::uint64_t n = 0;          ///< number of samples (rows of Phi)
  double ts = 0.0;              ///< sample period [s]
};

/// How captures are turned into regressor rows.
///
/// Exact conventions (k counts samples of the actual position x from 0):
/// * Shift: the command paired with x_k is x_r,k := cmd[k + command_shift]. Samples k without a
///   shifted command (k + shift outside the capture) are dropped, so a capture of N samples gives
///   M = N - |shift| pairs, renumbered from 0.
/// * Integrated error: e_i,k = ts * sum_{m=0..k} (x_r,m - x_m) over the pairs, i.e. from the first
///   pair of the capture (thesis: from its first sample), including pair k. It is not restarted by
///   the trims, and every capture (every accumulator) starts its own integral: merging two
///   problems is NOT the problem of the concatenated samples (no stencil or integral crosses the
///   seam).
/// * Stencils: xdot_k = (x_{k+1} - x_{k-1}) / (2 ts), xddot_k = (xdot_{k+1} - xdot_{k-1}) / (2 ts), the
///   same for x_r; rows exist for pairs 2 .. M-3 (where both stencils are defined).
/// * Trims: of these rows, the first trim_start and the last trim_end are dropped.
/// * Direction indicators: PV_k = 1 if xdot_k > deadband, NV_k = 1 if xdot_k < -deadband.
struct RegressorOptions {
  /// Command shifted forward by this many samples (x_r,k := cmd[k + shift]): the preview of a
  /// ZPETC (thesis 4.3.2 uses 2). May be negative; |shift| <= kMaxDelay.
  int command_shift = 0;
  /// Regressor rows dropped at the start and at the end (after the shift and the stencils);
  /// trim_end <= kMaxDelay (the streaming pass holds that many samples back).
  std::size_t trim_start = 0;
  std::size_t trim_end = 0;
  /// Velocity deadband of the direction indicators [length/s], finite and >= 0; empty =
  /// automatic, see `deadband_window`.
  std::optional<double> velocity_deadband;
  /// Automatic deadband: estimated from the `deadband_window` pairs that start with the stencil of
  /// the first (not trimmed) row whose measured velocity is nonzero (earlier rows have xdot = 0
  /// exactly and need no deadband), or from all remaining pairs when the capture is shorter; the
  /// pass holds these samples back until the window is complete:
  ///   deadband = max(1.25 q / ts, 4 sigma_v),
  /// q = the smallest nonzero |x_{k+1} - x_k| (the encoder resolution for quantized data; steps
  /// below 1000 eps |x| are representation noise and ignored). Over the stencil x_{k+1} - x_{k-1}
  /// of quantized data is a multiple of q: up to 2 counts (jitter around a standing position)
  /// stays inside the deadband, 3 counts and more are motion; the threshold lies midway, so
  /// rounding never decides a flag.
  /// sigma_v = the velocity noise of white position noise, sigma_x / (sqrt(2) ts), with sigma_x
  /// = 1.4826 median |x_{k+1} - 2 x_k + x_{k-1}| / sqrt(6) over the rows whose command stands still
  /// (x_r equal over the whole 5-sample stencil; at least 16 rows, else sigma_v = 0): the second
  /// difference suppresses the smooth settling motion that follows a stop, the median the rest.
  /// Range 16 .. kMaxDelay.
  std::size_t deadband_window = 2048;
};

/// Limit of |command_shift|, trim_end and deadband_window [samples] (memory held back by the
/// streaming pass).
inline constexpr std::size_t kMaxDelay = std::size_t{1} << 22;
/// Fewer regressor rows than this are an input error.
inline constexpr std::size_t kMinimumRows = 10;

/// A least-squares problem in factored form. Problems of several captures (or axes' separate
/// experiments) merge by stacking their factors: the thesis joins low- and high-speed runs so.
class RegressionProblem {
 public:
  RegressionProblem() = default;
  /// core::InputError (field "Ts", "factor" or "N") for ts not finite and positive, a factor that
  /// is not finite or not upper triangular, or samples = 0 with a nonzero factor. Rows with a
  /// negative diagonal are negated (U^T U is unchanged): the stored factor has diagonal >= 0.
  RegressionProblem(const Matrix9& factor, std::uint64_t samples, double ts);

  /// From exported normal equations: the augmented Gram matrix [P R; R^T Gamma] is scaled
  /// symmetrically to unit diagonal, factored by a diagonally pivoted Cholesky that stops at
  /// rounding-level pivots (semidefinite input, e.g. a friction column that is all zero, is
  /// accepted), and the factor is re-triangularized in the original column order.
  /// core::InputError (field "P", "R", "Gamma", "N" or "Ts") for non-finite entries, asymmetry
  /// beyond 1e-10 relative to sqrt(P_ii P_jj), a negative diagonal or Gamma, indefiniteness beyond
  /// rounding (a remaining scaled Schur complement entry above 1e-9), N = 0, ts not finite and > 0.
  /// With `warnings`, a Gamma below R^T P^+ R (statistics printed with few digits, as in the
  /// thesis's appendix) is raised to it and a warning appended instead: the minimizer of
  /// 1/2 theta^T P theta - R^T theta does not depend on Gamma, only the objective's level does. Still
  /// refused: an R outside the range of P, where the objective has no minimum.
  static RegressionProblem from_normal_equations(const NormalEquations& ne, std::vector<std::string>* warnings = nullptr);

  /// P = U11^T U11, R = U11^T u12, Gamma = U^T U's last diagonal entry; exactly symmetric P.
  [[nodiscard]] NormalEquations normal_equations() const;
  /// Upper-triangular U with U^T U = [Phi y]^T [Phi y] and diagonal >= 0.
  [[nodiscard]] const Matrix9& factor() const noexcept { return u_; }
  [[nodiscard]] std::uint64_t samples() const noexcept { return n_; }
  [[nodiscard]] double ts() const noexcept { return ts_; }
  [[nodiscard]] bool empty() const noexcept { return n_ == 0; }

  /// f(theta) = 1/2 ||y - Phi theta||^2 = 1/2 ||U [-theta; 1]||^2, evaluated from the factor.
  [[nodiscard]] double objective(const Vector8& theta) const;

  /// Adds another problem (concatenated experiments); merging into or with an empty problem
  /// copies / keeps. core::InputError (field "Ts") when the sample periods differ by more than
  /// 1e-9 relative.
  RegressionProblem& merge(const RegressionProblem& other);

 private:
  Matrix9 u_ = Matrix9::Zero();
  std::uint64_t n_ = 0;
  double ts_ = 0.0;
};

/// What the accumulator saw, for warnings and the model file.
struct RegressionDiagnostics {
  std::uint64_t samples = 0;           ///< samples received (before shift, stencils and trims)
  std::uint64_t rows = 0;              ///< regressor rows used
  std::uint64_t positive_rows = 0;     ///< rows with PV = 1
  std::uint64_t negative_rows = 0;     ///< rows with NV = 1
  double velocity_deadband = 0.0;      ///< deadband actually used [length/s]
  bool deadband_automatic = false;     ///< estimated from the data (RegressorOptions::deadband_window)
  double position_resolution = 0.0;    ///< automatic deadband: smallest nonzero position step q (0 = none seen)
  double velocity_noise = 0.0;         ///< automatic deadband: robust standstill velocity noise (0 = none)
  double command_range = 0.0;          ///< max - min of the command over the capture
  double actual_range = 0.0;           ///< max - min of the actual position over the capture
  std::vector<std::string> warnings;   ///< e.g. "no motion in the negative direction: delta- not identifiable"
};

/// Streams one capture's samples in chunks of any size in a single pass: memory is bounded by the
/// options (not the capture length) and per-sample work is allocation-free. Rows are scaled by
/// exact powers of two per column and folded into the triangular factor 256 at a time by
/// Householder reflections, so the result does not depend on how the capture is chunked
/// (bit-identical for any chunk sizes).
class RegressorAccumulator {
 public:
  /// core::InputError (field "Ts", "command_shift", "trim_end", "velocity_deadband",
  /// "deadband_window") for invalid settings.
  RegressorAccumulator(double ts, const RegressorOptions& options);
  ~RegressorAccumulator();
  RegressorAccumulator(RegressorAccumulator&&) noexcept;
  RegressorAccumulator& operator=(RegressorAccumulator&&) noexcept;
  RegressorAccumulator(const RegressorAccumulator&) = delete;
  RegressorAccumulator& operator=(const RegressorAccumulator&) = delete;

  /// Appends samples (x_r, x) of equal length. Chunks may be of any size, including 0 and 1.
  /// core::InputError for different lengths or a non-finite sample (message names its index in
  /// the capture, field "command" or "actual"); the chunk is then not added.
  void add(std::span<const double> command, std::span<const double> actual);
  /// Finishes the pass (the last rows held back by the stencils and trim_end are dropped) and
  /// returns the problem; warnings go to diagnostics(). core::InputError when fewer than
  /// kMinimumRows rows remain. Call once; add() and finish() afterwards are logic errors.
  RegressionProblem finish();
  [[nodiscard]] const RegressionDiagnostics& diagnostics() const noexcept;

 private:
  friend Eigen::MatrixXd regressor_matrix(std::span<const double>, std::span<const double>, double,
                                          const RegressorOptions&, RegressionDiagnostics*);
  struct State;
  std::unique_ptr<State> state_;
};

/// One-shot helper: the problem of one axis's command/actual traces. core::InputError for too
/// short traces (fewer than kMinimumRows rows after shift, stencils and trims), non-finite samples
/// (with index), different lengths or invalid options.
RegressionProblem build_problem(std::span<const double> command, std::span<const double> actual, double ts,
                                const RegressorOptions& options = {}, RegressionDiagnostics* diagnostics = nullptr);

/// The rows [Phi y] (columns in kRegressorNames order, then y = x) that build_problem folds into
/// its factor, as a dense matrix: for inspection, plots and residual time series. Allocates
/// rows x 9 doubles; same errors as build_problem.
Eigen::MatrixXd regressor_matrix(std::span<const double> command, std::span<const double> actual, double ts,
                                 const RegressorOptions& options = {}, RegressionDiagnostics* diagnostics = nullptr);

/// The problem of one axis of a capture.
struct AxisProblem {
  std::string axis;
  RegressionProblem problem;
  RegressionDiagnostics diagnostics;
};

/// Every axis of a capture, each independently (its own accumulator, shift, deadband); errors
/// name the axis in the field ("<axis>_cmd" / "<axis>_act").
std::vector<AxisProblem> build_problems(const core::Capture& capture, const RegressorOptions& options = {});

}  // namespace servotwin::rapid
