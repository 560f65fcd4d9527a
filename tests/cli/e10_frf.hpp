#pragma once
// The frequency response of the catalog's E10 table plant (K = 0.5, a = 0.2, ωz = 1, ζz = 0.06,
// ωn = 3, ζn = 0.15; the `table-5.1` preset's linear part) as a servotwin.frf/1 CSV, noise-free:
// the measured input of the fit and tune command tests.
#include <cstddef>
#include <numbers>
#include <sstream>
#include <string>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/io/frf_csv.hpp"

namespace servotwin::cli_test {

/// `count` log-spaced points from 0.05 to 15 rad/s.
inline std::string e10_csv(std::size_t count) {
  const core::TransferFunction tf(core::Polynomial{0.5, 0.06, 0.5}, core::Polynomial{1.0, 1.1, 9.18, 1.8});
  core::FrequencyResponse r;
  for (double w : core::log_space(0.05, 15.0, count)) {
    core::FrequencyPoint p;
    p.freq_hz = w / (2.0 * std::numbers::pi);
    p.value = tf.frequency_response(w);
    r.points.push_back(p);
  }
  std::ostringstream out;
  io::write_frf_csv(out, r);
  return out.str();
}

}  // namespace servotwin::cli_test
