#include "servotwin/io/prediction_csv.hpp"

#include <cmath>
#include <fmt/format.h>
#include <ostream>

#include "number_format.hpp"

namespace servotwin::io {

namespace {

void append_optional(fmt::memory_buffer& buffer, double v) {
  if (std::isfinite(v)) fmt::format_to(std::back_inserter(buffer), ",{}", v);
  else buffer.push_back(',');
}

}  // namespace

void write_prediction_csv(std::ostream& out, const vcnc::Prediction& p, const vcnc::MeasuredComparison* measured) {
  fmt::memory_buffer buffer;
  auto sink = std::back_inserter(buffer);
  if (!p.unstable.empty()) {
    // A comment line before the header, only then: a diverging prediction is marked in the file.
    buffer.append(std::string_view("# unstable_models:"));
    for (motion::Axis axis : p.unstable) fmt::format_to(sink, " {}", motion::axis_name(axis));
    buffer.push_back('\n');
  }
  buffer.append(std::string_view("t"));
  for (motion::Axis axis : p.axes) {
    const char* a = motion::axis_name(axis);
    fmt::format_to(sink, ",{0}_cmd,{0}_pred,{0}_err", a);
  }
  buffer.append(std::string_view(",contour_err,path"));
  if (measured != nullptr) {
    for (motion::Axis axis : p.axes) fmt::format_to(sink, ",{0}_meas,{0}_meas_err", motion::axis_name(axis));
    buffer.append(std::string_view(",contour_err_meas"));
  }
  buffer.push_back('\n');
  const int decimals = detail::time_decimals(0.0, p.ts);
  for (std::size_t k = 0; k < p.size(); ++k) {
    detail::append_time(buffer, static_cast<double>(k) * p.ts, decimals);
    for (std::size_t i = 0; i < p.axes.size(); ++i)
      fmt::format_to(sink, ",{},{},{}", p.command[i][k], p.predicted[i][k], p.tracking_error(i, k));
    fmt::format_to(sink, ",{},{}", p.contour_error[k], motion::path_kind_name(p.kind[k]));
    if (measured != nullptr) {
      for (std::size_t i = 0; i < p.axes.size(); ++i) {
        append_optional(buffer, measured->actual[i][k]);
        append_optional(buffer, measured->tracking_error[i][k]);
      }
      append_optional(buffer, measured->contour_error[k]);
    }
    buffer.push_back('\n');
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
