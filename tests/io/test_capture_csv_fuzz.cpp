// Replays the capture-CSV fuzz corpus and every input that once crashed the reader
// (tests/data/io/fuzz_regressions/) through the fuzzer's own harness, compiled with gcc.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "../../fuzz/capture_csv_harness.hpp"

namespace {

void replay_folder(const std::filesystem::path& folder, std::size_t& count) {
  if (!std::filesystem::exists(folder)) return;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(entry.path().string());
    servotwin::fuzz::capture_csv_one_input(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    ++count;
  }
}

TEST(CaptureCsvFuzz, CorpusAndRegressionsReplayCleanly) {
  std::size_t count = 0;
  replay_folder(SERVOTWIN_TEST_DATA_DIR "/../../fuzz/corpus/capture_csv", count);
  replay_folder(SERVOTWIN_TEST_DATA_DIR "/io/fuzz_regressions", count);
  EXPECT_GE(count, 4U);
}

TEST(CaptureCsvFuzz, HandcraftedNastyInputs) {
  const std::vector<std::string> inputs = {
      std::string("\0\0\0", 3), "t,x_cmd,x_act\n0,0,0\n0,0,0\n", "t,x_cmd,x_act\n\"0\",\"1\",\"2\"\n0.001,1,2\n",
      ",,,\n,,,\n", "t,x_cmd,x_act\r\n0,0,0\r\n0.001,1,1\r\n", "\xEF\xBB\xBFt,x_cmd,x_act\n0,0,0\n1e-300,1,1\n",
      "t,x_cmd,x_act\n0,0,0\n1e308,1,1\n1.7e308,2,2\n", "t,_cmd,_act\n0,0,0\n1,1,1\n"};
  for (const auto& s : inputs) servotwin::fuzz::capture_csv_one_input(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
}

}  // namespace
