// libFuzzer target for the G-code readers and writers; the checks live in gcode_harness.hpp so the
// replay test can run them without clang.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "gcode_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (const auto failure = servotwin::fuzz::check_gcode_input(data, size)) {
    std::fprintf(stderr, "gcode invariant violated: %s\n", failure->c_str());
    std::abort();
  }
  return 0;
}
