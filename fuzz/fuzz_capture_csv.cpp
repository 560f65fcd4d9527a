// libFuzzer target for the capture CSV reader: cmake --preset fuzz && cmake --build --preset fuzz,
// then build/fuzz/fuzz/fuzz_capture_csv fuzz/corpus/capture_csv -max_total_time=300
#include "capture_csv_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  servotwin::fuzz::capture_csv_one_input(data, size);
  return 0;
}
