// libFuzzer target for the axis model reader (issue 27 §5; contract in reader_harnesses.hpp):
// cmake --preset fuzz && cmake --build --preset fuzz, then
// build/fuzz/fuzz/fuzz_axis_model fuzz/corpus/axis_model -max_total_time=60
#include "reader_harnesses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  servotwin::fuzz::axis_model_one_input(data, size);
  return 0;
}
