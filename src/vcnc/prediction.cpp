#include "servotwin/vcnc/prediction.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "servotwin/core/error.hpp"
#include "servotwin/core/large_buffer.hpp"
#include "servotwin/core/parallel.hpp"
#include "servotwin/vcnc/trace_check.hpp"

namespace servotwin::vcnc {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

core::InputError error_at(const std::string& source, const std::string& field, const std::string& message) {
  return core::InputError({source, 0, 0, field}, message);
}

std::optional<motion::Axis> axis_of(const std::string& name) {
  if (name == "x" || name == "X") return motion::Axis::X;
  if (name == "y" || name == "Y") return motion::Axis::Y;
  if (name == "z" || name == "Z") return motion::Axis::Z;
  return std::nullopt;
}

/// Models by program axis (index X, Y, Z), checked: known names, no repeats, one sample period.
std::array<const AxisModelSpec*, motion::kAxisCount> models_by_axis(const std::vector<AxisModelSpec>& models) {
  if (models.empty()) throw core::InputError("no axis model given: prediction needs one model per moving axis");
  std::array<const AxisModelSpec*, motion::kAxisCount> by_axis{};
  for (const auto& m : models) {
    const auto axis = axis_of(m.axis);
    if (!axis) throw error_at(m.source, "axis", "model axis '" + m.axis + "' is not x, y or z");
    const auto i = static_cast<std::size_t>(*axis);
    if (by_axis[i] != nullptr)
      throw error_at(m.source, "axis", "a second model for axis " + m.axis + " (the first is " + by_axis[i]->source + ")");
    const double ts = models.front().model.ts();
    if (std::abs(m.model.ts() - ts) > 1e-9 * ts)
      throw error_at(m.source, "ts",
                     "sample period " + std::to_string(m.model.ts()) + " s differs from " + models.front().source + "'s " +
                         std::to_string(ts) + " s: the models of one machine share the sample period");
    by_axis[i] = &m;
  }
  return by_axis;
}

/// Appends a simulation's positions to a vector whose capacity was reserved: a prediction keeps
/// only the positions, and appending spares the zero-filling and the velocity and error columns
/// of AxisModel::simulate (on a 10-minute program, a tenth of predict's time went to them).
class AppendPositions final : public rapid::PositionSink {
 public:
  explicit AppendPositions(std::vector<double>& out) : out_(out) {}
  bool consume(std::size_t, std::span<const double> positions) override {
    out_.insert(out_.end(), positions.begin(), positions.end());
    return true;
  }

 private:
  std::vector<double>& out_;
};

/// Axis i's model driven by its commanded column (with its command shift), from rest at the first
/// command.
void simulate_axis(const AxisModelSpec& spec, Prediction& out, std::size_t i) {
  rapid::ModelSimulationOptions sim;
  sim.command_shift = spec.command_shift;
  sim.initial_position = out.command[i].front();
  std::vector<double>& predicted = out.predicted[i];
  predicted.clear();
  core::reserve_large(predicted, out.command[i].size());
  AppendPositions sink(predicted);
  try {
    spec.model.simulate_blocks(out.command[i], sim, sink);
  } catch (const core::InputError& e) {
    // A model the simulation refuses (a coefficient far beyond its sample rate): name its file.
    if (!e.where().file.empty() || spec.source.empty()) throw;
    throw error_at(spec.source, e.where().field, e.reason());
  }
}

/// Every axis model driven by its commanded column (with its command shift), from rest at the
/// first command; the axes are shared among `workers` threads.
void simulate_models(const std::array<const AxisModelSpec*, motion::kAxisCount>& by_axis, std::size_t workers,
                     Prediction& out) {
  // Issue 27 §3: an unstable model's prediction (38 mm of "tracking error") was printed without a
  // word; it is still simulated, so that the growth can be seen, and flagged.
  for (motion::Axis axis : out.axes) {
    const AxisModelSpec& spec = *by_axis[static_cast<std::size_t>(axis)];
    if (spec.model.is_stable()) continue;
    out.unstable.push_back(axis);
    out.warnings.push_back(fmt::format(
        "the model of axis {} ({}) is unstable: its predicted motion grows without bound and says nothing about the "
        "machine (an unconstrained least-squares fit can be unstable; identify with the exact or ga method)",
        motion::axis_name(axis), spec.source.empty() ? "no file" : spec.source));
  }
  out.predicted.resize(out.axes.size());
  core::parallel_parts(out.axes.size(), workers, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) simulate_axis(*by_axis[static_cast<std::size_t>(out.axes[i])], out, i);
  });
}

std::vector<motion::PathKind> kinds_of(const motion::ContourReference& path, std::size_t n, std::size_t workers) {
  std::vector<motion::PathKind> kind(n);
  core::parallel_parts(n, workers, 65536, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) kind[k] = path.kind(k);
  });
  return kind;
}

/// Warnings and notes on how the program's path-control modes enter a prediction from servotwin's
/// own interpolation.
void note_path_control(const motion::Program& program, const std::string& program_name,
                       const motion::InterpolationLimits& limits, Prediction& out) {
  const bool heidenhain = program.dialect == motion::Dialect::Heidenhain;
  if (!program.states_path_control()) {
    out.warnings.push_back(fmt::format(
        "{} states no path-control mode ({}): corners sharper than {} deg are taken as exact stops and shallower "
        "ones at feed, which need not be what the controller does by default (LinuxCNC blends); state the mode in "
        "the program (servotwin gcode ... --path-mode)",
        program_name, heidenhain ? "no Cycle 32 TOLERANCE: the machine's own tolerance applies" : "no G61 or G64",
        limits.corner_angle_deg));
  }
  if (program.blends()) {
    out.notes.push_back(fmt::format(
        "{} blends corners ({}): servotwin's planner passes corners up to {} deg on the programmed path at a capped "
        "speed and stops at sharper ones, it does not round them the controller's way; a prediction from the "
        "controller's recorded command (servotwin predict --command trace.csv) is the reliable one",
        program_name, heidenhain ? "Cycle 32" : "G64", limits.corner_angle_deg));
  }
}

}  // namespace

Prediction predict(const motion::Program& program, const std::string& program_name, motion::InterpolationLimits limits,
                   const std::vector<AxisModelSpec>& models, const PredictionOptions& options) {
  const auto by_axis = models_by_axis(models);
  std::vector<motion::Axis> axes;
  const std::uint8_t used = program.used_axes();
  for (std::size_t i = 0; i < motion::kAxisCount; ++i) {
    const auto axis = static_cast<motion::Axis>(i);
    const bool moves = (used & motion::axis_bit(axis)) != 0;
    if (moves && by_axis[i] == nullptr) {
      throw error_at(program_name, "", std::string("the program moves axis ") + motion::axis_letter(axis) +
                                           " but no model is given for it (add --model with axis " +
                                           motion::axis_name(axis) + ")");
    }
    if (moves) axes.push_back(axis);
  }
  if (axes.empty()) throw error_at(program_name, "", "the program moves no axis: nothing to predict");

  Prediction out;
  out.ts = models.front().model.ts();
  out.contour_window_s = options.contour_window_s;
  limits.ts = out.ts;
  const motion::MotionPlan plan = motion::plan_motion(program, limits);
  // The interpolation beside the contour path and the samples' path kinds (neither needs the
  // other), then the axes' models, then the contour errors: each stage on every worker.
  motion::Trajectory trajectory;
  std::shared_ptr<motion::ContourPath> path;
  core::parallel_parts(2, options.workers, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t task = begin; task < end; ++task) {
      if (task == 0) {
        trajectory = motion::sample(plan, axes);
      } else {
        path = std::make_shared<motion::ContourPath>(program, plan, options.contour_window_s);
        out.kind = kinds_of(*path, plan.sample_count(), 1);
      }
    }
  });
  out.axes = trajectory.axes;
  out.command = std::move(trajectory.positions);
  simulate_models(by_axis, options.workers, out);
  out.contour_error = motion::contour_errors(*path, out.axes, out.predicted, options.workers);
  out.path = std::move(path);
  if (!limits.exact_stop_every_block) note_path_control(program, program_name, limits, out);
  return out;
}

Prediction predict_from_command(const core::Capture& trace, const std::string& trace_name, const motion::Program* program,
                                const std::string& program_name, const std::vector<AxisModelSpec>& models,
                                const CommandPredictionOptions& options) {
  const auto by_axis = models_by_axis(models);
  if (trace.size() < 2) throw error_at(trace_name, "", "the trace has fewer than 2 samples");
  const double ts = models.front().model.ts();
  if (std::abs(trace.ts - ts) > 1e-6 * ts) {
    throw error_at(trace_name, "t",
                   fmt::format("the trace's sample period {:.6g} s differs from the models' {:.6g} s ({}): identify the "
                               "models from a trace at the same rate",
                               trace.ts, ts, models.front().source));
  }
  std::uint8_t moved = program != nullptr ? program->used_axes() : 0;
  if (program == nullptr) {
    for (const core::AxisTrace& a : trace.axes) {
      const auto axis = axis_of(a.name);
      if (!axis || a.cmd.empty()) continue;
      const auto [lo, hi] = std::minmax_element(a.cmd.begin(), a.cmd.end());
      if (*hi > *lo) moved = static_cast<std::uint8_t>(moved | motion::axis_bit(*axis));
    }
  }
  Prediction out;
  out.ts = trace.ts;
  out.contour_window_s = options.contour_window_s;
  for (std::size_t i = 0; i < motion::kAxisCount; ++i) {
    const auto axis = static_cast<motion::Axis>(i);
    const std::string name = motion::axis_name(axis);
    if (by_axis[i] == nullptr) {
      if ((moved & motion::axis_bit(axis)) != 0)
        throw error_at(program != nullptr ? program_name : trace_name, program != nullptr ? "" : name + "_cmd",
                       "axis " + name + " moves but no model is given for it (add --model with axis " + name + ")");
      continue;
    }
    const core::AxisTrace* a = trace.find(name);
    if (a == nullptr || a->cmd.size() != trace.size())
      throw error_at(trace_name, name + "_cmd",
                     "the trace has no commanded position of axis " + name + ", which " + by_axis[i]->source + " models");
    out.axes.push_back(axis);
    out.command.push_back(a->cmd);
  }
  simulate_models(by_axis, options.workers, out);
  if (program != nullptr) {
    TraceCheckOptions check_options;
    check_options.contour_window_s = options.contour_window_s;
    check_options.path_tolerance_mm = options.path_tolerance_mm;
    check_options.offset = options.offset;
    TraceCheck check = check_trace(trace, trace_name, program, program_name, check_options);
    out.warnings.insert(out.warnings.end(), check.warnings.begin(), check.warnings.end());
    out.notes.insert(out.notes.end(), check.notes.begin(), check.notes.end());
    out.notes.back() += ": contour errors are measured against the programmed lines and arcs";
    out.path = std::move(check.path);
  } else {
    motion::Trajectory command;
    command.ts = trace.ts;
    command.axes = out.axes;
    command.positions = out.command;
    out.path = std::make_shared<motion::CommandPolyline>(command, options.contour_window_s);
    out.notes.push_back("no program given: contour errors are measured against the trace's own commanded path");
  }
  out.contour_error = motion::contour_errors(*out.path, out.axes, out.predicted, options.workers);
  out.kind = kinds_of(*out.path, trace.size(), options.workers);
  return out;
}

namespace {

/// First sample at which any column leaves its first value by more than `tolerance`.
std::size_t motion_start(const std::vector<const std::vector<double>*>& columns, double tolerance) {
  const std::size_t n = columns.front()->size();
  for (std::size_t k = 0; k < n; ++k) {
    for (const auto* c : columns)
      if (std::abs((*c)[k] - c->front()) > tolerance) return k;
  }
  return n;
}

struct Alignment {
  std::ptrdiff_t offset = 0;
  std::size_t first = 0, count = 0;
  double rms = std::numeric_limits<double>::infinity();
};

/// Overlap of prediction samples [0, n) with capture samples [0, m) under `offset`, and the RMS
/// command difference over it.
Alignment score_offset(const std::vector<const std::vector<double>*>& predicted_cmd,
                       const std::vector<const std::vector<double>*>& captured_cmd, std::ptrdiff_t offset) {
  const auto n = static_cast<std::ptrdiff_t>(predicted_cmd.front()->size());
  const auto m = static_cast<std::ptrdiff_t>(captured_cmd.front()->size());
  Alignment a;
  a.offset = offset;
  const std::ptrdiff_t first = std::max<std::ptrdiff_t>(0, -offset);
  const std::ptrdiff_t last = std::min(n, m - offset);
  if (last <= first) return a;
  double sum = 0.0;
  for (std::size_t i = 0; i < predicted_cmd.size(); ++i) {
    for (std::ptrdiff_t k = first; k < last; ++k) {
      const double d = (*captured_cmd[i])[static_cast<std::size_t>(k + offset)] - (*predicted_cmd[i])[static_cast<std::size_t>(k)];
      sum += d * d;
    }
  }
  a.first = static_cast<std::size_t>(first);
  a.count = static_cast<std::size_t>(last - first);
  a.rms = std::sqrt(sum / static_cast<double>(a.count * predicted_cmd.size()));
  return a;
}

void add_scores(MeasuredComparison& out, const std::string& quantity, const std::vector<double>& measured,
                const std::vector<double>& predicted, const std::vector<motion::PathKind>& kind) {
  const std::size_t begin = out.first, end = out.first + out.count;
  out.scores.push_back({quantity, "all",
                        rapid::compare_tracking(std::span(measured).subspan(begin, out.count),
                                                std::span(predicted).subspan(begin, out.count))});
  for (std::size_t kk = 0; kk < motion::kPathKindCount; ++kk) {
    const auto k = static_cast<motion::PathKind>(kk);
    std::vector<double> m, p;
    for (std::size_t s = begin; s < end; ++s) {
      if (kind[s] != k) continue;
      m.push_back(measured[s]);
      p.push_back(predicted[s]);
    }
    if (m.size() >= 10) out.scores.push_back({quantity, motion::path_kind_name(k), rapid::compare_tracking(m, p)});
  }
}

}  // namespace

namespace {

/// Measured positions, tracking and contour errors and the scores over prediction samples
/// [out.first, out.first + out.count), capture sample = prediction sample + out.offset.
void fill_measurement(const Prediction& prediction, const std::vector<const std::vector<double>*>& captured_cmd,
                      const std::vector<const std::vector<double>*>& captured_act, MeasuredComparison& out) {
  const std::size_t n = prediction.size();
  const auto at = [&](std::size_t k) { return static_cast<std::size_t>(static_cast<std::ptrdiff_t>(k) + out.offset); };
  out.actual.assign(prediction.axes.size(), std::vector<double>(n, kNaN));
  for (std::size_t i = 0; i < prediction.axes.size(); ++i) {
    for (std::size_t k = out.first; k < out.first + out.count; ++k) out.actual[i][k] = (*captured_act[i])[at(k)];
  }
  out.contour_error.assign(n, kNaN);
  motion::Point p = prediction.path->start_point();
  for (std::size_t k = out.first; k < out.first + out.count; ++k) {
    for (std::size_t i = 0; i < prediction.axes.size(); ++i) p[static_cast<std::size_t>(prediction.axes[i])] = out.actual[i][k];
    out.contour_error[k] = prediction.path->nearest(k, p).signed_distance;
  }
  out.tracking_error.assign(prediction.axes.size(), std::vector<double>(n, kNaN));
  for (std::size_t i = 0; i < prediction.axes.size(); ++i) {
    std::vector<double> predicted(n, 0.0);
    for (std::size_t k = out.first; k < out.first + out.count; ++k) {
      // The measured tracking error is the capture's own: its command minus its position.
      out.tracking_error[i][k] = (*captured_cmd[i])[at(k)] - out.actual[i][k];
      predicted[k] = prediction.tracking_error(i, k);
    }
    add_scores(out, std::string(motion::axis_name(prediction.axes[i])) + " tracking", out.tracking_error[i], predicted,
               prediction.kind);
  }
  add_scores(out, "contour", out.contour_error, prediction.contour_error, prediction.kind);
}

}  // namespace

MeasuredComparison compare_with_capture(const Prediction& prediction, const core::Capture& capture,
                                        const std::string& source) {
  if (prediction.size() == 0) throw core::InputError("empty prediction");
  if (std::abs(capture.ts - prediction.ts) > 1e-6 * prediction.ts) {
    throw error_at(source, "t", "sample period " + std::to_string(capture.ts) + " s differs from the models' " +
                                    std::to_string(prediction.ts) + " s");
  }
  std::vector<const std::vector<double>*> predicted_cmd, captured_cmd, captured_act;
  double range = 0.0;
  for (std::size_t i = 0; i < prediction.axes.size(); ++i) {
    const std::string name = motion::axis_name(prediction.axes[i]);
    const core::AxisTrace* trace = capture.find(name);
    if (trace == nullptr) throw error_at(source, name + "_cmd", "the capture has no axis " + name + ", which the program moves");
    predicted_cmd.push_back(&prediction.command[i]);
    captured_cmd.push_back(&trace->cmd);
    captured_act.push_back(&trace->act);
    const auto [lo, hi] = std::minmax_element(prediction.command[i].begin(), prediction.command[i].end());
    range = std::max(range, *hi - *lo);
  }
  if (capture.size() == 0) throw error_at(source, "", "the capture has no samples");

  // Coarse: the starts of motion; fine: least squares over +-50 samples around it.
  const double tolerance = 1e-6 * range + 1e-12;
  const auto start_p = static_cast<std::ptrdiff_t>(motion_start(predicted_cmd, tolerance));
  const auto start_c = static_cast<std::ptrdiff_t>(motion_start(captured_cmd, tolerance));
  Alignment best;
  for (std::ptrdiff_t d = -50; d <= 50; ++d) {
    const Alignment a = score_offset(predicted_cmd, captured_cmd, start_c - start_p + d);
    if (a.count * 2 >= prediction.size() && a.rms < best.rms) best = a;
  }
  if (!std::isfinite(best.rms)) {
    throw error_at(source, "", "the capture covers less than half of the program's " + std::to_string(prediction.size()) +
                                   " samples: is it a capture of this program?");
  }
  if (best.rms > 1e-3 * range + 1e-9) {
    throw error_at(source, "", "the capture's commanded positions differ from the program's by " + std::to_string(best.rms) +
                                   " RMS after the best time alignment (motion range " + std::to_string(range) +
                                   "): is it a capture of this program, with the same feed and acceleration? A real "
                                   "controller's look-ahead and blending never match servotwin's: predict from the "
                                   "trace's own command instead (servotwin predict --command)");
  }

  MeasuredComparison out;
  out.offset = best.offset;
  out.first = best.first;
  out.count = best.count;
  out.command_mismatch_rms = best.rms;
  fill_measurement(prediction, captured_cmd, captured_act, out);
  return out;
}

MeasuredComparison compare_with_trace(const Prediction& prediction, const core::Capture& trace, const std::string& source) {
  if (prediction.size() == 0) throw core::InputError("empty prediction");
  if (trace.size() != prediction.size())
    throw error_at(source, "", "the trace has " + std::to_string(trace.size()) + " samples but the prediction " +
                                   std::to_string(prediction.size()) + ": it was not made from this trace");
  std::vector<const std::vector<double>*> captured_cmd, captured_act;
  for (const motion::Axis axis : prediction.axes) {
    const std::string name = motion::axis_name(axis);
    const core::AxisTrace* t = trace.find(name);
    if (t == nullptr || t->act.size() != trace.size())
      throw error_at(source, name + "_act", "the trace has no measured position of axis " + name);
    captured_cmd.push_back(&t->cmd);
    captured_act.push_back(&t->act);
  }
  MeasuredComparison out;
  out.count = prediction.size();
  if (const auto* path = dynamic_cast<const motion::ContourPath*>(prediction.path.get()))
    out.command_mismatch_rms = path->match().rms_deviation;
  fill_measurement(prediction, captured_cmd, captured_act, out);
  return out;
}

}  // namespace servotwin::vcnc
