// Classic families and the EI family. Expected values: closed forms (Singer–Seering binomial
// shapers; MZV's undamped amplitudes 1 − 1/√2, √2 − 1, 1 − 1/√2 over 0.75 T_d as in Klipper),
// Singhose's undamped EI closed forms, and tests/data/shaping/{classic,ei_family}.json from
// tools/reference/shaping_reference.py (numpy / scipy.optimize.fsolve on the defining conditions).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::shaping {
namespace {

using std::numbers::pi;

using test::expect_near_all;

TEST(Families, UndampedClosedForms) {
  expect_near_all(zv_shaper(1.0, 0.0).amplitudes, {0.5, 0.5}, 1e-15);
  expect_near_all(zvd_shaper(1.0, 0.0).amplitudes, {0.25, 0.5, 0.25}, 1e-15);
  expect_near_all(zvdd_shaper(1.0, 0.0).amplitudes, {0.125, 0.375, 0.375, 0.125}, 1e-15);
  expect_near_all(zvdd_shaper(2.0, 0.0).times, {0.0, pi / 2, pi, 1.5 * pi}, 1e-15);
  const Shaper m = mzv_shaper(2.0 * pi, 0.0);  // 1 Hz: T_d = 1 s, duration 0.75 s
  expect_near_all(m.times, {0.0, 0.375, 0.75}, 1e-15);
  expect_near_all(m.amplitudes, {1.0 - 1.0 / std::sqrt(2.0), std::sqrt(2.0) - 1.0, 1.0 - 1.0 / std::sqrt(2.0)}, 1e-15);
}

TEST(Families, DampedClosedFormsUseTheDamping) {
  // ZV with damping: A = [1, K]/(1+K), K = exp(−ζπ/√(1−ζ²)), t2 = π/ω_d.
  const double zeta = 0.1;
  const double k = std::exp(-zeta * pi / std::sqrt(1.0 - zeta * zeta));
  const Shaper zv = zv_shaper(2.0 * pi * 50.0, zeta);
  expect_near_all(zv.amplitudes, {1.0 / (1.0 + k), k / (1.0 + k)}, 1e-15);
  EXPECT_NEAR(zv.times[1], 0.5 / (50.0 * std::sqrt(1.0 - zeta * zeta)), 1e-15);
  // MZV's K uses the impulse spacing 3/8 T_d: exp(−0.75 ζπ/√(1−ζ²)).
  const double km = std::exp(-0.75 * zeta * pi / std::sqrt(1.0 - zeta * zeta));
  const double a1 = 1.0 - 1.0 / std::sqrt(2.0);
  const double sum = a1 + (std::sqrt(2.0) - 1.0) * km + a1 * km * km;
  expect_near_all(mzv_shaper(2.0 * pi * 50.0, zeta).amplitudes,
                  {a1 / sum, (std::sqrt(2.0) - 1.0) * km / sum, a1 * km * km / sum}, 1e-15);
  for (const Shaper& s : {zv_shaper(7.0, 0.3), zvd_shaper(7.0, 0.3), zvdd_shaper(7.0, 0.3), mzv_shaper(7.0, 0.3)})
    EXPECT_LT(residual_vibration(s, 7.0, 0.3), 1e-15) << s.type;
}

TEST(Families, MatchReferenceDefiningConditions) {
  const nlohmann::json data = test::load_fixture("classic.json");
  for (const auto& c : data.at("cases")) {
    const std::string type = c.at("type");
    SCOPED_TRACE(type);
    const Shaper s = design_shaper(parse_shaper_type(type), c.at("omega"), c.at("zeta"));
    expect_near_all(s.times, c.at("times").get<std::vector<double>>(), 1e-12);
    expect_near_all(s.amplitudes, c.at("amplitudes").get<std::vector<double>>(), 1e-12);
  }
}

TEST(Families, BinomialFamilyEqualsZv4Presets) {
  // Two independent routes to the same shapers: the classic closed forms and ZV4 Table 6.1, both
  // damped (the ZV4 polygon lives in the a_i = A_i e^{ζω t_i} frame).
  for (const auto& [type, preset] : {std::pair{ShaperType::kZv, "zv"}, {ShaperType::kZvd, "zvd"}, {ShaperType::kZvdd, "zvdd"}}) {
    const Shaper classic = design_shaper(type, 31.0, 0.12);
    const Shaper zv4 = zv4_shaper(31.0, 0.12, zv4_preset(preset));
    expect_near_all(zv4.times, classic.times, 1e-14);
    expect_near_all(zv4.amplitudes, classic.amplitudes, 1e-14);
  }
}

TEST(Families, EiUndampedEqualsSinghoseClosedForms) {
  const double v = 0.05;
  expect_near_all(ei_shaper(1.0, 0.0).amplitudes, {(1 + v) / 4, (1 - v) / 2, (1 + v) / 4}, 1e-13);
  expect_near_all(ei_shaper(1.0, 0.0).times, {0.0, pi, 2 * pi}, 1e-12);
  const Shaper two = two_hump_ei_shaper(1.0, 0.0);
  // Same shaper as ZV4's 2HEI 5 % row to the 4 printed digits (E19).
  expect_near_all(two.amplitudes, {0.1598, 0.3402, 0.3402, 0.1598}, 5e-5);
  const double a1 = (1 + 3 * v + 2 * std::sqrt(2 * v * (v + 1))) / 16;
  const double a2 = (1 - v) / 4;
  expect_near_all(three_hump_ei_shaper(1.0, 0.0).amplitudes, {a1, a2, 1 - 2 * (a1 + a2), a2, a1}, 1e-13);
}

TEST(Families, EiFamilyMatchesReferenceSolutions) {
  const nlohmann::json data = test::load_fixture("ei_family.json");
  for (const auto& c : data.at("cases")) {
    const std::string type = c.at("type");
    const double zeta = c.at("zeta");
    const double v_tol = c.at("v_tol");
    SCOPED_TRACE(type + " zeta=" + std::to_string(zeta) + " v_tol=" + std::to_string(v_tol));
    const double omega = 2.0 * pi * 40.0;
    const Shaper s = design_shaper(parse_shaper_type(type), omega, zeta, v_tol);
    std::vector<double> times = c.at("times_wn1").get<std::vector<double>>();
    for (double& t : times) t /= omega;
    expect_near_all(s.times, times, 1e-10 / omega);
    expect_near_all(s.amplitudes, c.at("amplitudes").get<std::vector<double>>(), 1e-10);
    // The defining property at the design frequency: a hump of V_tol (EI, 3-hump) or a zero (2-hump).
    const double expected = type == "2hump_ei" ? 0.0 : v_tol;
    EXPECT_NEAR(residual_vibration(s, omega, zeta), expected, 1e-11);
  }
}

TEST(Families, EiHumpsAreLocalMaximaOfHeightTolerance) {
  // Independent of the fixture: scan V on (0.6, 1.4)·ω_n and check that every interior local
  // maximum (the humps) has height V_tol and that their count is the family's hump count, ζ = 0.1.
  for (auto [type, humps] : {std::pair{ShaperType::kEi, 1}, {ShaperType::kTwoHumpEi, 2}, {ShaperType::kThreeHumpEi, 3}}) {
    const Shaper s = design_shaper(type, 1.0, 0.1);
    int found = 0;
    double before = residual_vibration(s, 0.6, 0.1);
    double here = residual_vibration(s, 0.6 + 1e-5, 0.1);
    for (int k = 2; k <= 80000; ++k) {
      const double after = residual_vibration(s, 0.6 + 1e-5 * k, 0.1);
      if (here >= before && here >= after) {
        ++found;
        EXPECT_NEAR(here, 0.05, 1e-8) << to_string(type) << " at " << 0.6 + 1e-5 * (k - 1);
      }
      before = here;
      here = after;
    }
    EXPECT_EQ(found, humps) << to_string(type);
  }
}

TEST(Families, BadInputNamesTheValue) {
  EXPECT_THROW((void)zv_shaper(-1.0, 0.1), core::InputError);
  EXPECT_THROW((void)mzv_shaper(10.0, 1.0), core::InputError);
  EXPECT_THROW((void)ei_shaper(10.0, 0.1, 0.6), core::InputError);
  EXPECT_THROW((void)design_shaper(ShaperType::kZv4, 10.0, 0.1), core::InputError);
  try {
    (void)parse_shaper_type("zz");
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("zz"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("mzv"), std::string::npos);
  }
  // Beyond its damping range the 3-hump EI has no positive solution: a clear error, not garbage.
  try {
    (void)three_hump_ei_shaper(10.0, 0.6);
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("zeta"), std::string::npos);
  }
}

// The EI family shares a table of exact solutions per vibration tolerance (built on first use):
// designs from several threads at once, each first to ask for its tolerance or not, must equal the
// same designs made one after another (reference: the serial results, themselves checked against
// ei_family.json above).
TEST(Families, EiFamilyDesignsAreThreadSafe) {
  const std::vector<double> zetas = {0.0, 0.013, 0.05, 0.117, 0.15};
  const std::vector<double> tolerances = {0.011, 0.023, 0.05};
  auto design_all = [&] {
    std::vector<Shaper> out;
    for (double v_tol : tolerances)
      for (double zeta : zetas)
        for (ShaperType type : {ShaperType::kEi, ShaperType::kTwoHumpEi, ShaperType::kThreeHumpEi})
          out.push_back(design_shaper(type, 100.0, zeta, v_tol));
    return out;
  };
  std::vector<std::vector<Shaper>> results(4);
  std::vector<std::thread> threads;
  for (auto& r : results) threads.emplace_back([&r, &design_all] { r = design_all(); });
  for (auto& t : threads) t.join();
  const std::vector<Shaper> serial = design_all();
  for (const auto& r : results) {
    ASSERT_EQ(r.size(), serial.size());
    for (std::size_t i = 0; i < r.size(); ++i) {
      expect_near_all(r[i].times, serial[i].times, 1e-15);
      expect_near_all(r[i].amplitudes, serial[i].amplitudes, 1e-15);
    }
  }
}

// Dampings just beyond the last tabulated node of a family and far beyond it: the same answer as
// before the table existed (a shaper, or the error naming zeta), never a hang.
TEST(Families, EiFamilyBeyondItsRange) {
  EXPECT_THROW((void)three_hump_ei_shaper(100.0, 0.9), core::InputError);
  EXPECT_THROW((void)two_hump_ei_shaper(100.0, 0.95), core::InputError);
  EXPECT_THROW((void)ei_shaper(100.0, 0.97), core::InputError);
}

}  // namespace
}  // namespace servotwin::shaping
