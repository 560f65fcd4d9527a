// `servotwin shaper compare`: the table and JSON rows agree with what `shaper design` states for
// each shaper (residual at design, insensitivity band, smoothing: computed there through a
// different path of the CLI), the report is written with its four charts, and bad input gives
// exit status 3 naming the file or option (2 for a missing argument).
#include <nlohmann/json.hpp>

#include <cmath>

#include "cli_support.hpp"

namespace servotwin::cli_test {
namespace {

class ShaperCompare : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    for (const char* args : {"--type zv --freq-hz 40 --zeta 0.1 -o zv.json", "--type mzv --freq-hz 40 --zeta 0.1 -o mzv.json",
                             "--type ei --freq-hz 40 --zeta 0.1 -o ei.json",
                             "--type zv4 --preset zvd --freq-hz 25 --zeta 0.02 -o zv4.json"}) {
      const Result r = run(std::string("-q shaper design ") + args);
      ASSERT_EQ(r.status, 0) << args << r.err;
    }
  }
};

TEST_F(ShaperCompare, JsonRowsAgreeWithTheDesignedShapers) {
  const Result r = run("shaper compare zv.json mzv.json ei.json zv4.json --json --level 0.05 --accel 5000 --scv 5");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 4u);
  const char* files[] = {"zv.json", "mzv.json", "ei.json", "zv4.json"};
  for (std::size_t i = 0; i < 4; ++i) {
    SCOPED_TRACE(files[i]);
    const auto designed = nlohmann::json::parse(slurp(path(files[i])));
    const auto& row = rows[i];
    EXPECT_EQ(row.at("file"), files[i]);
    EXPECT_EQ(row.at("type"), designed.at("type"));
    EXPECT_NEAR(row.at("freq_hz").get<double>(), designed.at("freq_hz").get<double>(), 1e-12);
    EXPECT_EQ(row.at("impulse_count").get<std::size_t>(), designed.at("times_s").size());
    EXPECT_NEAR(row.at("duration_s").get<double>(), designed.at("duration_s").get<double>(), 1e-15);
    EXPECT_NEAR(row.at("residual_at_design").get<double>(), designed.at("residual_at_design").get<double>(), 1e-15);
    const auto& robust = designed.at("robustness");
    EXPECT_NEAR(row.at("band_width_normalized").get<double>(), robust.at("band_width_normalized").get<double>(), 1e-12);
    EXPECT_NEAR(row.at("band_low_hz").get<double>(), robust.at("band_low_hz").get<double>(), 1e-9);
    EXPECT_NEAR(row.at("band_high_hz").get<double>(), robust.at("band_high_hz").get<double>(), 1e-9);
    EXPECT_NEAR(row.at("smoothing").get<double>(), robust.at("smoothing").get<double>(), 1e-15);
    EXPECT_GT(row.at("max_accel").get<double>(), 0.0);
  }
  // Longer shapers are more robust and smooth more: ZV < MZV < EI at the same mode.
  EXPECT_LT(rows[0].at("band_width_normalized").get<double>(), rows[1].at("band_width_normalized").get<double>());
  EXPECT_LT(rows[1].at("band_width_normalized").get<double>(), rows[2].at("band_width_normalized").get<double>());
  EXPECT_GT(rows[0].at("max_accel").get<double>(), rows[2].at("max_accel").get<double>());
}

TEST_F(ShaperCompare, TableAndReport) {
  const Result r = run("shaper compare zv.json zv4.json --report shapers.html --freq-max-hz 120 --title 'X axis'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("zv.json"), std::string::npos);
  EXPECT_NE(r.out.find("zv4.json"), std::string::npos);
  EXPECT_NE(r.out.find("band V<=5% [Hz]"), std::string::npos);
  EXPECT_NE(r.err.find("wrote report shapers.html"), std::string::npos);
  const std::string html = slurp(path("shapers.html"));
  std::size_t figures = 0;
  for (auto at = html.find("<figure class=\"chart"); at != std::string::npos; at = html.find("<figure class=\"chart", at + 1))
    ++figures;
  EXPECT_EQ(figures, 4u);
  EXPECT_NE(html.find("<h1>X axis</h1>"), std::string::npos);
  EXPECT_NE(html.find("from 0 to 120 Hz"), std::string::npos);
  // The report is never replaced without --force.
  EXPECT_EQ(run("shaper compare zv.json --report shapers.html").status, 3);
  EXPECT_EQ(run("-f shaper compare zv.json --report shapers.html").status, 0);
}

TEST_F(ShaperCompare, BadInputNamesTheFileOrOption) {
  const auto expect_bad = [&](const std::string& args, const std::string& needle) {
    const Result r = run("shaper compare " + args);
    EXPECT_EQ(r.status, 3) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  };
  expect_bad("zv.json missing.json", "missing.json");
  write("broken.json", "{\"format\": \"servotwin.shaper/1\", \"type\": \"zv\"}");
  expect_bad("zv.json broken.json", "broken.json");
  write("sum.json", "{\"format\": \"servotwin.shaper/1\", \"type\": \"zv\", \"freq_hz\": 10, \"zeta\": 0, "
                    "\"times_s\": [0, 0.05], \"amplitudes\": [0.5, 0.6]}");
  expect_bad("sum.json", "sum.json");
  expect_bad("zv.json --level 1.5", "--level");
  expect_bad("zv.json --accel -1", "--accel");
  expect_bad("zv.json --max-smoothing 0", "--max-smoothing");
  expect_bad("zv.json --freq-max-hz -3 --report r.html", "--freq-max-hz");
  EXPECT_FALSE(fs::exists(path("r.html")));  // nothing written on error
  EXPECT_EQ(run("shaper compare").status, 2);  // no shaper: usage error
  EXPECT_EQ(run("shaper compare --json").status, 2);
}

}  // namespace
}  // namespace servotwin::cli_test
