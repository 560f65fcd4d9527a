#pragma once
/// \file
/// The report of a plant-model fit (`servotwin fit --report`): the measured frequency response
/// with the fitted model over it, the modes and physical parameters with their uncertainties, and
/// how the model order was chosen.

#include <string>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/friction_fit.hpp"
#include "servotwin/fit/nonlinear.hpp"
#include "servotwin/report/document.hpp"

namespace servotwin::report {

/// Builds the report:
///  - "Fitted model": structure, output kind, gain, rigid and lag poles, delay (value ± std), fit
///    metrics (points, parameters, iterations, rms log error) and the initialization that won;
///  - "Modes": antiresonance and resonance of each mode (Hz, damping, ± std);
///  - "Physical parameters": motor and load inertia, stiffness, damping, resonance ratio (± std) or
///    the reason there are none;
///  - "Model order": the criterion and every candidate's cost and score;
///  - "Nonlinear mechanics" (when `nonlinear` is given): Coulomb friction and backlash with the
///    antiresonance per amplitude;
///  - "Coulomb friction" (when `friction` is given and fitted; `report` is then the one written,
///    fit::with_friction_model): Mm, Ml, viscous damping and both residuals; the response charts
///    then draw the model with friction at each measured point besides its linear part, and the
///    error chart is that of the model with friction;
///  - "Frequency response": Bode magnitude and phase of the measured points (as measured) and of the
///    fitted model on a dense logarithmic grid over the measured range (delay included), and the
///    relative error |P_model/P_meas - 1| per point with the point's relative standard deviation
///    when the data carry one.
/// `source` names the measured file in the subtitle. core::InputError when the response is empty.
Document fit_report(const core::FrequencyResponse& measured, const fit::FitReport& report, const std::string& source,
                    const fit::NonlinearMechanics* nonlinear = nullptr, const fit::CoulombFit* friction = nullptr);

}  // namespace servotwin::report
