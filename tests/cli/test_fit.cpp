// `servotwin fit` end to end: reads a frequency-response CSV of the catalog's E10 table plant
// (K = 0.5, a = 0.2, ωz = 1, ζz = 0.06, ωn = 3, ζn = 0.15), writes plant_model.json and prints the
// summary; exit statuses for existing outputs, bad options and bad data.
#include <cmath>
#include <numbers>

#include "cli_support.hpp"
#include "e10_frf.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/io/plant_model_json.hpp"

namespace servotwin::cli_test {
namespace {

TEST_F(Cli, FitWritesThePlantModelAndPrintsTheSummary) {
  write("frf.csv", e10_csv(20));
  const Result r = run("fit frf.csv --model two-mass -o plant_model.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("velocity output"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("motor inertia Im = 2"), std::string::npos) << r.out;  // Im = 1/K = 2
  const io::LoadedPlantModel m = io::load_plant_model(path("plant_model.json").string());
  ASSERT_EQ(m.model.modes.size(), 1u);
  EXPECT_NEAR(m.model.gain, 0.5, 1e-9);
  EXPECT_NEAR(m.model.rigid_pole_rad_s, 0.2, 1e-9);
  EXPECT_NEAR(m.model.modes[0].resonance.omega_rad_s, 3.0, 1e-9);
  EXPECT_NEAR(m.model.modes[0].antiresonance.zeta, 0.06, 1e-9);
  ASSERT_TRUE(m.physical);
  EXPECT_NEAR(m.physical->load_inertia.value, 2.0 * (9.0 - 1.0), 1e-8);  // Il = Im (r² − 1)

  // The output exists: refused without --force, replaced with it.
  EXPECT_EQ(run("fit frf.csv -o plant_model.json").status, 3);
  EXPECT_EQ(run("fit frf.csv -o plant_model.json --force").status, 0);
}

TEST_F(Cli, FitAutoStatesTheCriterion) {
  write("frf.csv", e10_csv(30));
  const Result r = run("fit frf.csv --model auto --output-kind velocity");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("BIC"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("n = 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("<- chosen"), std::string::npos) << r.out;
}

TEST_F(Cli, FitBadOptionsAndData) {
  write("frf.csv", e10_csv(20));
  Result r = run("fit frf.csv --model modes:x");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--model"), std::string::npos) << r.err;
  EXPECT_EQ(run("fit frf.csv --output-kind torque").status, 2);
  write("short.csv", e10_csv(3));
  r = run("fit short.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("needs at least 4 frequency points"), std::string::npos) << r.err;
  // A rigid plant has no resonance: the two-mass request fails with the reason.
  write("rigid.csv", "freq_hz,re,im\n0.1,0,-10\n0.2,0,-5\n0.4,0,-2.5\n0.8,0,-1.25\n1.6,0,-0.625\n3.2,0,-0.3125\n");
  r = run("fit rigid.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("resonance"), std::string::npos) << r.err;
  // Issue 25 §7: -o/--output names the file; the measured output kind is --output-kind.
  const Result kind = run("fit frf.csv --output velocity");
  EXPECT_EQ(kind.status, 2);
  EXPECT_NE(kind.err.find("the measured output is --output-kind velocity"), std::string::npos) << kind.err;
  const Result old = run("fit frf.csv --out old_spelling.json");
  EXPECT_EQ(old.status, 0) << old.err;
  EXPECT_NE(old.err.find("note: --out is now spelled -o/--output"), std::string::npos) << old.err;
  EXPECT_TRUE(std::filesystem::exists(path("old_spelling.json")));
}

}  // namespace
}  // namespace servotwin::cli_test
