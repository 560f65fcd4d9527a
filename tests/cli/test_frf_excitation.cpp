// End-to-end tests of `servotwin frf excitation` and of `frf estimate --excitation` (issue 25 §4):
// a design written, "played" by a drive simulated here (a discrete resonance, sample by sample,
// recorded with a lead-in and scaled), and read back. Expected responses: the resonance's closed
// form at z = e^{jωts}; the FdiTools recording's period (2500 samples) from its README.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fmt/format.h>
#include <numbers>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "servotwin/io/excitation_csv.hpp"
#include "servotwin/io/frf_csv.hpp"

namespace {

using servotwin::cli_test::Cli;
using servotwin::cli_test::slurp;
using ::testing::HasSubstr;

class FrfExcitation : public Cli {
 protected:
  /// The drive: y = H(z) u with H = (0.1 + 0.05 z⁻¹ + 0.02 z⁻²)/(1 − 1.6 z⁻¹ + 0.9 z⁻²), recorded
  /// from `lead` samples before the sequence starts, the applied input at 0.9 of the table.
  void play(const std::string& excitation, const std::string& recording, std::size_t lead, double ts) const {
    const auto e = servotwin::io::read_excitation_file(path(excitation).string());
    std::vector<double> u(lead, 0.0);
    for (double v : e.samples) u.push_back(0.9 * v);
    u.resize(u.size() + 300, 0.0);
    std::string text = "time_ms,iq,speed\n";
    double u1 = 0, u2 = 0, y1 = 0, y2 = 0;
    for (std::size_t n = 0; n < u.size(); ++n) {
      const double y = 0.1 * u[n] + 0.05 * u1 + 0.02 * u2 + 1.6 * y1 - 0.9 * y2;
      text += fmt::format("{},{},{}\n", static_cast<double>(n) * ts * 1e3, u[n], y);
      u2 = u1;
      u1 = u[n];
      y2 = y1;
      y1 = y;
    }
    write(recording, text);
  }
  static std::complex<double> drive_plant(double freq_hz, double ts) {
    const std::complex<double> z1 = std::polar(1.0, -2.0 * std::numbers::pi * freq_hz * ts);
    return (0.1 + 0.05 * z1 + 0.02 * z1 * z1) / (1.0 - 1.6 * z1 + 0.9 * z1 * z1);
  }
  void expect_plant(const std::string& frf_file, double ts, double tolerance) const {
    const auto frf = servotwin::io::read_frf_file(path(frf_file).string());
    ASSERT_GE(frf.size(), 10u);
    for (const auto& p : frf.points) {
      const auto h = drive_plant(p.freq_hz, ts);
      EXPECT_LT(std::abs(p.value - h), tolerance * std::abs(h)) << frf_file << " at " << p.freq_hz << " Hz";
    }
  }
};

TEST_F(FrfExcitation, MultisineWrittenPlayedAndReadBack) {
  auto r = run("frf excitation --type multisine --range-hz 1:200 --ts 0.001 --duration 6 --amplitude 2 -o ms.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("multisine: 6 periods of 1000 samples (1 s each), 200 lines 1 ... 200 Hz"));
  EXPECT_THAT(r.out, HasSubstr("crest factor"));
  const std::string text = slurp(path("ms.csv"));
  EXPECT_EQ(text.rfind("# format: servotwin.excitation/1\n# type: multisine\n# ts: 0.001\n# range_hz: 1 200\n"
                       "# amplitude: 2\n",
                       0),
            0u)
      << text.substr(0, 200);
  EXPECT_THAT(text, HasSubstr("\nt,u\n0.000,"));
  EXPECT_THAT(text, HasSubstr("\n0.001,"));
  const auto e = servotwin::io::read_excitation_file(path("ms.csv").string());
  EXPECT_EQ(e.samples.size(), 6000u);
  EXPECT_EQ(e.amplitude, 2.0);

  play("ms.csv", "rec.csv", 417, 0.001);
  r = run("frf estimate rec.csv --input iq --response speed --excitation ms.csv -o frf.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("multisine found at sample 417 (t = 0.417 s), gain 0.9, correlation 1.0000"));
  EXPECT_THAT(r.err, HasSubstr("per-period DFT over periods 2 ... 6 of 6"));
  EXPECT_THAT(r.out, HasSubstr("frf: 200 points, 1 ... 200 Hz"));
  expect_plant("frf.csv", 0.001, 1e-9);  // noise-free, leakage-free: exact to rounding
  EXPECT_THAT(slurp(path("frf.csv")), HasSubstr("# excitation: ms.csv (multisine), found at sample 417"));

  // Without the design: the period is detected from the recorded input.
  r = run("frf estimate rec.csv --input iq --response speed --method multisine --skip-periods 1 -o auto.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("detected a period of 1000 samples"));
}

TEST_F(FrfExcitation, ChirpAndSineStepsReadBack) {
  auto r = run("frf excitation --type chirp --range-hz 2:200 --ts 0.001 --duration 9 --periods 3 --amplitude 1 "
               "-o chirp.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("chirp: 3 logarithmic sweeps of 3 s, 2 ... 200 Hz"));
  play("chirp.csv", "rec_chirp.csv", 50, 0.001);
  r = run("frf estimate rec_chirp.csv --input iq --response speed --excitation chirp.csv -o chirp_frf.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_plant("chirp_frf.csv", 0.001, 1e-9);

  // 21 steps of 2 s: 0.5 s settling, 1.5 s measured (3 cycles of 2 Hz).
  r = run("frf excitation --type sine-steps --range-hz 2:200 --ts 0.001 --duration 42 --amplitude 1 -o steps.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("sine-steps: 21 frequencies 2 ... 200 Hz, 2 s each (0.5 s settling, then 1.5 s measured)"));
  play("steps.csv", "rec_steps.csv", 1234, 0.001);
  r = run("frf estimate rec_steps.csv --input iq --response speed --excitation steps.csv -o steps_frf.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("frf: 21 points"));
  EXPECT_THAT(r.out, HasSubstr("THD median"));
  EXPECT_THAT(slurp(path("steps_frf.csv")), HasSubstr("# quality: thd"));
  expect_plant("steps_frf.csv", 0.001, 1e-9);
}

TEST_F(FrfExcitation, FdiToolsPeriodIsDetected) {
  const std::string data = std::string(SERVOTWIN_REPO_DATA_DIR) + "/twomass-motor-bench-fditools/MultisineTypeA.csv";
  const auto r = run("frf estimate '" + data + "' --input iq_adx --response theta_mx --method multisine --skip-periods 1 -o a.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  // README of the data: 20 periods of 1 s at 2500 Hz.
  EXPECT_THAT(r.err, HasSubstr("detected a period of 2500 samples"));
  EXPECT_THAT(r.out, HasSubstr("frf: 240 points, 11 ... 250 Hz"));
}

TEST_F(FrfExcitation, BadInputIsRefusedAndNothingIsWritten) {
  // Beyond Nyquist, beyond the drive's limit, too short, a bad range, too few periods.
  auto r = run("frf excitation --range-hz 1:600 --ts 0.001 --duration 10 --amplitude 1 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--range-hz): 600 Hz is at or beyond the Nyquist frequency 500 Hz"));
  r = run("frf excitation --range-hz 1:100 --ts 0.001 --duration 10 --amplitude 3 --limit 2 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--amplitude): the peak 3 exceeds --limit 2"));
  r = run("frf excitation --range-hz 1:100 --ts 0.001 --duration 1.5 --amplitude 1 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--duration)"));
  EXPECT_THAT(r.err, HasSubstr("give at least 2 s"));
  r = run("frf excitation --type sine-steps --range-hz 1:100 --ts 0.001 --duration 10 --amplitude 1 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--duration): 21 steps"));
  r = run("frf excitation --range-hz 100 --ts 0.001 --duration 10 --amplitude 1 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--range-hz): expected BEGIN:END"));
  r = run("frf excitation --range-hz 1:100 --ts 0.001 --duration 10 --amplitude 1 --periods 1 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--periods)"));
  r = run("frf excitation --range-hz 1:100 --ts -1 --duration 10 --amplitude 1 -o x.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("(--ts)"));
  EXPECT_FALSE(std::filesystem::exists(path("x.csv")));
  EXPECT_EQ(run("frf excitation --type square --range-hz 1:100 --ts 0.001 --duration 10 --amplitude 1 -o x.csv").status, 2);

  // A recording at another sample period, or one that does not hold the excitation.
  ASSERT_EQ(run("frf excitation --range-hz 1:100 --ts 0.001 --duration 4 --amplitude 1 -o ms.csv").status, 0);
  play("ms.csv", "rec.csv", 10, 0.0005);
  r = run("frf estimate rec.csv --input iq --response speed --excitation ms.csv -o f.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("sampled every 0.0005 s, but ms.csv was designed for 0.001 s"));
  play("ms.csv", "rec.csv", 10, 0.001);
  r = run("frf estimate rec.csv --input speed --response iq --excitation ms.csv -o f.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("rec.csv (speed): does not hold the excitation"));
  EXPECT_FALSE(std::filesystem::exists(path("f.csv")));
  // The design decides the estimator: an option choosing another is a usage error.
  EXPECT_EQ(run("frf estimate rec.csv --input iq --response speed --excitation ms.csv --method h1 -o f.csv").status, 2);
  EXPECT_EQ(run("frf estimate rec.csv --input iq --response speed --excitation ms.csv --closed-loop --reference iq "
                "-o f.csv").status,
            2);
  // A damaged design.
  std::string text = slurp(path("ms.csv"));
  text.replace(text.find("# periods: 4"), 12, "# periods: 5");
  write("bad.csv", text);
  r = run("frf estimate rec.csv --input iq --response speed --excitation bad.csv -o f.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("bad.csv (u): 4000 samples, but the design in the comments makes 5000"));
}

}  // namespace
