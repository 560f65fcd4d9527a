// The streaming regressor accumulator (thesis Eq. 3.9-3.11): one pass over a capture, rows built
// from a ring buffer of raw samples and folded into the triangular factor of [Phi y] 256 at a time.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "regression_qr.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid {

namespace {

using detail::kAugmentedColumns;
using Vector9 = Eigen::Matrix<double, kAugmentedColumns, 1>;

/// Rows folded into the factor per Householder update: large enough to amortize the update of
/// the 9 x 9 factor, small enough that the block (18 KiB) stays in the L1 cache.
constexpr std::size_t kBlockRows = 256;
/// Rows a stencil reaches on each side of its centre sample (5-point stencil of xddot).
constexpr std::uint64_t kStencilHalfWidth = 2;
/// Below this many standstill rows the median second difference is no noise estimate.
constexpr std::size_t kMinimumStandstillRows = 16;
/// Gaussian consistency factor of the median absolute deviation.
constexpr double kMadToSigma = 1.4826;
/// Deadband in units of the encoder resolution per sample period: midway between 2 and 3 counts
/// over the 2-period stencil (RegressorOptions::deadband_window).
constexpr double kResolutionDeadbandFactor = 1.25;
/// Relative margin by which a velocity must exceed the deadband to set a direction flag.
constexpr double kDeadbandTieMargin = 1e-9;
/// Deadband in units of the noise standard deviation (false direction flag rate ~6e-5).
constexpr double kNoiseDeadbandFactor = 4.0;

core::InputError field_error(const std::string& field, const std::string& message) {
  return core::InputError(core::at_field(field), message);
}

/// A span as an Eigen vector, for Eigen's vectorized reductions (scalar min/max chains are
/// latency-bound).
Eigen::Map<const Eigen::VectorXd> as_vector(std::span<const double> values) {
  return {values.data(), static_cast<Eigen::Index>(values.size())};
}

std::size_t next_power_of_two(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

void validate(double ts, const RegressorOptions& o) {
  if (!std::isfinite(ts) || ts <= 0.0) {
    throw field_error("Ts", "sample period must be a finite positive number of seconds, got " + std::to_string(ts));
  }
  const auto shift = static_cast<long long>(o.command_shift);
  if (shift > static_cast<long long>(kMaxDelay) || -shift > static_cast<long long>(kMaxDelay)) {
    throw field_error("command_shift", "must be within +-" + std::to_string(kMaxDelay) + " samples, got " +
                                           std::to_string(o.command_shift));
  }
  if (o.trim_end > kMaxDelay) {
    throw field_error("trim_end", "must be at most " + std::to_string(kMaxDelay) + " samples, got " +
                                      std::to_string(o.trim_end));
  }
  if (o.deadband_window < 16 || o.deadband_window > kMaxDelay) {
    throw field_error("deadband_window", "must be within 16 .. " + std::to_string(kMaxDelay) + " samples, got " +
                                             std::to_string(o.deadband_window));
  }
  if (o.velocity_deadband && (!std::isfinite(*o.velocity_deadband) || *o.velocity_deadband < 0.0)) {
    throw field_error("velocity_deadband",
                      "must be a finite velocity >= 0 (length/s), got " + std::to_string(*o.velocity_deadband));
  }
}

}  // namespace

struct RegressorAccumulator::State {
  State(double period, const RegressorOptions& o)
      : ts(period),
        inv_2ts(1.0 / (2.0 * period)),
        options(o),
        cmd_offset(o.command_shift > 0 ? static_cast<std::uint64_t>(o.command_shift) : 0),
        act_offset(o.command_shift < 0 ? static_cast<std::uint64_t>(-static_cast<long long>(o.command_shift)) : 0),
        lag(cmd_offset + act_offset),
        first_row(kStencilHalfWidth + std::min<std::uint64_t>(o.trim_start, std::uint64_t{1} << 62)),
        lookahead(kStencilHalfWidth + o.trim_end),
        capacity(next_power_of_two(o.deadband_window + lag + lookahead + kBlockRows + 8)),
        mask(capacity - 1),
        // Uninitialized on purpose: a slot is always written before it is read, and zeroing
        // would touch every page of a buffer a short capture never fills.
        cmd_ring(new double[capacity]),
        act_ring(new double[capacity]),
        scratch(o.velocity_deadband ? nullptr : new double[o.deadband_window]) {
    if (o.velocity_deadband) {
      deadband = *o.velocity_deadband;
      deadband_known = true;
    }
    diagnostics.velocity_deadband = deadband;
    diagnostics.deadband_automatic = !o.velocity_deadband;
  }

  // Settings.
  double ts;
  double inv_2ts;
  RegressorOptions options;
  std::uint64_t cmd_offset;  ///< raw index of the command of pair 0
  std::uint64_t act_offset;  ///< raw index of the actual position of pair 0
  std::uint64_t lag;         ///< |shift|: raw samples needed beyond a pair's own index
  std::uint64_t first_row;   ///< first pair index that gives a row
  std::uint64_t lookahead;   ///< a row q is emitted once pair q + lookahead exists
  std::size_t capacity;
  std::size_t mask;

  // Raw samples, indexed by (raw index & mask).
  std::unique_ptr<double[]> cmd_ring;
  std::unique_ptr<double[]> act_ring;
  std::uint64_t received = 0;
  std::uint64_t next_pair = 0;  ///< next pair to integrate (and to turn into a row)

  // Integrated tracking error, compensated (Kahan) so that long captures keep full accuracy.
  double error_sum = 0.0;
  double error_compensation = 0.0;

  // Direction deadband.
  bool deadband_known = false;
  double deadband = 0.0;
  std::unique_ptr<double[]> scratch;  ///< standstill second differences of the estimation window

  // Row block (column-major, leading dimension kBlockRows) and the scaled factor.
  std::array<double, kAugmentedColumns * kBlockRows> block{};
  std::size_t block_rows = 0;
  Matrix9 factor = Matrix9::Zero();  ///< factor of [Phi y] * diag(scale)
  Vector9 scale = Vector9::Ones();
  Vector9 column_max = Vector9::Zero();
  std::vector<double>* dense = nullptr;  ///< regressor_matrix: rows go here instead

  // Ranges and counts.
  double cmd_min = std::numeric_limits<double>::infinity();
  double cmd_max = -std::numeric_limits<double>::infinity();
  double act_min = std::numeric_limits<double>::infinity();
  double act_max = -std::numeric_limits<double>::infinity();
  RegressionDiagnostics diagnostics;
  bool finished = false;

  [[nodiscard]] double cmd(std::uint64_t pair) const noexcept { return cmd_ring[(pair + cmd_offset) & mask]; }
  [[nodiscard]] double act(std::uint64_t pair) const noexcept { return act_ring[(pair + act_offset) & mask]; }
  [[nodiscard]] std::uint64_t pairs_available() const noexcept { return received > lag ? received - lag : 0; }
  /// Oldest raw sample still needed (the stencil start of the next pair, or a waiting window).
  [[nodiscard]] std::uint64_t oldest_needed() const noexcept {
    return next_pair > kStencilHalfWidth ? next_pair - kStencilHalfWidth : 0;
  }

  void check_finite(std::span<const double> values, const char* field) const {
    if (as_vector(values).allFinite()) return;
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        throw field_error(field, "sample " + std::to_string(received + i) + " is not finite (" +
                                     std::to_string(values[i]) + "); expected a finite position");
      }
    }
  }

  void update_ranges(std::span<const double> command, std::span<const double> actual) noexcept {
    if (command.empty()) return;
    cmd_min = std::min(cmd_min, as_vector(command).minCoeff());
    cmd_max = std::max(cmd_max, as_vector(command).maxCoeff());
    act_min = std::min(act_min, as_vector(actual).minCoeff());
    act_max = std::max(act_max, as_vector(actual).maxCoeff());
  }

  void add(std::span<const double> command, std::span<const double> actual) {
    std::size_t done = 0;
    while (done < command.size()) {
      const std::uint64_t held = received - oldest_needed();
      const std::size_t room = capacity - static_cast<std::size_t>(held);
      const std::size_t count = std::min(room, command.size() - done);
      // At most two contiguous pieces: up to the end of the ring, then from its start.
      const std::size_t slot = static_cast<std::size_t>(received) & mask;
      const std::size_t first = std::min(count, capacity - slot);
      std::copy_n(command.data() + done, first, cmd_ring.get() + slot);
      std::copy_n(actual.data() + done, first, act_ring.get() + slot);
      std::copy_n(command.data() + done + first, count - first, cmd_ring.get());
      std::copy_n(actual.data() + done + first, count - first, act_ring.get());
      received += count;
      done += count;
      process(false);
    }
  }

  /// Emits every row whose stencil and trim_end look-ahead are available. At the end of the
  /// capture (`final`) a deadband estimation that still waits for its window uses what exists.
  void process(bool final) {
    const std::uint64_t available = pairs_available();
    if (next_pair + lookahead >= available) return;
    const std::uint64_t limit = available - lookahead;  // pairs q < limit can be processed
    for (; next_pair < limit && next_pair < first_row; ++next_pair) integrate(cmd(next_pair), act(next_pair));
    // Until the deadband is known, rows go one at a time: the first with nonzero velocity starts
    // the estimation window.
    for (; next_pair < limit && !deadband_known; ++next_pair) {
      const std::uint64_t q = next_pair;
      if (act(q + 1) != act(q - 1)) {
        const std::uint64_t window_begin = q - kStencilHalfWidth;
        const std::uint64_t window_end = window_begin + options.deadband_window;
        if (window_end > available && !final) return;  // wait for the whole window
        estimate_deadband(window_begin, std::min(window_end, available));
      }
      emit_rows(q, q + 1);
    }
    if (next_pair < limit) {
      emit_rows(next_pair, limit);
      next_pair = limit;
    }
  }

  void integrate(double command, double actual) noexcept { kahan_add(error_sum, error_compensation, command - actual); }

  static void kahan_add(double& sum, double& compensation, double value) noexcept {
    const double y = value - compensation;
    const double t = sum + y;
    compensation = (t - sum) - y;
    sum = t;
  }

  /// Rows of pairs [begin, end) (begin >= first_row), integrating their pairs. The stencils slide
  /// along: one new sample and one new velocity per signal and row.
  void emit_rows(std::uint64_t begin, std::uint64_t end) {
    double a0 = act(begin), a1 = act(begin + 1);
    double c0 = cmd(begin), c1 = cmd(begin + 1);
    double xd_prev = (a0 - act(begin - 2)) * inv_2ts;  // xdot_{q-1}
    double xd = (a1 - act(begin - 1)) * inv_2ts;       // xdot_q
    double cd_prev = (c0 - cmd(begin - 2)) * inv_2ts;
    double cd = (c1 - cmd(begin - 1)) * inv_2ts;
    std::uint64_t positive = 0, negative = 0;
    // Locals: the row stores could alias members, which would put the sum's dependency chain
    // through memory.
    double sum = error_sum, compensation = error_compensation;
    // Velocities of quantized positions take discrete values, and the deadband (a multiple of the
    // resolution) can coincide with one of them; then rounding would decide the direction flag
    // and the model would change with the length unit. Values within 1e-9 of the deadband count
    // as inside it, in every unit alike.
    const double inv = inv_2ts, period = ts, band = deadband * (1.0 + kDeadbandTieMargin);
    const double* act_base = act_ring.get();
    const double* cmd_base = cmd_ring.get();
    const std::uint64_t act_shift = act_offset + 2, cmd_shift = cmd_offset + 2;
    const std::size_t wrap = mask;
    for (std::uint64_t q = begin; q < end;) {
      const std::uint64_t stop = std::min<std::uint64_t>(end, q + (kBlockRows - block_rows));
      double* row = block.data() + block_rows;
      for (; q < stop; ++q, ++row) {
        const double a2 = act_base[(q + act_shift) & wrap];
        const double c2 = cmd_base[(q + cmd_shift) & wrap];
        const double xd_next = (a2 - a0) * inv;
        const double cd_next = (c2 - c0) * inv;
        kahan_add(sum, compensation, c0 - a0);
        const bool is_positive = xd > band;
        const bool is_negative = xd < -band;
        row[0 * kBlockRows] = period * sum;
        row[1 * kBlockRows] = -xd;
        row[2 * kBlockRows] = -((xd_next - xd_prev) * inv);
        row[3 * kBlockRows] = c0;
        row[4 * kBlockRows] = cd;
        row[5 * kBlockRows] = (cd_next - cd_prev) * inv;
        row[6 * kBlockRows] = is_positive ? -1.0 : 0.0;
        row[7 * kBlockRows] = is_negative ? -1.0 : 0.0;
        row[8 * kBlockRows] = a0;
        positive += is_positive ? 1 : 0;
        negative += is_negative ? 1 : 0;
        a0 = a1;
        a1 = a2;
        c0 = c1;
        c1 = c2;
        xd_prev = xd;
        xd = xd_next;
        cd_prev = cd;
        cd = cd_next;
      }
      block_rows = static_cast<std::size_t>(row - block.data());
      if (block_rows == kBlockRows) flush_block();
    }
    error_sum = sum;
    error_compensation = compensation;
    diagnostics.positive_rows += positive;
    diagnostics.negative_rows += negative;
    diagnostics.rows += end - begin;
  }

  /// Folds the block into the factor. Column scales are exact powers of two from the running
  /// column maxima; when one grows, the factor's column is rescaled exactly.
  void flush_block() {
    if (block_rows == 0) return;
    if (dense != nullptr) {
      for (std::size_t i = 0; i < block_rows; ++i) {
        for (std::size_t j = 0; j < kAugmentedColumns; ++j) dense->push_back(block[j * kBlockRows + i]);
      }
      block_rows = 0;
      return;
    }
    for (int j = 0; j < kAugmentedColumns; ++j) {
      Eigen::Map<Eigen::VectorXd> column(block.data() + static_cast<std::size_t>(j) * kBlockRows,
                                         static_cast<Eigen::Index>(block_rows));
      // (Eigen's packet max: a scalar max chain would cost as much as the whole row build.)
      const double m = std::max(column_max(j), column.cwiseAbs().maxCoeff());
      column_max(j) = m;
      const double s = detail::power_of_two_scale(m);
      if (s != scale(j)) {
        factor.col(j) *= s / scale(j);
        scale(j) = s;
      }
      column *= s;
    }
    detail::triangular_update(factor, block.data(), kBlockRows, block_rows);
    block_rows = 0;
  }

  /// The automatic deadband over pairs [begin, end) (see RegressorOptions::deadband_window).
  void estimate_deadband(std::uint64_t begin, std::uint64_t end) {
    constexpr double representation_noise = 1e3 * std::numeric_limits<double>::epsilon();
    double step = std::numeric_limits<double>::infinity();
    for (std::uint64_t k = begin; k + 1 < end; ++k) {
      const double a = act(k);
      const double b = act(k + 1);
      const double d = std::abs(b - a);
      if (d > representation_noise * std::max(std::abs(a), std::abs(b)) && d < step) step = d;
    }
    std::size_t standstill = 0;
    for (std::uint64_t k = begin + kStencilHalfWidth; k + kStencilHalfWidth < end; ++k) {
      const double c = cmd(k);
      if (cmd(k - 2) == c && cmd(k - 1) == c && cmd(k + 1) == c && cmd(k + 2) == c) {
        scratch[standstill++] = std::abs(act(k + 1) - 2.0 * act(k) + act(k - 1));
      }
    }
    double noise = 0.0;
    // White position noise sigma_x gives second differences of deviation sqrt(6) sigma_x and
    // velocities (x_{k+1} - x_{k-1}) / (2 ts) of deviation sigma_x / (sqrt(2) ts).
    if (standstill >= kMinimumStandstillRows) noise = kMadToSigma * median(standstill) / (std::sqrt(12.0) * ts);
    const double resolution = std::isfinite(step) ? step : 0.0;
    deadband = std::max(kResolutionDeadbandFactor * resolution / ts, kNoiseDeadbandFactor * noise);
    deadband_known = true;
    diagnostics.velocity_deadband = deadband;
    diagnostics.position_resolution = resolution;
    diagnostics.velocity_noise = noise;
  }

  /// Median of scratch[0, n), n >= 1 (reorders scratch).
  double median(std::size_t n) {
    double* const first = scratch.get();
    const auto middle = first + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(first, middle, first + static_cast<std::ptrdiff_t>(n));
    if (n % 2 == 1) return *middle;
    const double upper = *middle;
    const double lower = *std::max_element(first, middle);
    return 0.5 * (lower + upper);
  }

  void add_warnings() {
    auto& w = diagnostics.warnings;
    if (diagnostics.actual_range == 0.0) {
      w.emplace_back("no motion at all: the actual position is constant, the model is not identifiable");
    } else if (diagnostics.positive_rows == 0 && diagnostics.negative_rows == 0) {
      w.emplace_back("no motion beyond the velocity deadband (" + std::to_string(deadband) +
                     " length/s): delta+ and delta- not identifiable");
    } else if (diagnostics.negative_rows == 0) {
      w.emplace_back("no motion in the negative direction: delta- not identifiable");
    } else if (diagnostics.positive_rows == 0) {
      w.emplace_back("no motion in the positive direction: delta+ not identifiable");
    }
    if (diagnostics.command_range == 0.0) {
      w.emplace_back("the command is constant: beta_0, beta_1, beta_2 are not identifiable");
    }
  }

  RegressionProblem finish() {
    process(true);
    flush_block();
    diagnostics.samples = received;
    diagnostics.command_range = received > 0 ? cmd_max - cmd_min : 0.0;
    diagnostics.actual_range = received > 0 ? act_max - act_min : 0.0;
    if (diagnostics.rows < kMinimumRows) {
      throw core::InputError("capture too short: " + std::to_string(received) + " samples give " +
                             std::to_string(diagnostics.rows) + " regressor rows after the command shift (" +
                             std::to_string(options.command_shift) + "), the difference stencils (2 + 2) and the trims (" +
                             std::to_string(options.trim_start) + " + " + std::to_string(options.trim_end) +
                             "); at least " + std::to_string(kMinimumRows) + " rows are needed");
    }
    add_warnings();
    Matrix9 u = factor * scale.cwiseInverse().asDiagonal();
    return RegressionProblem(u, diagnostics.rows, ts);
  }
};

RegressorAccumulator::RegressorAccumulator(double ts, const RegressorOptions& options) {
  validate(ts, options);
  state_ = std::make_unique<State>(ts, options);
}

RegressorAccumulator::~RegressorAccumulator() = default;
RegressorAccumulator::RegressorAccumulator(RegressorAccumulator&&) noexcept = default;
RegressorAccumulator& RegressorAccumulator::operator=(RegressorAccumulator&&) noexcept = default;

void RegressorAccumulator::add(std::span<const double> command, std::span<const double> actual) {
  if (!state_ || state_->finished) throw std::logic_error("RegressorAccumulator::add after finish()");
  if (command.size() != actual.size()) {
    throw core::InputError("command and actual chunks must have equal lengths, got " + std::to_string(command.size()) +
                           " and " + std::to_string(actual.size()) + " samples");
  }
  state_->check_finite(command, "command");
  state_->check_finite(actual, "actual");
  state_->update_ranges(command, actual);
  state_->add(command, actual);
}

RegressionProblem RegressorAccumulator::finish() {
  if (!state_ || state_->finished) throw std::logic_error("RegressorAccumulator::finish called twice");
  state_->finished = true;
  return state_->finish();
}

const RegressionDiagnostics& RegressorAccumulator::diagnostics() const noexcept {
  static const RegressionDiagnostics moved_from;
  return state_ ? state_->diagnostics : moved_from;
}

RegressionProblem build_problem(std::span<const double> command, std::span<const double> actual, double ts,
                                const RegressorOptions& options, RegressionDiagnostics* diagnostics) {
  RegressorAccumulator accumulator(ts, options);
  accumulator.add(command, actual);
  RegressionProblem problem = accumulator.finish();
  if (diagnostics != nullptr) *diagnostics = accumulator.diagnostics();
  return problem;
}

Eigen::MatrixXd regressor_matrix(std::span<const double> command, std::span<const double> actual, double ts,
                                 const RegressorOptions& options, RegressionDiagnostics* diagnostics) {
  RegressorAccumulator accumulator(ts, options);
  std::vector<double> rows;
  accumulator.state_->dense = &rows;
  accumulator.add(command, actual);
  (void)accumulator.finish();
  if (diagnostics != nullptr) *diagnostics = accumulator.diagnostics();
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, kAugmentedColumns, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(rows.data(), static_cast<Eigen::Index>(rows.size() / kAugmentedColumns),
                                    kAugmentedColumns);
}

std::vector<AxisProblem> build_problems(const core::Capture& capture, const RegressorOptions& options) {
  std::vector<AxisProblem> out;
  out.reserve(capture.axes.size());
  for (const core::AxisTrace& axis : capture.axes) {
    AxisProblem item;
    item.axis = axis.name;
    try {
      item.problem = build_problem(axis.cmd, axis.act, capture.ts, options, &item.diagnostics);
    } catch (const core::InputError& e) {
      core::SourceLocation where = e.where();
      if (where.field == "command") where.field = axis.name + "_cmd";
      else if (where.field == "actual") where.field = axis.name + "_act";
      else if (where.field.empty()) where.field = axis.name;
      throw core::InputError(where, "axis " + axis.name + ": " + e.reason());
    }
    out.push_back(std::move(item));
  }
  return out;
}

}  // namespace servotwin::rapid
