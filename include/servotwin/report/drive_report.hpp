#pragma once
/// \file
/// The report of a closed-loop simulation (`servotwin simulate --report`): the run's settings and
/// gains, the step metrics of the plant with its nonlinearities beside those of its linear part,
/// and the time responses (controlled variable against the reference, motor velocity, torque
/// command with its limit, measured output).

#include <string>

#include "servotwin/report/document.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"

namespace servotwin::report {

/// Where the inputs came from (shown in the subtitle).
struct DriveReportOptions {
  std::string plant_source;
  std::string controller_source;
};

/// The report of `simulation` (which must have samples).
[[nodiscard]] Document drive_report(const vcnc::DriveSimulation& simulation, const DriveReportOptions& options = {});

/// The section with the metrics table and the charts of one run, as the tuning report embeds it.
[[nodiscard]] Section drive_section(const vcnc::DriveSimulation& simulation, const std::string& title);

}  // namespace servotwin::report
