#pragma once
// Body of the capture-file fuzzer (CSV, halsampler and halscope layouts), shared by the libFuzzer target (fuzz_capture_csv.cpp, clang) and
// the regression test that replays the corpus under gcc (tests/io/test_capture_csv_fuzz.cpp).
// Contract checked: any byte sequence either reads into a consistent capture or raises
// core::InputError; a capture that reads back after writing is identical.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/io/capture_csv.hpp"

namespace servotwin::fuzz {

inline void check_capture(const core::Capture& c) {
  const std::size_t n = c.size();
  if (n < 2 || !(c.ts > 0.0)) std::abort();
  for (const auto& axis : c.axes)
    if (axis.cmd.size() != n || axis.act.size() != n || (!axis.u.empty() && axis.u.size() != n)) std::abort();
}

inline void capture_csv_one_input(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  io::CaptureReadOptions variants[4];
  variants[1].map = {{"x_cmd", "qg"}, {"x_act", "qm"}};
  variants[1].scale = 1000.0;
  variants[1].ts = 0.001;
  // LinuxCNC layouts: halsampler (names given, blank-separated, sample numbers) and halscope logs.
  variants[2].format = io::TraceFormat::Halsampler;
  variants[2].columns = {"x_cmd", "x_act", "x_u"};
  variants[2].ts = 0.001;
  variants[3].format = io::TraceFormat::Halscope;
  for (const auto& options : variants) {
    std::istringstream in(text);
    core::Capture capture;
    try {
      capture = io::read_capture_csv(in, "fuzz.csv", options);
    } catch (const core::InputError&) {
      continue;
    }
    check_capture(capture);
    std::stringstream rewritten;
    io::write_capture_csv(rewritten, capture);
    const core::Capture again = io::read_capture_csv(rewritten, "rewritten.csv");
    if (again.axes.size() != capture.axes.size()) std::abort();
    for (std::size_t i = 0; i < capture.axes.size(); ++i)
      if (again.axes[i].cmd != capture.axes[i].cmd || again.axes[i].act != capture.axes[i].act) std::abort();
  }
}

}  // namespace servotwin::fuzz
