// The per-sample paths of a frequency-response experiment do not allocate (design.md): the
// real-time identification block's step() through a whole run (sweep, settling, latching,
// extrema, ramp-out) and the flexible plant's step() with and without friction and backlash.
// Counting: tests/malloc_counting.hpp (skipped under the sanitizers).
#include <gtest/gtest.h>

#include <cmath>

#include "malloc_counting.hpp"
#include "servotwin/frf/rfid_block.hpp"
#include "servotwin/machine/flexible_presets.hpp"
#include "servotwin/vcnc/frf_experiment.hpp"

namespace servotwin {
namespace {

using test_support::allocations;

TEST(Allocation, CounterSeesAllocationsInThisExecutable) {
  SKIP_WITHOUT_COUNTING();
  const std::size_t before = allocations();
  { std::vector<double> v(100, 1.0); EXPECT_EQ(v.size(), 100u); }
  EXPECT_GE(allocations() - before, 1U);  // without this the tests below could not fail
}

TEST(Allocation, AWholeRunOfTheBlockAgainstAFrictionAndBacklashPlantDoesNotAllocate) {
  SKIP_WITHOUT_COUNTING();
  machine::PlantConfig config = machine::flexible_preset("motor-bench");
  std::get<machine::MassChain>(config.model).backlash = {2e-4};
  machine::FlexiblePlant plant(config);
  vcnc::FrfExperimentSettings s;
  s.f_begin_hz = 5.0;
  s.f_end_hz = 200.0;
  s.points = 10;
  frf::RfidBlock block(vcnc::experiment_parameters(plant, s));
  const double dc_gain = vcnc::dc_hold_gain(plant, s);

  const std::size_t before = allocations();
  double pv = 0.0, cv = 0.0, sum = 0.0;
  long k = 0;
  for (; k < 8000 * 60; ++k) {
    const frf::RfidOutput o = block.step(true, pv, cv);
    if (o.state == frf::RfidState::kDone || o.state == frf::RfidState::kAborted) break;
    cv = -dc_gain * o.harmonics[0];
    pv = plant.step(o.mv).y;
    sum += pv;
  }
  EXPECT_EQ(allocations() - before, 0U);
  EXPECT_EQ(block.state(), frf::RfidState::kDone);
  EXPECT_GE(block.points().size(), 10u);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(Allocation, TheLinearPlantStepDoesNotAllocate) {
  SKIP_WITHOUT_COUNTING();
  machine::FlexiblePlant plant(machine::flexible_preset("testbed-1"));
  const std::size_t before = allocations();
  double sum = 0.0;
  for (int k = 0; k < 20000; ++k) sum += plant.step(std::sin(0.01 * k)).y;
  EXPECT_EQ(allocations() - before, 0U);
  EXPECT_TRUE(std::isfinite(sum));
}

}  // namespace
}  // namespace servotwin
