// Replays the G-code fuzzer's seed corpus (fuzz/corpus/gcode) and every input the fuzzer ever
// crashed on (tests/data/motion/fuzz_regressions) through the fuzzer's own checks
// (fuzz/gcode_harness.hpp), compiled here with the regular compiler so CI needs no clang.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "../../fuzz/gcode_harness.hpp"
#include "gcode_test_support.hpp"

namespace servotwin::motion {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().filename() != "README.md") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

void replay(const fs::path& dir, std::size_t at_least) {
  const std::vector<fs::path> files = files_in(dir);
  EXPECT_GE(files.size(), at_least) << dir;
  for (const fs::path& file : files) {
    const std::string data = test::read_text(file.string());
    const auto failure =
        servotwin::fuzz::check_gcode_input(reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
    EXPECT_FALSE(failure.has_value()) << file << ": " << failure.value_or("");
  }
}

TEST(GcodeFuzzReplay, SeedCorpus) {
  replay(fs::path(SERVOTWIN_TEST_DATA_DIR) / ".." / ".." / "fuzz" / "corpus" / "gcode", 5);
}

TEST(GcodeFuzzReplay, Regressions) {
  replay(fs::path(SERVOTWIN_TEST_DATA_DIR) / "motion" / "fuzz_regressions", 0);
}

TEST(GcodeFuzzReplay, HarnessPassesRejectedAndValidInputs) {
  for (const std::string& text : {std::string("G01 X1 F100\nG02 X1.2.3\n"), std::string("\xff\xfe"),
                                  std::string("G00 X1\nG01 Y2 F5\nG03 X0 Y1 R1\n")}) {
    const auto failure = servotwin::fuzz::check_gcode_input(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
    EXPECT_FALSE(failure.has_value()) << failure.value_or("");
  }
}

// The checks can fail: altered programs are caught.
TEST(GcodeFuzzReplay, HarnessChecksDetectDifferences) {
  using servotwin::fuzz::gcode_detail::check_consistent;
  using servotwin::fuzz::gcode_detail::compare_motion;
  const Program p = test::iso("G01 X1 F100 M3\nG02 X3 Y0 I1 J0\n");
  EXPECT_TRUE(compare_motion(p, p, "same").empty());
  Program moved = p;
  moved.blocks[1].end[0] = 3.0000001;
  EXPECT_FALSE(compare_motion(p, moved, "end").empty());
  Program centre = p;
  centre.blocks[1].center[0] += 1e-9;
  EXPECT_FALSE(compare_motion(p, centre, "centre").empty());
  Program codes = p;
  codes.blocks[0].m_codes = {5};
  EXPECT_FALSE(compare_motion(p, codes, "m").empty());
  EXPECT_TRUE(check_consistent(p, "p").empty());
  Program open_arc = p;
  open_arc.blocks[1].end[0] = 3.1;  // radius 1 at the start, 1.1 at the end
  EXPECT_FALSE(check_consistent(open_arc, "arc").empty());
  Program broken = p;
  broken.blocks[1].start[1] = 1.0;
  EXPECT_FALSE(check_consistent(broken, "chain").empty());
}

}  // namespace
}  // namespace servotwin::motion
