#pragma once
/// \file
/// The report of a rapid identification (`servotwin identify --report`): what was measured, how
/// well the identified closed-loop model reproduces it, and what the model is.

#include <span>
#include <vector>

#include "servotwin/report/document.hpp"
#include "servotwin/vcnc/identification.hpp"

namespace servotwin::report {

/// Builds the report of one or more identified axes (from the same captures):
///  - "Captures": per capture (identification and validation) samples, duration, sample period and
///    the range of every identified axis's command and actual position, and a chart of both over
///    time;
///  - per axis, "Axis <a>: model": coefficients of thesis Eq. 3.3, solver (method, objective,
///    certified lower bound, Kuhn-Tucker case, active bounds with their multipliers), fit metrics
///    and the command-shift search;
///  - per axis, "Axis <a>: frequency responses": poles and zeros (Hz, damping), the bounds of the
///    search, and Bode plots (magnitude in dB, unwrapped phase in degrees, log frequency from below
///    the lowest pole or zero to the Nyquist frequency) of the tracking response x/x_r, including
///    the command shift's exp(j omega shift ts) as `servotwin model --frf` writes it, and of the
///    disturbance response x/d;
///  - per axis, "Axis <a>: measured vs simulated tracking error": per capture the measured tracking
///    error x_r - x and the model's, simulated from the capture's first actual position with the
///    identified command shift (as vcnc::simulated_fit), their difference, and per capture metrics.
/// An unstable model is reported, not refused: non-finite simulated values are gaps and their
/// metrics say so. core::InputError when `axes` is empty or an axis is missing from a capture.
Document identification_report(std::span<const vcnc::AxisIdentification> axes,
                               const std::vector<vcnc::NamedCapture>& captures,
                               const std::vector<vcnc::NamedCapture>& validation);

/// The report of one axis.
Document identification_report(const vcnc::AxisIdentification& axis, const std::vector<vcnc::NamedCapture>& captures,
                               const std::vector<vcnc::NamedCapture>& validation);

}  // namespace servotwin::report
