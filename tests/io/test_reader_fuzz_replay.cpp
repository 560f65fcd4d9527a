// Replays the corpus of every reader fuzzer (fuzz/corpus/<reader>/, issue 27 §5) and every input
// that once broke a reader (tests/data/io/fuzz_regressions/<reader>/) through the fuzzers' own
// harnesses (fuzz/reader_harnesses.hpp), compiled with gcc: the contract holds for each.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../../fuzz/reader_harnesses.hpp"

namespace {

using Harness = void (*)(const std::uint8_t*, std::size_t);

std::size_t replay_folder(const std::filesystem::path& folder, Harness harness) {
  std::size_t count = 0;
  if (!std::filesystem::exists(folder)) return count;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(entry.path().string());
    harness(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    ++count;
  }
  return count;
}

struct Reader {
  const char* name;
  const char* corpus;  ///< folder under fuzz/corpus
  Harness harness;
};

const Reader kReaders[] = {
    {"frf_csv", "frf_csv", servotwin::fuzz::frf_csv_one_input},
    {"klipper_csv", "klipper_csv", servotwin::fuzz::klipper_csv_one_input},
    {"signal_csv", "signal_csv", servotwin::fuzz::signal_csv_one_input},
    {"excitation_csv", "excitation_csv", servotwin::fuzz::excitation_csv_one_input},
    {"axis_model", "axis_model", servotwin::fuzz::axis_model_one_input},
    {"normal_equations", "normal_equations", servotwin::fuzz::normal_equations_one_input},
    {"machine", "machine", servotwin::fuzz::machine_one_input},
    {"plant", "plant", servotwin::fuzz::plant_one_input},
    {"plant_model", "plant_model", servotwin::fuzz::plant_model_one_input},
    {"shaper", "shaper", servotwin::fuzz::shaper_one_input},
    {"controller", "controller", servotwin::fuzz::controller_one_input},
    {"trace_profile", "trace_profile", servotwin::fuzz::trace_profile_one_input},
    {"interpolation", "gcode", servotwin::fuzz::interpolation_one_input},
};

TEST(ReaderFuzz, CorporaAndRegressionsReplayCleanly) {
  for (const Reader& r : kReaders) {
    SCOPED_TRACE(r.name);
    const std::size_t seeds = replay_folder(std::string(SERVOTWIN_TEST_DATA_DIR "/../../fuzz/corpus/") + r.corpus, r.harness);
    EXPECT_GE(seeds, 1U) << "no corpus for " << r.name;
    replay_folder(std::string(SERVOTWIN_TEST_DATA_DIR "/io/fuzz_regressions/") + r.name, r.harness);
  }
}

TEST(ReaderFuzz, HandcraftedNastyInputs) {
  const std::vector<std::string> inputs = {
      "", std::string("\0\0\0", 3), "{", "{}", "[]", "null", "{\"format\": 1}", "{\"a\": 1, \"a\": 2}",
      "{\"format\": \"servotwin.plant/1\", \"type\": \"mass-chain\", \"inertias\": [1e-300], \"ts\": 1e-300}",
      "freq_hz,re,im\n1,1e308,1e308\n2,-1e308,1e308\n", "# x\nfreq_hz,re,im\n", "t,u\n0,1\n0,2\n",
      "G01 X1e9 F1\nG02 X-1e9 I-1e9 F1\n", "\xEF\xBB\xBF{\"format\": \"servotwin.shaper/1\"}"};
  for (const std::string& s : inputs)
    for (const Reader& r : kReaders) r.harness(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
}

}  // namespace
