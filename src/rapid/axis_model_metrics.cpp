// Simulation-based fit quality (the issue: the model is judged by simulating it, not by its
// one-step prediction).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/axis_model.hpp"

namespace servotwin::rapid {

namespace {

void require_finite(std::span<const double> values, const char* name) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) {
      throw core::InputError(core::at_field(std::string(name) + "[" + std::to_string(k) + "]"),
                             "tracking error sample must be finite (an unstable model's prediction diverges)");
    }
  }
}

// sqrt(sum v_k^2) with the scaling of BLAS dnrm2, so that squares of large errors cannot overflow.
class Norm {
 public:
  void add(double v) {
    const double a = std::abs(v);
    if (a == 0.0) return;
    if (a > scale_) {
      sum_ = 1.0 + sum_ * (scale_ / a) * (scale_ / a);
      scale_ = a;
    } else {
      sum_ += (a / scale_) * (a / scale_);
    }
  }
  [[nodiscard]] double value() const { return scale_ * std::sqrt(sum_); }

 private:
  double scale_ = 0.0, sum_ = 0.0;
};

// The running norms of a comparison of tracking errors, sample by sample in order (the same
// order gives the same numbers, whether the errors come whole or block by block).
struct RunningComparison {
  Norm measured, predicted, difference;
  double max_difference = 0.0;
  std::size_t offset = 0;  // samples of the records before the current one (simulation_fit)

  void add(double measured_error, double predicted_error) {
    const double d = measured_error - predicted_error;
    measured.add(measured_error);
    predicted.add(predicted_error);
    difference.add(d);
    max_difference = std::max(max_difference, std::abs(d));
  }

  // The metrics of n samples whose measured error has the given deviation norm (about its mean);
  // constant: the measured error never changes, so nrmse has no scale (FitMetrics::nrmse).
  [[nodiscard]] FitMetrics metrics(std::size_t n, const Norm& deviation, bool constant) const {
    FitMetrics m;
    const double root_n = std::sqrt(static_cast<double>(n));
    m.samples = n;
    m.rms_measured = measured.value() / root_n;
    m.rms_predicted = predicted.value() / root_n;
    m.rms_difference = difference.value() / root_n;
    m.max_difference = max_difference;
    if (constant) m.nrmse = difference.value() == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
    else m.nrmse = difference.value() / deviation.value();
    m.fit_percent = 100.0 * (1.0 - m.nrmse);
    m.std_measured = deviation.value() / root_n;
    return m;
  }
};

}  // namespace

FitMetrics compare_tracking(std::span<const double> measured_error, std::span<const double> predicted_error) {
  if (measured_error.size() != predicted_error.size()) {
    throw core::InputError(core::at_field("predicted_error"), "length " + std::to_string(predicted_error.size()) +
                                                         " differs from the measured error's " +
                                                         std::to_string(measured_error.size()));
  }
  if (measured_error.empty()) throw core::InputError(core::at_field("measured_error"), "at least one sample is required");
  require_finite(measured_error, "measured_error");
  require_finite(predicted_error, "predicted_error");

  const std::size_t n = measured_error.size();
  const double count = static_cast<double>(n);
  double mean = 0.0;
  for (const double e : measured_error) mean += e;
  mean /= count;
  const auto [min_it, max_it] = std::minmax_element(measured_error.begin(), measured_error.end());
  const bool constant = *min_it == *max_it;

  RunningComparison sums;
  Norm deviation;
  for (std::size_t k = 0; k < n; ++k) {
    sums.add(measured_error[k], predicted_error[k]);
    deviation.add(measured_error[k] - mean);
  }
  return sums.metrics(n, deviation, constant);
}

namespace {

// The count of sorted, distinct values (reading_quantum's rule), 0 when there is none.
double quantum_of_sorted(std::span<const double> values) {
  if (values.size() < 3) return 0.0;
  double count = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < values.size(); ++k) count = std::min(count, values[k] - values[k - 1]);
  // A gap of a few ulps of the largest reading is round-off, not a count.
  const double largest = std::max(std::abs(values.front()), std::abs(values.back()));
  if (count <= 1e-12 * largest) return 0.0;
  for (std::size_t k = 1; k < values.size(); ++k) {
    const double steps = (values[k] - values[k - 1]) / count;
    if (std::abs(steps - std::round(steps)) > 0.01) return 0.0;
  }
  return count;
}

// The sorted distinct values in O(n) when the reading visibly lies on a grid: the smallest
// change between consecutive samples is the grid's step candidate, and every value goes to the
// bucket of its grid index. Empty when that does not work out (values off the candidate grid, two
// distinct values in one bucket, too many buckets): the caller sorts instead. When it works the
// buckets hold exactly sort + unique's values in order (a value lies within a quarter step of its
// index, so bucket order is value order), so the result does not depend on the path.
std::vector<double> distinct_on_grid(std::span<const double> positions, std::size_t finite) {
  double step = std::numeric_limits<double>::infinity(), previous = std::numeric_limits<double>::quiet_NaN();
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  for (const double x : positions) {
    if (!std::isfinite(x)) continue;
    if (x != previous && std::isfinite(previous)) step = std::min(step, std::abs(x - previous));
    previous = x;
    lowest = std::min(lowest, x);
    highest = std::max(highest, x);
  }
  if (!std::isfinite(step)) return {};
  const double span = (highest - lowest) / step;
  if (!(span < 4.0 * static_cast<double>(finite) + 16.0)) return {};
  std::vector<double> bucket(static_cast<std::size_t>(std::llround(span)) + 1, std::numeric_limits<double>::quiet_NaN());
  for (const double x : positions) {
    if (!std::isfinite(x)) continue;
    const double index = (x - lowest) / step;
    const double nearest = std::round(index);
    if (std::abs(index - nearest) > 0.25 || nearest >= static_cast<double>(bucket.size())) return {};
    double& slot = bucket[static_cast<std::size_t>(nearest)];
    if (std::isnan(slot)) slot = x;
    else if (slot != x) return {};
  }
  std::erase_if(bucket, [](double v) { return std::isnan(v); });
  return bucket;
}

}  // namespace

double reading_quantum(std::span<const double> positions) {
  const auto finite = static_cast<std::size_t>(
      std::count_if(positions.begin(), positions.end(), [](double x) { return std::isfinite(x); }));
  // Issue 26: sorting a copy cost 70 ms of a 1 M-sample identification; the grid's buckets give
  // the same distinct values in one pass whenever the reading is a clean count.
  std::vector<double> values = distinct_on_grid(positions, finite);
  if (values.empty()) {
    values.reserve(finite);
    for (const double x : positions)
      if (std::isfinite(x)) values.push_back(x);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
  }
  return quantum_of_sorted(values);
}

void set_reading_quantum(FitMetrics& fit, double quantum) {
  fit.reading_quantum = quantum > 0.0 && std::isfinite(quantum) ? quantum : 0.0;
  fit.quantization_floor =
      fit.reading_quantum > 0.0 && fit.std_measured > 0.0 ? fit.reading_quantum / std::sqrt(12.0) / fit.std_measured : 0.0;
}

FitMetrics simulation_fit(const AxisModel& model, std::span<const double> command, std::span<const double> actual,
                          const ModelSimulationOptions& options) {
  const TrackingRecord record{command, actual};
  return simulation_fit(model, std::span<const TrackingRecord>(&record, 1), options);
}

namespace {

class ComparisonSink final : public PositionSink {
 public:
  ComparisonSink(const TrackingRecord& record, RunningComparison& sums, double give_up_norm)
      : record_(record), sums_(sums), give_up_norm_(give_up_norm) {}

  bool consume(std::size_t first, std::span<const double> positions) override {
    for (std::size_t j = 0; j < positions.size(); ++j) {
      const std::size_t k = first + j;
      const double measured = record_.command[k] - record_.actual[k];
      const double predicted = record_.command[k] - positions[j];
      if (!std::isfinite(predicted)) {
        // Issue 27 §3: an unstable model (identify --method ls) ended identify with exit 3 here;
        // its fit is reported as diverged instead, and the model is still written.
        diverged_ = true;
        diverged_at_ = sums_.offset + k;
        return false;
      }
      sums_.add(measured, predicted);
    }
    gave_up_ = sums_.difference.value() > give_up_norm_;
    return !gave_up_;
  }
  [[nodiscard]] bool gave_up() const { return gave_up_; }
  [[nodiscard]] bool diverged() const { return diverged_; }
  [[nodiscard]] std::size_t diverged_at() const { return diverged_at_; }

 private:
  const TrackingRecord& record_;
  RunningComparison& sums_;
  double give_up_norm_;
  bool gave_up_ = false;
  bool diverged_ = false;
  std::size_t diverged_at_ = 0;
};

}  // namespace

FitMetrics simulation_fit(const AxisModel& model, std::span<const TrackingRecord> records,
                          const ModelSimulationOptions& options, double give_up_above) {
  // First pass over the data alone: nrmse's scale, the spread of the measured error.
  std::size_t n = 0;
  double sum = 0.0;
  for (const TrackingRecord& r : records) {
    if (r.command.size() != r.actual.size()) {
      throw core::InputError(core::at_field("actual"), "length " + std::to_string(r.actual.size()) +
                                                  " differs from the command's " + std::to_string(r.command.size()));
    }
    if (r.command.empty()) throw core::InputError(core::at_field("command"), "at least one sample is required");
    for (std::size_t k = 0; k < r.actual.size(); ++k) {
      if (!std::isfinite(r.actual[k]))
        throw core::InputError(core::at_field("actual[" + std::to_string(n + k) + "]"), "actual position sample must be finite");
      sum += r.command[k] - r.actual[k];
    }
    n += r.command.size();
  }
  if (n == 0) throw core::InputError(core::at_field("command"), "at least one sample is required");
  const double count = static_cast<double>(n);
  const double mean = sum / count;
  Norm deviation;
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  for (const TrackingRecord& r : records) {
    for (std::size_t k = 0; k < r.command.size(); ++k) {
      const double e = r.command[k] - r.actual[k];
      deviation.add(e - mean);
      lowest = std::min(lowest, e);
      highest = std::max(highest, e);
    }
  }
  const bool constant = lowest == highest;
  // A constant measured error has no spread to scale by: never give up then.
  const double give_up_norm = constant ? std::numeric_limits<double>::infinity() : give_up_above * deviation.value();

  RunningComparison sums;
  bool gave_up = false;
  std::optional<std::size_t> diverged_at;
  for (const TrackingRecord& r : records) {
    ModelSimulationOptions o = options;
    if (!o.initial_position) o.initial_position = r.actual.front();
    ComparisonSink sink(r, sums, give_up_norm);
    (void)model.simulate_blocks(r.command, o, sink);
    sums.offset += r.command.size();
    if (sink.diverged()) diverged_at = sink.diverged_at();
    if ((gave_up = sink.gave_up() || sink.diverged())) break;
  }

  FitMetrics m = sums.metrics(n, deviation, constant);
  m.complete = !gave_up;
  if (diverged_at) {
    // The sums cover the samples before the divergence: their RMS values are over those.
    const double covered = static_cast<double>(std::max<std::size_t>(*diverged_at, 1));
    const double scale = std::sqrt(count / covered);
    m.rms_measured *= scale;
    m.rms_predicted *= scale;
    m.rms_difference *= scale;
    m.samples = *diverged_at;
    m.diverged = true;
    m.diverged_at = *diverged_at;
    m.nrmse = std::numeric_limits<double>::infinity();
    m.fit_percent = -std::numeric_limits<double>::infinity();
  }
  return m;
}

}  // namespace servotwin::rapid
