// libFuzzer target for the trace profile reader (issue 27 §5; contract in reader_harnesses.hpp):
// cmake --preset fuzz && cmake --build --preset fuzz, then
// build/fuzz/fuzz/fuzz_trace_profile fuzz/corpus/trace_profile -max_total_time=60
#include "reader_harnesses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  servotwin::fuzz::trace_profile_one_input(data, size);
  return 0;
}
