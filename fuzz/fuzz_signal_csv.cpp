// libFuzzer target for the signal csv reader (issue 27 §5; contract in reader_harnesses.hpp):
// cmake --preset fuzz && cmake --build --preset fuzz, then
// build/fuzz/fuzz/fuzz_signal_csv fuzz/corpus/signal_csv -max_total_time=60
#include "reader_harnesses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  servotwin::fuzz::signal_csv_one_input(data, size);
  return 0;
}
