#pragma once
/// \file
/// The report of a prediction (`servotwin predict --report`, and the contouring part of
/// `servotwin demo --report`): what the identified models predict for a program and, when a
/// measured capture is given, how that compares with the measurement.

#include <string>

#include "servotwin/report/document.hpp"
#include "servotwin/vcnc/prediction.hpp"

namespace servotwin::report {

/// Sections for one program (titles prefixed with `name`):
///  - "<name>: summary": per axis the predicted tracking error and the contour error (RMS and max,
///    per kind of path) and, when measured, the alignment and the table of scores;
///  - "<name>: tracking errors": per axis predicted (and measured) tracking error over time;
///  - "<name>: contour error": predicted (and measured) contour error along the path (x = distance
///    travelled by the commanded point) and over time;
///  - "<name>: path": the commanded path and the predicted (and measured) points in the plane of
///    the first two predicted axes, with the deviation from the path magnified by the factor in the
///    chart title (chosen so that the largest deviation shows as a tenth of the path's extent).
/// `measured` may be null.
std::vector<Section> prediction_sections(const std::string& name, const vcnc::Prediction& prediction,
                                         const vcnc::MeasuredComparison* measured);

/// A whole document for one program.
Document prediction_report(const std::string& program_name, const vcnc::Prediction& prediction,
                           const vcnc::MeasuredComparison* measured);

}  // namespace servotwin::report
