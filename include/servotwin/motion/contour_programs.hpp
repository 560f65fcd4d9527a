#pragma once
/// \file
/// The contouring test toolpaths of the rapid-identification thesis (sections 3.4.1 and 4.3):
/// a circle and a diamond run at 200 mm/s (F12000) to compare predicted and actual contour
/// errors. The thesis gives the circle's diameter (40 mm, Fig. 4.7); the diamond is the square
/// with its vertices on the same circle (a 40 mm diagonal), so both fit the same ±20 mm window.

#include <optional>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

struct ContourProgramOptions {
  Point center{};               ///< centre of the toolpath [mm]
  double size_mm = 40.0;        ///< circle diameter, diamond diagonal [mm], > 0
  double feed_mm_min = 12000.0; ///< programmed feed (200 mm/s), > 0
  Dialect dialect = Dialect::Iso;
  /// Path-control mode stated on every block; empty = the dialect's default (exact stop for ISO
  /// and LinuxCNC, the machine's setting for Heidenhain), as IdentificationOptions::path_control.
  std::optional<PathControl> path_control;
  double blend_tolerance_mm = 0.0;  ///< with PathControl::Blend: the stated tolerance, 0 = none
};

/// G17, a rapid from `center` to the rightmost point (centre + size/2 in X), one full
/// counter-clockwise circle (G03 with I = -size/2), a rapid back to the centre, M30. The program
/// starts at `center`. core::InputError (field "size_mm", "feed_mm_min", "center", "path_control")
/// for bad options.
Program make_circle_program(const ContourProgramOptions& options);

/// G17, a rapid from `center` to the rightmost vertex, four G01 edges counter-clockwise through
/// the top, left and bottom vertices back to it (90 degree corners: exact stops), a rapid back to
/// the centre, M30. Same errors as make_circle_program.
Program make_diamond_program(const ContourProgramOptions& options);

}  // namespace servotwin::motion
