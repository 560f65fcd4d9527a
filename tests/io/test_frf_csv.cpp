// Frequency-response CSV: exact round trip, the documented header, the accepted reduced forms,
// and bad input named by file:line:column. Expected values are literal file contents and closed
// forms (dB/degree conversions).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/io/frf_csv.hpp"

namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace frf_csv_test {

using servotwin::core::FrequencyPoint;
using servotwin::core::FrequencyResponse;
using servotwin::core::InputError;
using servotwin::core::QualityKind;
using servotwin::io::read_frf_csv;
using ::testing::HasSubstr;

FrequencyResponse read(const std::string& text) {
  std::istringstream in(text);
  return read_frf_csv(in, "frf.csv");
}

InputError error_of(const std::string& text) {
  try {
    read(text);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return InputError("none");
}

FrequencyResponse sample() {
  FrequencyResponse r;
  r.duration_s = 19.5;
  r.points.push_back(FrequencyPoint{1.5, {0.1, -0.2}, 0.99, 120.0, 0.8, 1e-3});
  r.points.push_back(FrequencyPoint{2.25, {-1.0 / 3.0, 1e-7}, 0.5, 0.0, 0.0, 0.0});
  r.points.push_back(FrequencyPoint{100.0, {0.0, 0.0}, 0.0, 0.0, 2.0, 0.1});  // a zero point
  return r;
}

TEST(FrfCsv, WritesTheDocumentedHeader) {
  std::ostringstream out;
  servotwin::io::write_frf_csv(out, sample(), {"method: test"});
  const std::string text = out.str();
  EXPECT_EQ(text.substr(0, text.find("1.5,")),
            "# format: servotwin.frf/1\n# quality: coherence\n# duration_s: 19.5\n# method: test\n"
            "freq_hz,re,im,mag_db,phase_deg,coherence_or_thd,snr,amplitude,std,valid\n");
  // 20·log10|0.1 − 0.2j| and arg in degrees, shortest round-trip.
  const double mag_db = 20.0 * std::log10(std::abs(std::complex<double>(0.1, -0.2)));
  const double phase = std::atan2(-0.2, 0.1) * 180.0 / std::numbers::pi;
  EXPECT_THAT(text, HasSubstr(fmt::format("1.5,0.1,-0.2,{},{},0.99,120,0.8,0.001,1\n", mag_db, phase)));
}

TEST(FrfCsv, RoundTripIsExact) {
  std::ostringstream out;
  FrequencyResponse r = sample();
  r.quality_kind = QualityKind::kThd;
  r.points[1].valid = false;  // issue 25 §1: an invalid point keeps its place and its reason
  r.points[1].note = "THD 0.39 above 0.07: amplitude at its ceiling";
  servotwin::io::write_frf_csv(out, r);
  EXPECT_THAT(out.str(), HasSubstr("# invalid 2.25 Hz: THD 0.39 above 0.07: amplitude at its ceiling\n"));
  const FrequencyResponse back = read(out.str());
  EXPECT_EQ(back.quality_kind, QualityKind::kThd);
  EXPECT_EQ(back.duration_s, 19.5);
  ASSERT_EQ(back.size(), r.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(back.points[i].freq_hz, r.points[i].freq_hz);
    EXPECT_EQ(back.points[i].value, r.points[i].value);
    EXPECT_EQ(back.points[i].quality, r.points[i].quality);
    EXPECT_EQ(back.points[i].snr, r.points[i].snr);
    EXPECT_EQ(back.points[i].amplitude, r.points[i].amplitude);
    EXPECT_EQ(back.points[i].std_dev, r.points[i].std_dev);
    EXPECT_EQ(back.points[i].valid, r.points[i].valid);
    EXPECT_EQ(back.points[i].note, r.points[i].note);
  }
  EXPECT_EQ(back.valid_only().size(), 2u);
  EXPECT_THAT(error_of("freq_hz,re,im,valid\n1,1,0,1\n2,1,0,0.5\n").what(),
              HasSubstr("frf.csv:3:7 (valid): column 'valid' must be 0 or 1, got 0.5"));
}

TEST(FrfCsv, AcceptsReImOnly) {
  const auto r = read("freq_hz,re,im\n1,1,0\n2,0,-1\n");
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r.points[1].value, std::complex<double>(0, -1));
  EXPECT_EQ(r.points[1].quality, 0.0);
  EXPECT_EQ(r.quality_kind, QualityKind::kCoherence);
  EXPECT_FALSE(r.duration_s);
}

TEST(FrfCsv, AcceptsMagnitudeAndPhaseInAnyOrder) {
  // -20 dB at 90 degrees = 0.1j; 6.0206 dB at 180 degrees ≈ -2.
  const auto r = read("phase_deg,freq_hz,mag_db,thd\n90,10,-20,0.01\n180,20,6.020599913279624,0.02\n");
  EXPECT_NEAR(r.points[0].value.real(), 0.0, 1e-15);
  EXPECT_NEAR(r.points[0].value.imag(), 0.1, 1e-15);
  EXPECT_NEAR(r.points[1].value.real(), -2.0, 1e-12);
  EXPECT_EQ(r.quality_kind, QualityKind::kThd);  // from the column name
  EXPECT_EQ(r.points[1].quality, 0.02);
}

// Issue 27 §5 (fuzzing): a magnitude beyond a double is refused naming mag_db; a phase of 1e308
// degrees is a phase (it overflowed to infinity when multiplied by π first, then read as NaN).
TEST(FrfCsv, MagnitudeOverflowIsRefusedAndHugePhasesAreRead) {
  EXPECT_THAT(error_of("freq_hz,mag_db,phase_deg\n1,7000,0\n").what(), HasSubstr("(mag_db): the magnitude overflows a double"));
  EXPECT_THAT(error_of("freq_hz,re,im\n1,1.5e308,1.5e308\n2,1,0\n").what(), HasSubstr("|re + j im| overflows"));
  const auto r = read("freq_hz,mag_db,phase_deg\n1,0,1e308\n2,0,0\n");
  EXPECT_NEAR(std::abs(r.points[0].value), 1.0, 1e-12);  // |e^{jφ}| = 1 for any finite φ
}

TEST(FrfCsv, MissingColumnsAreNamed) {
  auto e = error_of("f,re,im\n1,1,0\n2,1,0\n");
  EXPECT_EQ(e.where().line, 1u);
  EXPECT_THAT(e.what(), HasSubstr("missing column 'freq_hz' (columns: f, re, im)"));
  e = error_of("freq_hz,re,phase_deg\n1,1,0\n2,1,0\n");
  EXPECT_THAT(e.what(), HasSubstr("expected the columns 're, im' or 'mag_db, phase_deg'"));
}

TEST(FrfCsv, NonIncreasingFrequencyNamesLineAndColumn) {
  auto e = error_of("# c\nre,freq_hz,im\n1,1,0\n1,3,0\n1,3,0\n");
  EXPECT_EQ(e.where().file, "frf.csv");
  EXPECT_EQ(e.where().line, 5u);
  EXPECT_EQ(e.where().column, 3u);
  EXPECT_EQ(e.where().field, "freq_hz");
  EXPECT_THAT(e.what(), HasSubstr("frequencies must increase: 3 Hz after 3 Hz"));
  e = error_of("freq_hz,re,im\n0,1,0\n1,1,0\n");
  EXPECT_EQ(e.where().line, 2u);
  EXPECT_THAT(e.what(), HasSubstr("must be > 0 Hz"));
}

TEST(FrfCsv, NanAndNegativeQualityAreRejected) {
  auto e = error_of("freq_hz,re,im\n1,1,0\n2,nan,0\n");
  EXPECT_EQ(e.where().line, 3u);
  EXPECT_EQ(e.where().column, 3u);
  EXPECT_THAT(e.what(), HasSubstr("column 're'"));
  e = error_of("freq_hz,re,im,coherence_or_thd\n1,1,0,0.5\n2,1,0,-0.1\n");
  EXPECT_EQ(e.where().column, 7u);
  EXPECT_THAT(e.what(), HasSubstr("must be >= 0"));
  e = error_of("freq_hz,re,im\n1,1,0\n2,1\n");
  EXPECT_THAT(e.what(), HasSubstr("expected 3 fields as in the header, found 2"));
}

TEST(FrfCsv, TooFewPoints) {
  auto e = error_of("freq_hz,re,im\n1,1,0\n");
  EXPECT_THAT(e.what(), HasSubstr("1 frequency point: at least 2 are needed"));
  EXPECT_THAT(error_of("").what(), HasSubstr("empty file"));
  std::istringstream in("freq_hz,re,im\n1,1,0\n");
  EXPECT_EQ(read_frf_csv(in, "one.csv", {.min_points = 1}).size(), 1u);
}

TEST(FrfCsv, CommentsAreChecked) {
  auto e = error_of("# format: servotwin.frf/2\nfreq_hz,re,im\n1,1,0\n2,1,0\n");
  EXPECT_EQ(e.where().line, 1u);
  EXPECT_EQ(e.where().column, 11u);
  EXPECT_THAT(e.what(), HasSubstr("unsupported version"));
  EXPECT_THAT(error_of("# format: servotwin.axis-model/1\nfreq_hz,re,im\n1,1,0\n2,1,0\n").what(),
              HasSubstr("not a frequency-response file"));
  EXPECT_THAT(error_of("# quality: snr\nfreq_hz,re,im\n1,1,0\n2,1,0\n").what(), HasSubstr("unknown quality kind"));
  EXPECT_THAT(error_of("# duration_s: -3\nfreq_hz,re,im\n1,1,0\n2,1,0\n").what(), HasSubstr("duration must be > 0"));
  EXPECT_THAT(error_of("# duration_s: soon\nfreq_hz,re,im\n1,1,0\n2,1,0\n").what(), HasSubstr("expected a number"));
  EXPECT_THAT(error_of("# quality: coherence\nfreq_hz,re,im,thd\n1,1,0,0\n2,1,0,0\n").what(),
              HasSubstr("contradicts"));
  // Minor versions and unknown comments are fine.
  EXPECT_EQ(read("# format: servotwin.frf/1.3\n# note: x\nfreq_hz,re,im\n1,1,0\n2,1,0\n").size(), 2u);
}

TEST(FrfCsv, WriterRefusesWhatTheReaderWouldReject) {
  std::ostringstream out;
  FrequencyResponse r = sample();
  r.points[1].freq_hz = 1.5;
  EXPECT_THROW(servotwin::io::write_frf_csv(out, r), std::invalid_argument);
  r = sample();
  r.points[0].value = {std::nan(""), 0.0};
  EXPECT_THROW(servotwin::io::write_frf_csv(out, r), std::invalid_argument);
  EXPECT_THROW(servotwin::io::write_frf_csv(out, sample(), {"two\nlines"}), std::invalid_argument);
}

}  // namespace frf_csv_test
}  // namespace
