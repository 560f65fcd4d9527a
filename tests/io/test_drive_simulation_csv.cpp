// The closed-loop simulation CSV: header, one row per sample, values written shortest-round-trip
// (read back bit for bit), empty cells for signals a transfer-function plant does not have.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "servotwin/io/drive_simulation_csv.hpp"

namespace servotwin::io {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

vcnc::DriveSimulation small_run() {
  vcnc::DriveSimulation s;
  s.test = vcnc::DriveTest::kLoadStep;
  s.structure = tuning::Structure::kPid;
  s.ts = 1e-3;
  s.amplitude = 0.25;
  for (int k = 0; k < 3; ++k) {
    vcnc::DriveSample x;
    x.t = k * 1e-3;
    x.load_torque = 0.25;
    x.torque_command = 0.1 * k + 1.0 / 3.0;
    x.motor_velocity = -0.01 * k;
    x.load_velocity = std::numeric_limits<double>::quiet_NaN();  // as for a transfer-function plant
    x.motor_position = 1e-7 * k;
    x.load_position = std::numeric_limits<double>::quiet_NaN();
    x.measured = x.motor_velocity;
    s.samples.push_back(x);
    x.torque_command *= 2.0;
    s.linear_samples.push_back(x);
  }
  return s;
}

TEST(DriveSimulationCsv, WritesEverySampleAndReadsBackExactly) {
  const vcnc::DriveSimulation s = small_run();
  std::ostringstream out;
  write_drive_simulation_csv(out, s);
  std::istringstream in(out.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "# servotwin.drive-simulation/1 test=load-step structure=pid ts=0.001 amplitude=0.25");
  std::getline(in, line);
  const auto header = split(line);
  ASSERT_EQ(header.size(), 14U);
  EXPECT_EQ(header[0], "t");
  EXPECT_EQ(header[3], "torque");
  EXPECT_EQ(header[9], "linear_torque");
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    const auto cells = split(line);
    ASSERT_EQ(cells.size(), 14U) << line;
    const auto& x = s.samples[rows];
    EXPECT_EQ(std::stod(cells[3]), x.torque_command);  // shortest round trip: exact
    EXPECT_EQ(std::stod(cells[4]), x.motor_velocity);
    EXPECT_TRUE(cells[5].empty());                     // no load: empty cell
    EXPECT_EQ(std::stod(cells[6]), x.motor_position);
    EXPECT_EQ(std::stod(cells[9]), s.linear_samples[rows].torque_command);
    ++rows;
  }
  EXPECT_EQ(rows, 3U);
}

}  // namespace
}  // namespace servotwin::io
