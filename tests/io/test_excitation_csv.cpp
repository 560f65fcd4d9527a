// Excitation CSV (io/excitation_csv.hpp): what is written is read back exactly (shortest
// round-trip numbers), and a damaged file is refused at its line and key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_design.hpp"
#include "servotwin/io/excitation_csv.hpp"

namespace servotwin::io {
namespace {

frf::Excitation excitation_csv_design(frf::ExcitationType type) {
  frf::ExcitationRequest r;
  r.type = type;
  r.f_begin_hz = 2.0;
  r.f_end_hz = 100.0;
  r.ts = 0.002;
  r.duration_s = 40.0;
  r.amplitude = 0.75;
  r.periods = type == frf::ExcitationType::kSineSteps ? 0 : 20;  // periods of 1000 samples, lines 4 ... 200
  return frf::design_excitation(r);
}

std::string excitation_csv_text(const frf::Excitation& e) {
  std::ostringstream out;
  write_excitation_csv(out, e, {"a free comment"});
  return out.str();
}

std::string excitation_csv_error(const std::string& text) {
  std::istringstream in(text);
  try {
    (void)read_excitation_csv(in, "exc.csv");
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(ExcitationCsv, EveryTypeRoundTripsExactly) {
  for (const auto type : {frf::ExcitationType::kMultisine, frf::ExcitationType::kChirp, frf::ExcitationType::kSineSteps}) {
    const frf::Excitation e = excitation_csv_design(type);
    std::istringstream in(excitation_csv_text(e));
    const frf::Excitation back = read_excitation_csv(in, "exc.csv");
    EXPECT_EQ(back.type, e.type);
    EXPECT_EQ(back.ts, e.ts);
    EXPECT_EQ(back.f_begin_hz, 2.0);
    EXPECT_EQ(back.f_end_hz, 100.0);
    EXPECT_EQ(back.samples, e.samples);
    EXPECT_EQ(back.amplitude, 0.75);
    EXPECT_EQ(back.period_samples, e.period_samples);
    EXPECT_EQ(back.periods, e.periods);
    EXPECT_EQ(back.lines, e.lines);
    ASSERT_EQ(back.steps.size(), e.steps.size());
    for (std::size_t j = 0; j < e.steps.size(); ++j) {
      EXPECT_EQ(back.steps[j].freq_hz, e.steps[j].freq_hz);
      EXPECT_EQ(back.steps[j].begin, e.steps[j].begin);
      EXPECT_EQ(back.steps[j].cycles, e.steps[j].cycles);
    }
  }
}

TEST(ExcitationCsv, DamagedFilesAreRefusedAtTheirLine) {
  const std::string good = excitation_csv_text(excitation_csv_design(frf::ExcitationType::kMultisine));
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  EXPECT_THAT(excitation_csv_error(with("# format: servotwin.excitation/1\n", "")),
              ::testing::HasSubstr("exc.csv (format): missing '# format:' line"));
  EXPECT_THAT(excitation_csv_error(with("servotwin.excitation/1", "servotwin.frf/1")),
              ::testing::HasSubstr("exc.csv:1:11 (format): not an excitation file"));
  EXPECT_THAT(excitation_csv_error(with("# type: multisine", "# type: square")),
              ::testing::HasSubstr("exc.csv:2:9 (type): unknown excitation type 'square'"));
  EXPECT_THAT(excitation_csv_error(with("# lines: 4 5", "# lines: 5 4")), ::testing::HasSubstr("(lines): lines must rise"));
  EXPECT_THAT(excitation_csv_error(with("# lines: 4", "# lines: 9999 4")), ::testing::HasSubstr("(lines): line 9999"));
  EXPECT_THAT(excitation_csv_error(with("# ts: 0.002", "# ts: abc")), ::testing::HasSubstr("exc.csv:3:7"));
  EXPECT_THAT(excitation_csv_error(with("# periods: 20", "# periods: 20\n# periods: 20")),
              ::testing::HasSubstr("'# periods:' appears twice"));
  EXPECT_THAT(excitation_csv_error(with("# periods: 20", "# periods: 21")),
              ::testing::HasSubstr("(u): 20000 samples, but the design in the comments makes 21000"));
  EXPECT_THAT(excitation_csv_error(with("\n0.002,", "\n0.003,")), ::testing::HasSubstr("(t)"));
}

}  // namespace
}  // namespace servotwin::io
