// Direct LP synthesis of multi-mode shapers (catalog C6.3 / C6.4, examples E21–E23).
// Expected values: the catalog's printed numbers (E22 / E23, tolerance ~1e-3 as printed to 4
// decimals) and tests/data/shaping/lp_multimode.json, written by
// tools/reference/shaping_lp_reference.py (the same LP stated unscaled and solved with HiGHS via
// scipy.optimize.linprog; it also records, per amplitude, its range over the optimal face, to tell
// a unique optimum from a non-unique one).
#include "servotwin/shaping/lp_shaper.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/multimode.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::shaping {
namespace {

const std::vector<LpMode> kE21Modes = {{1.0, 0.1}, {2.25, 0.1}, {3.4, 0.1}};

/// Options on a fixed (or, with n = 0, searched) grid; the rest default.
LpShaperOptions grid(double tp, int n, int order = 0) {
  LpShaperOptions o;
  o.pulse_spacing = tp;
  o.pulse_count = n;
  o.derivative_order = order;
  return o;
}

std::vector<LpMode> modes_from(const nlohmann::json& c) {
  std::vector<LpMode> modes;
  for (const auto& m : c.at("modes")) modes.push_back({m.at(0).get<double>(), m.at(1).get<double>()});
  return modes;
}

LpShaperOptions options_from(const nlohmann::json& c) {
  LpShaperOptions o;
  o.pulse_spacing = c.at("tp").get<double>();
  o.pulse_count = c.at("n").get<int>();
  o.derivative_order = c.at("derivative_order").get<int>();
  o.cost_k = c.at("cost_k").get<double>();
  for (const auto& b : c.at("bounds")) o.bounds.push_back({b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>()});
  return o;
}

const nlohmann::json& fixture_case(const std::string& name) {
  static const nlohmann::json doc = test::load_fixture("lp_multimode.json");
  for (const auto& c : doc.at("cases"))
    if (c.at("name") == name) return c;
  throw std::runtime_error("no case " + name + " in lp_multimode.json");
}

/// The full grid of a candidate (zero impulses re-inserted), for element-wise comparisons.
std::vector<double> grid_amplitudes(const LpCandidate& c) {
  std::vector<double> a(static_cast<std::size_t>(c.pulse_count), 0.0);
  for (std::size_t i = 0; i < c.shaper.times.size(); ++i) {
    const double slot = c.shaper.times[i] / c.pulse_spacing;
    EXPECT_NEAR(slot, std::round(slot), 1e-9) << "impulse " << i << " off the grid";
    a[static_cast<std::size_t>(std::lround(slot))] = c.shaper.amplitudes[i];
  }
  return a;
}

double sum(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s;
}

/// V(ω, ζ) of C6.3 relative to the grid's end t_n (the bounds' definition).
double grid_vibration(const std::vector<double>& a, double tp, double omega, double zeta) {
  const double wd = omega * std::sqrt(1.0 - zeta * zeta);
  const double tn = tp * static_cast<double>(a.size() - 1);
  double c = 0.0, s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double t = tp * static_cast<double>(i);
    const double w = std::exp(-zeta * omega * (tn - t));
    c += a[i] * w * std::cos(wd * t);
    s += a[i] * w * std::sin(wd * t);
  }
  return std::hypot(c, s);
}

void expect_shaper_invariants(const LpCandidate& c) {
  const Shaper& s = c.shaper;
  EXPECT_EQ(s.type, "lp");
  ASSERT_FALSE(s.times.empty());
  EXPECT_EQ(s.times.front(), 0.0);
  for (std::size_t i = 1; i < s.times.size(); ++i) EXPECT_GT(s.times[i], s.times[i - 1]);
  for (double a : s.amplitudes) EXPECT_GE(a, 0.0);
  EXPECT_NEAR(sum(s.amplitudes), 1.0, 1e-12);
}

// E22 (eq. 6.78): ZV + zero slope at ω = 1, 2.25, 3.4 rad/s, ζ = 0.1, J2 with k = 1, n = 14,
// Tp = 0.68 s. The reference LP has a unique optimum (face width < 1e-7), so the amplitudes are
// compared element-wise: to HiGHS within 1e-6 and to the print within 1e-3 (the catalog's own
// HiGHS check is within 5e-4 of it).
TEST(LpShaper, DissertationE22MatchesHighsAndPrint) {
  const nlohmann::json& ref = fixture_case("e22");
  ASSERT_TRUE(ref.at("unique").get<bool>());
  const LpCandidate c = lp_shaper_design(kE21Modes, options_from(ref));
  expect_shaper_invariants(c);
  EXPECT_EQ(c.pulse_count, 14);
  EXPECT_NEAR(c.grid_duration(), 8.84, 1e-12);   // catalog E22: Tf = 8.84 s
  EXPECT_NEAR(c.shaper.duration(), 8.84, 1e-12);  // the last impulse (0.0235) is not zero
  const std::vector<double> a = grid_amplitudes(c);
  test::expect_near_all(a, ref.at("amplitudes").get<std::vector<double>>(), 1e-6);
  EXPECT_NEAR(c.cost, ref.at("cost").get<double>(), 1e-8);
  const std::vector<double> printed = {0.1492, 0,      0.1138, 0.0539, 0.0922, 0.1172, 0.1078,
                                       0.1320, 0.0245, 0.0867, 0.0237, 0.0559, 0.0196, 0.0235};
  test::expect_near_all(a, printed, 1e-3);
  EXPECT_EQ(c.shaper.times.size(), 13u);  // A_2 = 0 is dropped (printed 0)
  for (const LpMode& m : kE21Modes) EXPECT_LT(residual_vibration(c.shaper, m.omega, m.zeta), 1e-9) << m.omega;
}

// Catalog E22: n = 14 is the minimum feasible n at Tp = 0.68 s; at 0.63 s it is 15 (Tf 8.82 s),
// at 0.75 s 13 (Tf 9.0 s). The fixture's e22_min_n (HiGHS bisection, confirmed at n and n − 1)
// agrees; pulse_count = 0 must find the same.
TEST(LpShaper, DissertationE22MinimumPulseCounts) {
  const nlohmann::json doc = test::load_fixture("lp_multimode.json");
  const int expected_n[] = {15, 14, 13};
  const double expected_tf[] = {8.82, 8.84, 9.0};
  ASSERT_EQ(doc.at("e22_min_n").size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& row = doc.at("e22_min_n").at(i);
    ASSERT_EQ(row.at("n").get<int>(), expected_n[i]);  // fixture and catalog agree
    LpShaperOptions o;
    o.pulse_spacing = row.at("tp").get<double>();
    o.derivative_order = 1;
    const LpCandidate c = lp_shaper_design(kE21Modes, o);
    EXPECT_EQ(c.pulse_count, expected_n[i]) << "Tp " << o.pulse_spacing;
    EXPECT_NEAR(c.grid_duration(), expected_tf[i], 1e-12) << "Tp " << o.pulse_spacing;
    // One impulse fewer is infeasible: InputError.
    o.pulse_count = expected_n[i] - 1;
    EXPECT_THROW((void)lp_shaper_design(kE21Modes, o), core::InputError) << "Tp " << o.pulse_spacing;
  }
}

// E23 (eq. 6.79): ZV per mode + V ≤ 5 % at 0.85 and 1.15 × each mode, n = 14, Tp = 0.63 s.
// Constraints and cost against HiGHS; the reference found the optimum unique in this
// formulation (face width < 1e-7), so the amplitudes are compared too.
TEST(LpShaper, DissertationE23BoundsHoldAndCostMatchesHighs) {
  const nlohmann::json& ref = fixture_case("e23");
  const LpShaperOptions o = options_from(ref);
  ASSERT_EQ(o.bounds.size(), 6u);
  const LpCandidate c = lp_shaper_design(kE21Modes, o);
  expect_shaper_invariants(c);
  EXPECT_NEAR(c.grid_duration(), 8.19, 1e-12);  // catalog E23: Tf = 8.19 s
  EXPECT_NEAR(c.cost, ref.at("cost").get<double>(), 1e-8);
  const std::vector<double> a = grid_amplitudes(c);
  const auto lo = ref.at("amplitude_min").get<std::vector<double>>();
  const auto hi = ref.at("amplitude_max").get<std::vector<double>>();
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_GE(a[i], lo[i] - 1e-6) << i;
    EXPECT_LE(a[i], hi[i] + 1e-6) << i;
  }
  if (ref.at("unique").get<bool>()) test::expect_near_all(a, ref.at("amplitudes").get<std::vector<double>>(), 1e-6);
  for (const LpMode& m : kE21Modes) EXPECT_LT(residual_vibration(c.shaper, m.omega, m.zeta), 1e-9);
  // The bounds hold (V ≤ S_max; the LP imposes |C|, |S| ≤ S_max/√2, so V ≤ S_max).
  for (const SensitivityBound& b : o.bounds) EXPECT_LE(grid_vibration(a, 0.63, b.omega, b.zeta), b.s_max + 1e-9);
}

// The printed E23 amplitudes meet the 5 % bounds (catalog: 0.050/0.024, 0.049/0.027, 0.049/0.036
// at 0.85/1.15 × ω_k) but are NOT an exact solution of the LP as stated: they leave 0.1–0.3 %
// vibration at the modes (catalog: 0.001/0.001/0.003) and their J2 cost is below the exact
// optimum. So the dissertation's solve was looser than exact zero vibration (replacing ZV by
// V ≤ 0.1 % at each mode reproduces the print to 4e-3 in amplitude and 2e-4 in cost: fixture
// printed.e23.relaxed_zv_0p1); ours is the exact optimum.
TEST(LpShaper, DissertationE23PrintIsApproximateZeroVibration) {
  const nlohmann::json doc = test::load_fixture("lp_multimode.json");
  const auto& printed = doc.at("printed").at("e23");
  std::vector<double> a = printed.at("amplitudes").get<std::vector<double>>();
  const double total = sum(a);
  for (double& x : a) x /= total;
  const LpShaperOptions o = options_from(fixture_case("e23"));
  for (const SensitivityBound& b : o.bounds) EXPECT_LE(grid_vibration(a, 0.63, b.omega, b.zeta), 0.0501) << b.omega;
  const double vibration_at_mode3 = grid_vibration(a, 0.63, 3.4, 0.1);
  EXPECT_GT(vibration_at_mode3, 2e-3);  // catalog: 0.003
  EXPECT_LT(vibration_at_mode3, 4e-3);
  const LpCandidate c = lp_shaper_design(kE21Modes, o);
  double printed_cost = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) printed_cost += (static_cast<double>(i) + 1.0) * a[i];
  EXPECT_LT(printed_cost, c.cost);  // lower than the exact optimum: the print is not exactly feasible
  EXPECT_NEAR(printed_cost, c.cost, 0.03);
  EXPECT_NEAR(printed.at("cost_j2_k1").get<double>(), 5.5872, 1e-4);
}

// Other LP shapes against HiGHS: J1 (k = 0), second-derivative constraints with k = 2, and a
// degenerate grid where the two-pulse ZV is the answer (closed form [0.5, 0.5] for ζ = 0,
// Tp = π/ω).
TEST(LpShaper, OtherCasesMatchHighs) {
  for (const char* name : {"e22_j1", "two_modes_d2", "single_zv"}) {
    SCOPED_TRACE(name);
    const nlohmann::json& ref = fixture_case(name);
    const std::vector<LpMode> modes = modes_from(ref);
    const LpCandidate c = lp_shaper_design(modes, options_from(ref));
    expect_shaper_invariants(c);
    EXPECT_NEAR(c.cost, ref.at("cost").get<double>(), 1e-8);
    const std::vector<double> a = grid_amplitudes(c);
    const auto lo = ref.at("amplitude_min").get<std::vector<double>>();
    const auto hi = ref.at("amplitude_max").get<std::vector<double>>();
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_GE(a[i], lo[i] - 1e-6) << i;
      EXPECT_LE(a[i], hi[i] + 1e-6) << i;
    }
    for (const LpMode& m : modes) EXPECT_LT(grid_vibration(a, c.pulse_spacing, m.omega, m.zeta), 1e-9);
  }
  const LpCandidate zv = lp_shaper_design({{2.0, 0.0}}, grid(std::numbers::pi / 2.0, 2));
  test::expect_near_all(zv.shaper.amplitudes, {0.5, 0.5}, 1e-12);
}

// Flatness: with the zero-slope rows the vibration stays small around each mode, much smaller
// than with zero vibration alone on the same grid (E22 grid; V is quadratic in the frequency
// error with the derivative rows, linear without).
TEST(LpShaper, DerivativeConstraintsFlattenTheNotches) {
  LpShaperOptions flat = grid(0.68, 14, 1);
  LpShaperOptions plain = flat;
  plain.derivative_order = 0;
  const Shaper s_flat = lp_shaper(kE21Modes, flat);
  const Shaper s_plain = lp_shaper(kE21Modes, plain);
  for (const LpMode& m : kE21Modes) {
    for (double ratio : {0.97, 1.03}) {
      const double v_flat = residual_vibration(s_flat, ratio * m.omega, m.zeta);
      const double v_plain = residual_vibration(s_plain, ratio * m.omega, m.zeta);
      EXPECT_LT(v_flat, 0.01) << m.omega << " x" << ratio;
      EXPECT_LT(v_flat, 0.5 * v_plain) << m.omega << " x" << ratio;
    }
    // Zero slope: halving the frequency error quarters V (to within the cubic term).
    const double v1 = residual_vibration(s_flat, 1.02 * m.omega, m.zeta);
    const double v2 = residual_vibration(s_flat, 1.01 * m.omega, m.zeta);
    EXPECT_NEAR(v1 / v2, 4.0, 0.3) << m.omega;
  }
}

// C6.4's point: the LP design (E22, Tf = 8.84 s) is shorter than the convolution of per-mode ZVD
// shapers (E21, Tf = 10.979 s), which meets the same zero-vibration and zero-slope conditions.
TEST(LpShaper, ShorterThanConvolution) {
  std::vector<Shaper> factors;
  for (const LpMode& m : kE21Modes) factors.push_back(zvd_shaper(m.omega, m.zeta));
  const Shaper convolved = convolve_shapers(factors);
  EXPECT_NEAR(convolved.duration(), 10.979, 5e-4);
  const Shaper lp = lp_shaper(kE21Modes, grid(0.68, 0, 1));
  EXPECT_LT(lp.duration(), convolved.duration() - 2.0);
}

// C6.4 steps 1–4 against the fixture's search (T = 0.05 s, every multiple up to π/ω_d1, the
// minimal n per spacing by HiGHS bisection under the same duration cap): same spacings, same n,
// same optimal cost, and the same order.
TEST(LpShaperSearch, MatchesHighsSearchOnCoarseGrid) {
  const nlohmann::json doc = test::load_fixture("lp_multimode.json");
  const auto& ref = doc.at("search_e22");
  LpShaperOptions base;
  base.derivative_order = ref.at("derivative_order").get<int>();
  const std::vector<LpCandidate> found =
      lp_shaper_search(kE21Modes, base, {.sample_period = ref.at("sample_period").get<double>()});
  const auto& rows = ref.at("rows");
  ASSERT_EQ(found.size(), rows.size());
  std::map<int, const nlohmann::json*> by_multiple;
  for (const auto& row : rows) by_multiple[row.at("multiple").get<int>()] = &row;
  for (const LpCandidate& c : found) {
    ASSERT_TRUE(by_multiple.count(c.multiple)) << "multiple " << c.multiple;
    const nlohmann::json& row = *by_multiple[c.multiple];
    EXPECT_EQ(c.pulse_count, row.at("n").get<int>()) << "Tp " << c.pulse_spacing;
    EXPECT_NEAR(c.cost, row.at("cost").get<double>(), 1e-7) << "Tp " << c.pulse_spacing;
    EXPECT_NEAR(c.pulse_spacing, row.at("tp").get<double>(), 1e-12);
    for (const LpMode& m : kE21Modes) EXPECT_LT(residual_vibration(c.shaper, m.omega, m.zeta), 1e-9);
  }
  for (std::size_t i = 1; i < found.size(); ++i) {
    const int d0 = (found[i - 1].pulse_count - 1) * found[i - 1].multiple;
    const int d1 = (found[i].pulse_count - 1) * found[i].multiple;
    EXPECT_TRUE(d0 < d1 || (d0 == d1 && found[i - 1].pulse_count <= found[i].pulse_count)) << i;
  }
  // The best candidate: Tf = 8.6 s at Tp = 0.2 s, n = 44 (the fixture's minimum duration, fewest pulses).
  EXPECT_EQ(found.front().multiple, 4);
  EXPECT_EQ(found.front().pulse_count, 44);
}

// The E22 spacings of the catalog appear in a search with T = 0.01 s limited to 0.75 s
// (multiples 63, 68, 75 → n = 15, 14, 13).
TEST(LpShaperSearch, FindsCatalogE22Spacings) {
  LpShaperOptions base;
  base.derivative_order = 1;
  const std::vector<LpCandidate> found = lp_shaper_search(kE21Modes, base, {.sample_period = 0.01, .max_multiple = 75});
  EXPECT_EQ(found.size(), 75u);
  std::map<int, int> n_of;
  for (const LpCandidate& c : found) n_of[c.multiple] = c.pulse_count;
  EXPECT_EQ(n_of[63], 15);
  EXPECT_EQ(n_of[68], 14);
  EXPECT_EQ(n_of[75], 13);
}

TEST(LpShaper, TooFewPulsesIsInfeasible) {
  // Three modes need n >= 2m + 1 = 7 on a generic grid (C6.4 counting); n = 5 < 2m.
  try {
    (void)lp_shaper(kE21Modes, grid(0.68, 5));
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("infeasible"), std::string::npos) << what;
    EXPECT_NE(what.find("n = 5"), std::string::npos) << what;
    EXPECT_NE(what.find("0.68"), std::string::npos) << what;
  }
  // A 1 % bound right at 1.02 × a ZV-only mode with 7 impulses cannot be met either.
  LpShaperOptions tight = grid(0.68, 7);
  tight.bounds = {{1.5, 0.1, 1e-4}};
  EXPECT_THROW((void)lp_shaper(kE21Modes, tight), core::InputError);
}

void expect_field_error(const std::vector<LpMode>& modes, const LpShaperOptions& o, const std::string& field) {
  try {
    (void)lp_shaper(modes, o);
    ADD_FAILURE() << "expected InputError for " << field;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, field) << e.what();
  }
}

TEST(LpShaper, BadInputNamesTheField) {
  const LpShaperOptions good = grid(0.68, 14);
  expect_field_error({}, good, "modes");
  expect_field_error({{1.0, 0.1}, {-2.0, 0.1}}, good, "modes[1].omega");
  expect_field_error({{std::nan(""), 0.1}}, good, "modes[0].omega");
  expect_field_error({{1.0, 1.0}}, good, "modes[0].zeta");
  LpShaperOptions o = good;
  o.pulse_spacing = 0.0;
  expect_field_error(kE21Modes, o, "pulse_spacing");
  o = good;
  o.pulse_count = -1;
  expect_field_error(kE21Modes, o, "pulse_count");
  o = good;
  o.derivative_order = 3;
  expect_field_error(kE21Modes, o, "derivative_order");
  o = good;
  o.bounds = {{1.0, 0.1, 0.0}};
  expect_field_error(kE21Modes, o, "bounds[0].s_max");
  o.bounds = {{0.0, 0.1, 0.05}};
  expect_field_error(kE21Modes, o, "bounds[0].omega");
  o = good;
  o.cost_k = -1.0;
  expect_field_error(kE21Modes, o, "cost_k");
  o = good;
  o.max_pulse = 0.0;
  expect_field_error(kE21Modes, o, "max_pulse");
  // A spacing of exactly one damped period of a mode: every impulse in phase there.
  o = good;
  o.pulse_spacing = 2.0 * std::numbers::pi / (2.25 * std::sqrt(1.0 - 0.01));
  expect_field_error(kE21Modes, o, "pulse_spacing");
  EXPECT_THROW((void)lp_shaper_search(kE21Modes, {}, {.sample_period = -1.0}), core::InputError);
  EXPECT_THROW((void)lp_shaper_search(kE21Modes, {}, {.sample_period = 5.0}), core::InputError);  // > π/ω_d1
}

// GLPK must stay silent, including on infeasible problems.
TEST(LpShaper, PrintsNothing) {
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  (void)lp_shaper(kE21Modes, grid(0.68, 0, 1));
  EXPECT_THROW((void)lp_shaper(kE21Modes, grid(0.68, 5)), core::InputError);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// Units: scaling every frequency by s and the spacing by 1/s gives the same amplitudes (the LP is
// a function of ω·t and ζ only).
TEST(LpShaper, InvariantUnderTimeScaling) {
  const LpShaperOptions o = grid(0.68, 14, 1);
  const Shaper base = lp_shaper(kE21Modes, o);
  const double s = 1000.0;
  std::vector<LpMode> fast;
  for (const LpMode& m : kE21Modes) fast.push_back({m.omega * s, m.zeta});
  LpShaperOptions fo = o;
  fo.pulse_spacing = o.pulse_spacing / s;
  const Shaper scaled = lp_shaper(fast, fo);
  test::expect_near_all(scaled.amplitudes, base.amplitudes, 1e-9);
  ASSERT_EQ(scaled.times.size(), base.times.size());
  for (std::size_t i = 0; i < base.times.size(); ++i) EXPECT_NEAR(scaled.times[i] * s, base.times[i], 1e-9);
}

}  // namespace
}  // namespace servotwin::shaping
