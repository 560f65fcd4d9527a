// `servotwin shaper apply`: end-to-end runs of the built tool. Expected values: the 90-degree
// corner of tests/data/shaping/discrete_reference.json (tools/reference/shaping_discrete_reference.py:
// numpy convolution + distance to the two half-lines), and the interpolator's own straight moves,
// which a shaper must not leave.
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.hpp"

namespace servotwin::cli_test {
namespace {

nlohmann::json corner_reference() {
  std::ifstream in(std::string(SERVOTWIN_TEST_DATA_DIR) + "/shaping/discrete_reference.json");
  return nlohmann::json::parse(in).at("corner").at(0);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string item;
  while (std::getline(s, item, ',')) out.push_back(item);
  return out;
}

// Rows of a CSV after the header (numbers), and the header.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

Table read_table(const fs::path& p) {
  std::ifstream in(p);
  Table t;
  std::string line;
  std::getline(in, line);
  t.header = split(line);
  while (std::getline(in, line)) {
    std::vector<double> row;
    for (const auto& cell : split(line)) row.push_back(std::stod(cell));
    t.rows.push_back(row);
  }
  return t;
}

class ShaperApply : public Cli {
 protected:
  // The corner fixture as files: its continuous ZV4 as shaper JSON and the corner trajectory.
  void write_corner() const {
    const auto c = corner_reference();
    nlohmann::json shaper = {{"format", "servotwin.shaper/1"},
                             {"type", "zv4"},
                             {"freq_hz", c.at("omega").get<double>() / (2 * std::numbers::pi)},
                             {"zeta", c.at("zeta")},
                             {"times_s", c.at("times")},
                             {"amplitudes", c.at("amplitudes")}};
    write("shaper.json", shaper.dump());
    const double ts = c.at("ts").get<double>(), v = c.at("v").get<double>();
    const auto before = c.at("n_before").get<int>(), after = c.at("n_after").get<int>();
    std::string csv = "t,x_cmd,y_cmd\n";
    for (int k = 0; k <= before + after; ++k) {
      const double tau = (k - before) * ts;
      csv += fmt::format("{},{},{}\n", k * ts, tau < 0 ? v * tau : 0.0, tau > 0 ? v * tau : 0.0);
    }
    write("corner.csv", csv);
  }
};

TEST_F(ShaperApply, CornerDeviationMatchesTheReference) {
  write_corner();
  const auto c = corner_reference();
  const Result r = run("shaper apply shaper.json corner.csv -o shaped.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const Table t = read_table(path("shaped.csv"));
  EXPECT_EQ(t.header, (std::vector<std::string>{"t", "x_cmd", "y_cmd", "x_shaped", "y_shaped", "deviation"}));
  ASSERT_EQ(t.rows.size(), c.at("samples").get<std::size_t>());
  double max = 0.0;
  for (const auto& row : t.rows) max = std::max(max, row[5]);
  EXPECT_NEAR(max, c.at("max_deviation").get<double>(), 1e-9);
  const auto worst = c.at("max_index").get<std::size_t>();
  EXPECT_NEAR(t.rows[worst][3], c.at("max_point")[0].get<double>(), 1e-9);
  EXPECT_NEAR(t.rows[worst][4], c.at("max_point")[1].get<double>(), 1e-9);
  // Summary: delay = max delay * ts, rms and max as the reference.
  const auto delays = c.at("delays").get<std::vector<std::size_t>>();
  EXPECT_NE(r.out.find(fmt::format("delay added: {:.6g} s ({} samples)",
                                   static_cast<double>(delays.back()) * c.at("ts").get<double>(), delays.back())),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(fmt::format("rms {:.6g}, max {:.6g}", c.at("rms_deviation").get<double>(),
                                   c.at("max_deviation").get<double>())),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("7 pulses"), std::string::npos) << r.out;
}

TEST_F(ShaperApply, InterpolatedStraightMovesStayOnThePath) {
  // Interpolator output (exact stops at the 90-degree corner): the shaped path stays on the lines
  // except around the corner, and ends at the program's end point.
  write("part.nc", "G21 G90 G17\nG01 X20 Y0 F3000\nG01 X20 Y15\nM30\n");
  ASSERT_EQ(run("interpolate --program part.nc --ts 0.001 --accel 2000 -o traj.csv").status, 0);
  write_corner();  // for shaper.json (10 Hz ZV4)
  const Result r = run("shaper apply shaper.json traj.csv -o shaped.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const Table t = read_table(path("shaped.csv"));
  const auto& last = t.rows.back();
  EXPECT_NEAR(last[3], 20.0, 1e-9);
  EXPECT_NEAR(last[4], 15.0, 1e-9);
  double max_on_lines = 0.0, max_total = 0.0;
  for (const auto& row : t.rows) {
    // The shaper mixes the last 0.1 s of command; at <= 50 mm/s that reaches <= 5 mm back.
    const bool near_corner = std::hypot(row[3] - 20.0, row[4]) < 5.5;
    if (!near_corner) max_on_lines = std::max(max_on_lines, row[5]);
    max_total = std::max(max_total, row[5]);
  }
  EXPECT_LT(max_on_lines, 1e-9);
  EXPECT_GT(max_total, 1e-3);  // the corner is cut
}

TEST_F(ShaperApply, OutputAndInputErrors) {
  write_corner();
  ASSERT_EQ(run("shaper apply shaper.json corner.csv -o shaped.csv").status, 0);
  Result r = run("shaper apply shaper.json corner.csv -o shaped.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(run("--force shaper apply shaper.json corner.csv -o shaped.csv --method round").status, 0);
  r = run("shaper apply shaper.json corner.csv --ts 0.002 -o other.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--ts"), std::string::npos) << r.err;
  r = run("shaper apply shaper.json corner.csv --method nearest -o other.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--method"), std::string::npos) << r.err;
  write("no_cmd.csv", "t,x_act\n0,0\n0.001,1\n");
  r = run("shaper apply shaper.json no_cmd.csv -o other.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("no_cmd.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("_cmd"), std::string::npos) << r.err;
  // Sample period over half the damped period of the 10 Hz mode (50 ms).
  std::string slow = "t,x_cmd\n";
  for (int k = 0; k < 5; ++k) slow += fmt::format("{},{}\n", 0.06 * k, k);
  write("slow.csv", slow);
  r = run("shaper apply shaper.json slow.csv -o other.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("half the damped period"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("other.csv")));
}

}  // namespace
}  // namespace servotwin::cli_test
