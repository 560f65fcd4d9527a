#pragma once
/// \file
/// The generalized closed-loop axis model of thesis Eq. 3.3,
///   [s^2 + a1 s + a2 + a3/s] x = [b0 s^2 + b1 s + b2 + a3/s] x_r - [PV(x') d0 + NV(x') d1],
/// its poles and zeros, tracking and disturbance transfer functions and their frequency responses,
/// and its time simulation from any commanded trajectory.
///
/// Time-domain form. With the integrated tracking error e_i = integral of (x_r - x), Eq. 3.3 is
///   x''  = -a1 x' - a2 x + a3 e_i + b0 x_r'' + b1 x_r' + b2 x_r - F(x'),
///   e_i' = x_r - x,
/// i.e. the 3-state linear system z = (x, x', e_i), z' = A z + B (w - F, x_r) with
///   A = [[0, 1, 0], [-a2, -a1, a3], [-1, 0, 0]],  det(sI - A) = s^3 + a1 s^2 + a2 s + a3,
/// drive w = b2 x_r + b1 x_r' + b0 x_r'' and Coulomb friction F (acceleration units, like d0, d1):
///   F = d0 while x' > 0, F = d1 while x' < 0 (d1 is normally negative). At x' = 0 the axis sticks
///   (x' stays 0, x constant, e_i keeps integrating) while the net drive g = -a2 x + a3 e_i + w
///   lies in [d1, d0], and breaks away in the direction of g when it leaves that band (Karnopp).
///
/// Units: lengths in the user's unit (coefficients a, b are unit-free per s^k; d0, d1 are
/// length/s^2 and scale with the length unit), time in s, frequencies in rad/s unless `_hz`.

#include <complex>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid {

/// Coefficients of Eq. 3.3 (lengths in the user's unit, time in s).
struct ModelCoefficients {
  double a1 = 0, a2 = 0, a3 = 0, b0 = 0, b1 = 0, b2 = 0, d0 = 0, d1 = 0;
};

/// theta (Eq. 3.10) -> coefficients: a2 = 1/alpha_2, a1 = alpha_1 a2, a3 = alpha_i a2,
/// b2 = beta_0 a2, b1 = beta_1 a2, b0 = beta_2 a2, d0 = delta+ a2, d1 = delta- a2.
/// core::InputError (field "theta" / "theta[2] (alpha_2)") for a non-finite theta or alpha_2 = 0.
ModelCoefficients coefficients_from_theta(const Vector8& theta);
/// The inverse mapping. core::InputError (field "a2") unless a2 is finite and nonzero.
Vector8 theta_from_coefficients(const ModelCoefficients& c);

/// Options of a model simulation.
struct ModelSimulationOptions {
  /// As RegressorOptions::command_shift: the model is driven by x_r,k+shift (the preview of a
  /// ZPETC). Indices beyond the capture are clamped to its first/last sample.
  int command_shift = 0;
  /// Initial position x(0); default: where the model rests under its first (shifted) command
  /// sample x_r,0, i.e. x_r,0 itself, or (b2/a2) x_r,0 when a3 = 0 (static error of a loop
  /// without integrator; x_r,0 if also a2 = 0). Velocity starts at 0.
  std::optional<double> initial_position;
  /// Initial integrated tracking error e_i(0); default: zero net drive at rest,
  /// a3 e_i(0) = a2 x(0) - b2 x_r,0 (0 when a3 = 0). With b2 = a2 (PID structure) and
  /// x(0) = x_r,0 this is 0; for the P-PI structure (b2 != a2) an integrator starting at 0 would
  /// start the model away from equilibrium.
  std::optional<double> initial_integrator;
  /// Examine every sample with the exact event search (the series of the matrix exponential)
  /// instead of first certifying that the velocity keeps its sign through the sample: the
  /// reference the fast path is tested and benchmarked against (tens of times slower on models
  /// faster than the sample rate). Results agree to rounding.
  bool event_search_every_sample = false;
};

/// Event counts of one simulation (friction switching).
struct SimulationEvents {
  std::uint64_t reversals = 0;   ///< changes of the direction of motion (through rest or directly)
  std::uint64_t sticks = 0;      ///< arrivals at rest with the net drive inside [d1, d0]
  std::uint64_t breakaways = 0;  ///< departures from rest
  /// Samples in which more than AxisModel::kMaxEventsPerSample events occurred; the rest of such a
  /// sample is integrated in the current friction mode without event location (never observed
  /// with sign-consistent friction; a safeguard against Zeno behaviour of degenerate fits).
  std::uint64_t event_limit_hits = 0;
};

/// Predicted response to a command.
struct ModelResponse {
  std::vector<double> position;        ///< predicted x_k
  std::vector<double> velocity;        ///< predicted x'_k (exactly 0 while stuck)
  std::vector<double> tracking_error;  ///< x_r,k - x_k (with the unshifted command)
  SimulationEvents events;
};

/// Receives a simulation's positions block by block (AxisModel::simulate_blocks).
class PositionSink {
 public:
  virtual ~PositionSink() = default;
  /// Positions x_k for k = first, first + 1, ...; false stops the simulation.
  virtual bool consume(std::size_t first, std::span<const double> positions) = 0;
};

/// A measured tracking record: the command and the actual position of one axis, sample by sample.
struct TrackingRecord {
  std::span<const double> command;
  std::span<const double> actual;
};

/// Eq. 3.3 with its sample period.
class AxisModel {
 public:
  /// Maximum number of friction events (zero crossings, sticks, breakaways) located per sample.
  static constexpr int kMaxEventsPerSample = 32;
  /// Samples per block of simulate_blocks.
  static constexpr std::size_t kSimulationBlock = 1024;

  /// core::InputError (field "a1".."d1" or "ts") for non-finite coefficients or ts not finite > 0.
  AxisModel(const ModelCoefficients& coefficients, double ts);

  [[nodiscard]] const ModelCoefficients& coefficients() const noexcept { return c_; }
  [[nodiscard]] double ts() const noexcept { return ts_; }

  /// x/x_r = (b0 s^3 + b1 s^2 + b2 s + a3)/(s^3 + a1 s^2 + a2 s + a3). When a3 = 0 the integrator
  /// does not act on x (e_i is then unobservable from x) and the common factor s is cancelled
  /// exactly: (b0 s^2 + b1 s + b2)/(s^2 + a1 s + a2).
  [[nodiscard]] core::TransferFunction tracking() const;
  /// x/d = -s/(s^3 + a1 s^2 + a2 s + a3), d in acceleration units (friction d0, d1);
  /// -1/(s^2 + a1 s + a2) when a3 = 0.
  [[nodiscard]] core::TransferFunction disturbance() const;
  /// tracking()(j omega) and disturbance()(j omega) on a grid [rad/s].
  [[nodiscard]] std::vector<std::complex<double>> tracking_response(std::span<const double> omega_rad_s) const;
  [[nodiscard]] std::vector<std::complex<double>> disturbance_response(std::span<const double> omega_rad_s) const;
  /// Roots of the denominator / numerator of tracking() (ascending modulus, conjugate pairs
  /// adjacent), with frequency in rad/s and Hz and damping (zeta = -1 for a real root in the right
  /// half plane, as the thesis tables print).
  [[nodiscard]] std::vector<core::ModalInfo> poles() const;
  [[nodiscard]] std::vector<core::ModalInfo> zeros() const;
  /// All poles in the open left half plane.
  [[nodiscard]] bool is_stable() const;
  /// tracking() at s = 0: 1 when a3 != 0 (the integrator removes static error), else b2/a2;
  /// +-inf (or NaN for 0/0) when the reduced denominator vanishes at 0.
  [[nodiscard]] double tracking_dc_gain() const;
  /// disturbance() at s = 0: 0 when a3 != 0, else -1/a2 (static deflection per unit of d).
  [[nodiscard]] double disturbance_dc_gain() const;
  /// Lowest frequency where |tracking| falls 3 dB (factor 10^(-3/20), as MATLAB's bandwidth) below
  /// |tracking_dc_gain()| [Hz]: the first crossing on a log grid (200 points per decade, plus the
  /// zero frequencies so that narrow notches are not stepped over) refined by bisection to 1e-12
  /// relative. +inf if the gain never falls so low below the Nyquist frequency pi/ts; NaN when the
  /// DC gain is 0 or not finite.
  [[nodiscard]] double bandwidth_hz() const;

  /// Simulates from sampled commands (allocates only the output vectors). Output k is the state
  /// at t = k ts (output 0 is the initial state); events are counted up to the last sample.
  ///
  /// Inputs: between samples k and k+1 the command x_r,k and its central differences
  ///   x_r'_k = (x_r,k+1 - x_r,k-1)/(2 ts),  x_r''_k = (x_r'_k+1 - x_r'_k-1)/(2 ts)
  /// (the regression's stencils) are held; the command is extended by its end values before the
  /// first and after the last sample (the axis rests before and after the capture), so the end
  /// samples use the same stencils on the padded command.
  ///
  /// Integration is exact: each friction mode (F = d0, F = d1) is a linear system with constant
  /// input, stepped by its zero-order-hold matrices. A velocity zero crossing inside a sample is
  /// located on the exact solution (a power series of the sub-step's matrix exponential, scanned
  /// and refined by safeguarded Newton/bisection) and the sample is split there; at rest the axis
  /// sticks or moves on according to the Karnopp rule above, so a reversal produces exactly one
  /// change of direction and no chatter. When d0 = d1 the friction is a constant input and the
  /// model is simulated as the linear system it is.
  ///
  /// Sign-inconsistent friction (d0 < d1, e.g. d0 < 0 < d1 from a bad fit): no rest state is
  /// consistent (the stick band [d1, d0] is empty); at x' = 0 the axis moves in the direction whose
  /// friction law is self-consistent, and when both are (d0 < g < d1) in the direction of the
  /// larger acceleration, i.e. positive iff g >= (d0 + d1)/2. Simulation never hangs: at most
  /// kMaxEventsPerSample events are located per sample.
  ///
  /// Unstable models are simulated as well (the response grows; see is_stable()).
  /// core::InputError (field "command[k]") for a non-finite command sample, (field "ts") when the
  /// model's growth over one sample exceeds the double range.
  [[nodiscard]] ModelResponse simulate(std::span<const double> command,
                                       const ModelSimulationOptions& options = {}) const;
  /// The positions of simulate(), handed to `sink` in blocks of at most kSimulationBlock samples
  /// instead of stored: for consumers that reduce a long capture on the fly and may stop early
  /// (simulation_fit's give-up bound). No allocation. Returns the number of samples simulated.
  /// The same errors as simulate().
  std::size_t simulate_blocks(std::span<const double> command, const ModelSimulationOptions& options,
                              PositionSink& sink) const;
  /// As simulate(), writing into `out` and reusing the capacity of its vectors: no allocation at
  /// all when they are large enough (repeated simulations, e.g. a solver scoring many models).
  void simulate_into(std::span<const double> command, ModelResponse& out,
                     const ModelSimulationOptions& options = {}) const;

  /// Precomputed stepping data (implementation detail, exposed only so AxisModel stays a value).
  struct Kernel {
    double phi[3][3] = {};   ///< exp(A ts)
    double gamma_w[3] = {};  ///< ZOH input vector of the drive w - F
    double gamma_r[3] = {};  ///< ZOH input vector of x_r (the e_i' equation)
    bool valid = false;      ///< false when exp(A ts) overflows
  };

 private:
  ModelCoefficients c_;
  double ts_;
  Kernel kernel_;
};

/// Simulation-based fit quality of a predicted tracking error against a measured one.
struct FitMetrics {
  double rms_measured = 0.0;    ///< RMS of the measured tracking error
  double rms_predicted = 0.0;   ///< RMS of the predicted tracking error
  double rms_difference = 0.0;  ///< RMS of (measured - predicted) tracking error
  double max_difference = 0.0;  ///< max |measured - predicted|
  /// ||e_meas - e_pred|| / ||e_meas - mean(e_meas)||: 0 is perfect, 1 is no better than the mean
  /// (MATLAB compare: fit = 100 (1 - nrmse) %). When the measured error is constant (zero
  /// variance) the ratio is undefined; it is then defined as 0 if the prediction equals it
  /// sample for sample and +inf otherwise.
  double nrmse = 0.0;
  double fit_percent = 0.0;     ///< 100 (1 - nrmse)
  double std_measured = 0.0;    ///< standard deviation of the measured tracking error (nrmse's scale)
  /// Step of the grid the actual positions lie on (an encoder's count), 0 when none was found
  /// or looked for (set_reading_quantum).
  double reading_quantum = 0.0;
  /// The nrmse the reading's quantization alone gives a perfect prediction: (q / sqrt(12)) /
  /// std_measured. No prediction driven by the command scores below it; 0 without a quantum.
  double quantization_floor = 0.0;
  std::size_t samples = 0;
  /// false: simulation_fit gave up early (see there); nrmse is then a lower bound.
  bool complete = true;
  /// The simulated positions stopped being finite numbers at sample `diverged_at` (an unstable
  /// model's prediction diverges): the other members cover the samples before it, nrmse is +inf.
  bool diverged = false;
  std::size_t diverged_at = 0;
};

/// The count of the grid `positions` lie on: the smallest gap between distinct values, accepted
/// only when every gap between adjacent distinct values is a whole multiple of it (to 1 % of
/// the count) and it is not floating-point round-off. 0 when there is no such grid (positions
/// that vary continuously, fewer than three distinct values, or readings printed with too few
/// significant digits to keep one count). Sorts a copy: O(n log n), call it once per capture.
double reading_quantum(std::span<const double> positions);

/// Sets fit.reading_quantum and the quantization_floor that follows from it (q = 0 clears both).
void set_reading_quantum(FitMetrics& fit, double quantum);
/// core::InputError (fields "measured_error", "predicted_error[k]") for different lengths, empty
/// input or a non-finite sample (e.g. the prediction of an unstable model).
FitMetrics compare_tracking(std::span<const double> measured_error, std::span<const double> predicted_error);

/// Simulates `model` on `command` and compares its tracking error with the measured one
/// (command - actual). Unless options.initial_position is set the simulation starts at the
/// measured actual[0]. core::InputError as simulate() and compare_tracking(), and (field
/// "actual") when the traces differ in length.
FitMetrics simulation_fit(const AxisModel& model, std::span<const double> command, std::span<const double> actual,
                          const ModelSimulationOptions& options = {});

/// simulation_fit over several records compared as one sequence (each simulated from its own
/// first actual position unless options.initial_position is set), without storing the
/// simulation. give_up_above: the simulation stops as soon as the nrmse reached so far exceeds it
/// (the norm of the difference only grows, and nrmse's scale, the measured error's spread, is
/// known before the simulation): the result then has complete = false and nrmse, rms_difference
/// and max_difference are lower bounds, the rest undefined. The numbers of a complete result equal
/// compare_tracking's on the same sequence. Errors as simulation_fit.
FitMetrics simulation_fit(const AxisModel& model, std::span<const TrackingRecord> records,
                          const ModelSimulationOptions& options,
                          double give_up_above = std::numeric_limits<double>::infinity());

}  // namespace servotwin::rapid
