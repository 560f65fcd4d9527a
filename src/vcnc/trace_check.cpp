#include "servotwin/vcnc/trace_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::vcnc {

namespace {

core::InputError error_at(const std::string& source, const std::string& field, const std::string& message) {
  return core::InputError({source, 0, 0, field}, message);
}

double column_range(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

/// The trace's command of every axis it has, X, Y, Z order.
motion::Trajectory trace_command(const core::Capture& trace, const std::string& trace_name) {
  motion::Trajectory t;
  t.ts = trace.ts;
  for (std::size_t i = 0; i < motion::kAxisCount; ++i) {
    const auto axis = static_cast<motion::Axis>(i);
    const core::AxisTrace* a = trace.find(motion::axis_name(axis));
    if (a == nullptr) continue;
    if (a->cmd.size() != trace.size())
      throw error_at(trace_name, std::string(motion::axis_name(axis)) + "_cmd", "the command column has another length");
    t.axes.push_back(axis);
    t.positions.push_back(a->cmd);
  }
  return t;
}

/// A unit mismatch between trace and program: their travel on one axis differs by a known factor.
void check_units(const core::Capture& trace, const std::string& trace_name, const motion::Program& program,
                 const std::string& program_name) {
  motion::InterpolationLimits coarse;
  coarse.ts = 0.01;  // the extent only: the path sampled every 10 ms at the default limits
  const motion::Trajectory planned = motion::interpolate(program, coarse);
  for (std::size_t i = 0; i < planned.axes.size(); ++i) {
    const std::string name = motion::axis_name(planned.axes[i]);
    const core::AxisTrace* a = trace.find(name);
    const double travel = column_range(planned.positions[i]);
    if (a == nullptr || travel <= 0.0) continue;
    const double ratio = column_range(a->cmd) / travel;
    struct Unit {
      double ratio;  // trace travel / program travel
      const char* what;
      double scale;
    };
    static constexpr std::array<Unit, 6> kUnits{{{1e-3, "in m", 1000.0},
                                                 {1.0 / 25.4, "in inches", 25.4},
                                                 {0.1, "in cm", 10.0},
                                                 {1e3, "in um", 1e-3},
                                                 {25.4, "in mm against an inch program? servotwin reads programs in mm: ", 1.0 / 25.4},
                                                 {10.0, "in 0.1 mm", 0.1}}};
    for (const Unit& u : kUnits) {
      if (std::abs(ratio / u.ratio - 1.0) > 0.03) continue;
      throw error_at(trace_name, name + "_cmd",
                     fmt::format("the trace's {} travel is {:.6g} but {}'s is {:.6g} mm ({:.4g} times): is the trace {}? "
                                 "read it with --scale {:g} (or a profile with its units)",
                                 name, column_range(a->cmd), program_name, travel, ratio, u.what, u.scale));
    }
  }
}

}  // namespace

double default_path_tolerance(const motion::Program& program, double range) {
  const double rounding = 0.01 + 1e-4 * range;
  double blend = 0.0;
  bool unbounded = !program.states_path_control();
  for (const motion::Block& b : program.blocks) {
    if (b.type == motion::BlockType::None || b.type == motion::BlockType::Dwell) continue;
    if (b.path_control != motion::PathControl::Blend) continue;
    if (b.blend_tolerance_mm > 0.0) {
      blend = std::max(blend, b.blend_tolerance_mm);
    } else {
      unbounded = true;
    }
  }
  return rounding + (unbounded ? 0.1 * range : blend);
}

TraceCheck check_trace(const core::Capture& trace, const std::string& trace_name, const motion::Program* program,
                       const std::string& program_name, const TraceCheckOptions& options) {
  TraceCheck out;
  for (const core::AxisTrace& a : trace.axes) {
    if (!a.cmd.empty() && column_range(a.cmd) == 0.0)
      out.notes.push_back(fmt::format("axis {}: the command never moves in {}", a.name, trace_name));
  }
  if (program == nullptr) return out;
  check_units(trace, trace_name, *program, program_name);

  const motion::Trajectory command = trace_command(trace, trace_name);
  double range = 0.0;
  for (const auto& column : command.positions) range = std::max(range, column_range(column));
  motion::CommandMatchOptions match_options;
  match_options.window_s = options.contour_window_s;
  match_options.tolerance_mm = options.path_tolerance_mm.value_or(default_path_tolerance(*program, range));
  match_options.offset = options.offset;
  out.path_tolerance_mm = match_options.tolerance_mm;
  std::shared_ptr<motion::ContourPath> path;
  try {
    path = std::make_shared<motion::ContourPath>(motion::ContourPath::from_command(*program, command, match_options));
  } catch (const core::InputError& e) {
    throw error_at(trace_name, "", std::string(e.what()));
  }
  const motion::CommandMatch& m = path->match();
  if (m.max_deviation > match_options.tolerance_mm) {
    throw error_at(trace_name, "",
                   fmt::format("the trace's commanded path leaves {}'s path by {:.4g} mm at t = {:.4g} s (sample {}), more "
                               "than the tolerance {:.4g} mm{}: is it a run of this program (same coordinates, or give "
                               "--offset)?",
                               program_name, m.max_deviation, trace.time(m.worst_sample), m.worst_sample,
                               match_options.tolerance_mm, options.path_tolerance_mm ? "" : " (set it with --path-tolerance)"));
  }
  if (m.progress_end < 0.5 * m.path_length) {
    throw error_at(trace_name, "",
                   fmt::format("the trace's command covers {:.4g} mm of {}'s {:.4g} mm path: is it a run of this program?",
                               m.progress_end, program_name, m.path_length));
  }
  if (m.progress_end < m.path_length - match_options.tolerance_mm) {
    out.warnings.push_back(fmt::format("the trace ends before {} does: its command covers {:.4g} of {:.4g} mm of the path",
                                       program_name, m.progress_end, m.path_length));
  }
  if (m.max_feed_ratio > 1.02) {
    out.warnings.push_back(fmt::format("the commanded speed reaches {:.0f} % of the programmed F{:g} at t = {:.4g} s ({} line "
                                       "{}): a feed override was on, the trace does not run the program as written",
                                       100.0 * m.max_feed_ratio, m.feed_mm_min, trace.time(m.feed_sample), program_name,
                                       m.feed_line));
  }
  if (m.offset != motion::Point{0.0, 0.0, 0.0}) {
    out.notes.push_back(fmt::format("the trace is offset from {}'s coordinates by X {:.6g} Y {:.6g} Z {:.6g} mm", program_name,
                                    m.offset[0], m.offset[1], m.offset[2]));
  }
  out.notes.push_back(fmt::format("the trace's command keeps within {:.3g} mm of {}'s path (RMS {:.3g} mm)", m.max_deviation,
                                  program_name, m.rms_deviation));
  out.path = std::move(path);
  return out;
}

}  // namespace servotwin::vcnc
