// Multi-mode shapers by convolution (catalog C6.4 option 2, example E21).
#include <gtest/gtest.h>

#include <cmath>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/multimode.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::shaping {
namespace {

// Closed form: the transform of ZV is (1 + K e^{-sT/2})/(1 + K); its square has impulses 1, 2K, K²
// at 0, T/2, T — ZVD. The merge must join the two middle impulses into one.
TEST(ConvolveShapers, ZvTimesZvIsZvd) {
  const Shaper zv = zv_shaper(7.0, 0.05);
  const Shaper product = convolve_shapers(zv, zv);
  const Shaper zvd = zvd_shaper(7.0, 0.05);
  EXPECT_EQ(product.type, "multi");
  test::expect_near_all(product.times, zvd.times, 1e-12);
  test::expect_near_all(product.amplitudes, zvd.amplitudes, 1e-12);
}

// E21 (dissertation eq. 6.77, catalog E21): ZVD shapers for ω = 1, 2.25, 3.4 rad/s, ζ = 0.1
// convolved: 27 pulses, T_f = 10.979 s, first times 0, 0.9287, 1.4033, 1.8573 (the catalog's
// recomputation; the print has 1.4030, 1.8570), first amplitude 0.0374.
TEST(ConvolveShapers, DissertationE21ThreeZvd) {
  const std::vector<double> omegas = {1.0, 2.25, 3.4};
  std::vector<Shaper> factors;
  for (double w : omegas) factors.push_back(zvd_shaper(w, 0.1));
  const Shaper h = convolve_shapers(factors);
  ASSERT_EQ(h.times.size(), 27u);
  EXPECT_NEAR(h.duration(), 10.979, 5e-4);
  EXPECT_DOUBLE_EQ(h.times[0], 0.0);
  EXPECT_NEAR(h.times[1], 0.9287, 5e-5);
  EXPECT_NEAR(h.times[2], 1.4033, 5e-5);
  EXPECT_NEAR(h.times[3], 1.8573, 5e-5);
  EXPECT_NEAR(h.amplitudes[0], 0.0374, 5e-5);
  double sum = 0.0;
  for (double a : h.amplitudes) sum += a;
  EXPECT_NEAR(sum, 1.0, 1e-14);
  // Every factor's zero (and flatness) survives: no residual vibration at any of the modes.
  for (double w : omegas) EXPECT_LT(residual_vibration(h, w, 0.1), 1e-12) << "mode " << w;
  // The product of the factors' vibrations at any other frequency (|transform| multiplies).
  const double w = 1.7;
  double product = 1.0;
  for (const Shaper& f : factors) {
    // V of a shaper at ζ = 0 is |Σ A e^{jωt}|, the magnitude of its transform on the imaginary axis.
    product *= residual_vibration(f, w, 0.0);
  }
  EXPECT_NEAR(residual_vibration(h, w, 0.0), product, 1e-12);
}

TEST(ConvolveShapers, SingleShaperListIsUnchanged) {
  const Shaper mzv = mzv_shaper(30.0, 0.1);
  const Shaper same = convolve_shapers(std::vector<Shaper>{mzv});
  EXPECT_EQ(same.type, "mzv");
  test::expect_near_all(same.times, mzv.times, 0.0);
}

TEST(ConvolveShapers, BadInputNamesTheShaper) {
  Shaper empty{"zv", 1.0, 0.0, {}, {}};
  try {
    (void)convolve_shapers(zv_shaper(1.0, 0.0), empty);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("second shaper"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)convolve_shapers(std::vector<Shaper>{}), core::InputError);
  Shaper negative{"x", 1.0, 0.0, {0.0, 1.0}, {0.5, -0.5}};
  EXPECT_THROW((void)convolve_shapers(negative, negative), core::InputError);
}

}  // namespace
}  // namespace servotwin::shaping
