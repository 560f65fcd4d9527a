#pragma once
/// \file
/// The report of a controller tuning (`servotwin tune --report`): the plant as
/// the tuner normalized it, the design (ω*, gains, the automatic ω* scan, closed-loop poles), the
/// loop shapes and margins, the robustness tests against an uncertainty weight W2, the P position
/// loop of a pi+p design, and the linear step responses of the rational closed loop.
///
/// Units: frequencies in Hz (normalized ω × ωz/2π), times in s (normalized t/ωz), gains and
/// dimensional frequency functions in the plant model's units (torque per velocity for the
/// controller, velocity per torque for the plant and the load-torque response); dimensionless
/// functions (S, T, tracking) in dB, as the other reports' Bode charts.

#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/report/document.hpp"
#include "servotwin/tuning/compare.hpp"
#include "servotwin/tuning/tune.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"

namespace servotwin::report {

/// What the report needs beyond the tuner's result.
struct TuningReportOptions {
  std::string source;  ///< the plant's name or file, for the subtitle
  /// The multiplicative uncertainty weight W2(s) the tuning used, in physical s [rad/s] (as
  /// tuning::TuneOptions::w2): draws |W2 T| and the robust-performance function.
  std::optional<core::TransferFunction> w2;
  std::size_t frequency_points =
      400;  ///< log grid of the frequency charts (plus the plant's and poles' frequencies), >= 16
  std::size_t time_points = 1200;  ///< samples of each step response, >= 16
  /// Closed-loop simulations of the design on the plant with its nonlinearities
  /// (vcnc::simulate_drive), each drawn as a section after the linear responses.
  std::vector<vcnc::DriveSimulation> simulations{};
};

/// Builds the report of `result` (a tuning::tune() result):
///  - "Plant": normalized parameters (ωz and the resonance in Hz, r, ζz, ζp, a, Im, higher
///    modes, known HF dynamics, the two-mass realization with friction when there is one), the
///    C7.4 verdict for r, Bode magnitude and phase of the design model, of the model with the
///    higher modes and of the model with the known HF dynamics (NormalizedPlant::measured_response);
///  - "Design": design parameters and gains (normalized and physical), the admissible ω* range;
///    when ω* was chosen automatically the scan (bandwidth, ‖S‖∞ and tracking peak over ω*, the
///    Ms/Mt limits, the chosen ω*); the closed-loop poles (Hz, damping);
///  - "Loop shapes": |S|, |T|, |ωm/ω*|, |ωl/ω*| with the Ms/Mt lines; the closed- and open-loop
///    load-torque response |ωl/Tl|; the controller |C(jω)|; margins and peaks;
///  - "Robustness" (with W2): |W2|, |W2 T|, |S|/Ms + |W2 T| against 1 and the RS/NP/RP table;
///  - "Position loop" (pi+p): |φl/φ*| and |φl/Tl| at the chosen Kpp and the Kpp limits;
///  - "Time responses (linear)": unit setpoint step (motor and load velocity, motor torque) and unit
///    load-torque step from the rational closed loop by exact zero-order-hold simulation;
///  - one section per given simulation on the nonlinear plant (report::drive_section).
/// core::InputError (field "frequency_points" / "time_points") for options out of range, and
/// "w2" for a weight that is improper or unstable.
[[nodiscard]] Document tuning_report(const tuning::TuneResult& result, const TuningReportOptions& options = {});

/// What the comparison report needs beyond the comparison.
struct ComparisonReportOptions {
  std::string source;                  ///< the plant's name or file, for the subtitle
  std::size_t frequency_points = 400;  ///< log grid of the frequency charts, >= 16
  std::size_t time_points = 1200;      ///< samples of each step response, >= 16
  /// Runs of the compared designs on the plant with its nonlinearities (vcnc::simulate_drive), any
  /// structures and tests: one section per test with every structure's run overlaid.
  std::vector<vcnc::DriveSimulation> simulations{};
};

/// The structure comparison of C7.15 (`servotwin tune compare --report`):
///  - "Comparison": the common spec and, per structure, the load bandwidth, ‖S‖∞, the tracking
///    peak, ‖ωl/Tl‖∞ and the load-step ITAE (each also relative to the PI), the margins, the
///    design parameter (ω* or kbw), the controller's own stability, or why it could not be tuned;
///  - "Loop shapes": |ωl/ω*| (|ωm/ω*| without a load side) with Mt, |S| with Ms, and the
///    closed-loop |ωl/Tl| of every structure beside the uncontrolled plant's;
///  - "Time responses (linear)": the load velocity after a unit setpoint step and after a unit
///    load-torque step, and the torque command of the setpoint step, every structure in one chart;
///  - per test in options.simulations, "Simulation on the plant: <test>": a metrics table (plant
///    and linear part) and the controlled variable and torque of every structure overlaid;
///  - "Notes": each design's notes.
/// core::InputError (field "comparison") when no structure has a design, and as tuning_report()
/// for the point counts.
[[nodiscard]] Document comparison_report(const std::vector<tuning::StructureComparison>& comparison,
                                         const ComparisonReportOptions& options = {});

}  // namespace servotwin::report
