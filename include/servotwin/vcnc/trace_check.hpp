#pragma once
/// \file
/// Checks of a controller's trace before it is used, on its own and against the program it ran
/// (issue 24, "checks on every trace"): axes whose command never moves; with the program, the
/// units (a trace in m or inch against a program in mm), the command matched to the programmed
/// path (motion/contour.hpp: not a run of this program beyond a tolerance, or cut short), and a
/// commanded speed above the programmed feed (feed override). Gaps and irregular time stamps are
/// the readers' (io/capture_csv.hpp).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/motion/contour.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::vcnc {

struct TraceCheckOptions {
  double contour_window_s = 0.2;  ///< window of the matched path's contour errors [s]
  /// Largest distance the command may keep from the program's path [mm]; empty = from the
  /// program's path-control modes: 0.01 mm plus 1e-4 of the motion range for exact stop and exact
  /// path, plus the largest stated blend tolerance where the program blends with one, and 10 % of
  /// the motion range where blending has no tolerance or no mode is stated.
  std::optional<double> path_tolerance_mm;
  /// Trace coordinates = program coordinates + offset [mm]; empty = found (motion/contour.hpp).
  std::optional<motion::Point> offset;
};

struct TraceCheck {
  std::vector<std::string> warnings;  ///< feed override, a trace that ends early
  std::vector<std::string> notes;     ///< axes that never move, how the command matched the program
  /// The program's path with the command's progress (when a program was given).
  std::shared_ptr<const motion::ContourPath> path;
  double path_tolerance_mm = 0.0;     ///< the tolerance used
};

/// The tolerance TraceCheckOptions::path_tolerance_mm defaults to, for a motion range [mm].
double default_path_tolerance(const motion::Program& program, double motion_range_mm);

/// Checks `trace` (and, when `program` is given, it against the program). core::InputError naming
/// the trace when: its travel is 1000, 25.4 or 10 times (or a fraction of) the program's (a unit
/// mismatch, with the --scale that fixes it), the program moves an axis the trace lacks, the
/// command leaves the path by more than the tolerance, or covers less than half of it.
TraceCheck check_trace(const core::Capture& trace, const std::string& trace_name, const motion::Program* program,
                       const std::string& program_name, const TraceCheckOptions& options = {});

}  // namespace servotwin::vcnc
