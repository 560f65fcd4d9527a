// The drive filters (issue 25 §5): definitions, Tustin biquads with prewarping, the chain, and
// the refusals. Expected values: tests/data/tuning/drive_filter_reference.json from
// tools/reference/drive_filter_reference.py (scipy.signal.bilinear with the prewarped rate,
// scipy.signal.freqz, scipy.optimize.brentq), and closed forms stated at each test.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/tuning/drive_filter.hpp"

namespace servotwin::tuning {
namespace {

constexpr double kFilterTwoPi = 2.0 * std::numbers::pi;

const nlohmann::json& filters_reference() {
  static const nlohmann::json j =
      test_support::read_json_fixture("tuning/drive_filter_reference.json", "drive_filter_reference.py");
  return j;
}

DriveFilterSpec filter_spec_of(const nlohmann::json& j) {
  DriveFilterSpec s;
  const std::string type = j.at("type");
  s.type = type == "notch" ? DriveFilterType::kNotch : type == "lowpass" ? DriveFilterType::kLowpass : DriveFilterType::kBiquad;
  s.frequency_hz = j.at("frequency_hz");
  s.width_hz = j.value("width_hz", 0.0);
  s.depth_db = j.value("depth_db", 0.0);
  if (j.contains("damping")) s.damping = j.at("damping").get<double>();
  s.pole_frequency_hz = j.value("pole_frequency_hz", 0.0);
  s.pole_damping = j.value("pole_damping", 0.0);
  return s;
}

void expect_coefficients(std::span<const double> got, const nlohmann::json& want, double tol, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  double scale = 0.0;
  for (const auto& v : want) scale = std::max(scale, std::abs(v.get<double>()));
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i].get<double>(), tol * scale) << what << " [" << i << "]";
}

TEST(DriveFilter, ContinuousAndDiscreteFormsMatchScipy) {
  // Continuous: the definitions written out in the script (rounding only: 1e-12). Discrete:
  // scipy's bilinear at the prewarped rate; both are a handful of flops from the same numbers,
  // so 1e-10 relative (the tan of the prewarp is the largest rounding source).
  const nlohmann::json& ref = filters_reference();
  const double ts = ref.at("ts");
  for (const nlohmann::json& c : ref.at("cases")) {
    const std::string name = c.at("name");
    const DriveFilter f = make_drive_filter(filter_spec_of(c.at("spec")), ts);
    expect_coefficients(f.continuous.num().coefficients(), c.at("num"), 1e-12, name + " num");
    expect_coefficients(f.continuous.den().coefficients(), c.at("den"), 1e-12, name + " den");
    ASSERT_TRUE(f.discrete.has_value());
    const DiscreteBiquad& q = *f.discrete;
    EXPECT_NEAR(q.prewarp_hz, c.at("prewarp_hz").get<double>(), 1e-9 * q.prewarp_hz) << name;
    const std::vector<double> b{q.b0, q.b1, q.b2}, a{1.0, q.a1, q.a2};
    expect_coefficients(b, c.at("b"), 1e-10, name + " b");
    expect_coefficients(a, c.at("a"), 1e-10, name + " a");
    // Prewarping keeps the response exact at the filter's own frequency (scipy's freqz and the
    // continuous value agree there to rounding).
    const std::complex<double> h = response(q, kFilterTwoPi * q.prewarp_hz);
    const std::complex<double> want = test::root_of(c.at("continuous_at_prewarp"));
    EXPECT_LT(std::abs(h - want), 1e-9 * std::max(1.0, std::abs(want))) << name;
    EXPECT_LT(std::abs(h - test::root_of(c.at("response_at_prewarp"))), 1e-9 * std::max(1.0, std::abs(want))) << name;
  }
}

TEST(DriveFilter, NotchHasItsDepthAtTheCentreAndItsWidthAtMinusThreeDecibels) {
  // Depth: |N(jω0)| = ζz/ζp = 10^(−depth/20) (closed form). Width: the −3 dB frequencies of the
  // infinitely deep notch found by brentq in the script lie `width` apart; a 200 dB notch is
  // infinitely deep to 1e-10 in |N|², the tolerance.
  DriveFilterSpec s;
  s.frequency_hz = 100.0;
  s.width_hz = 30.0;
  s.depth_db = 26.0;
  const core::TransferFunction n = continuous_filter(s);
  EXPECT_NEAR(std::abs(n.frequency_response(kFilterTwoPi * 100.0)), std::pow(10.0, -26.0 / 20.0), 1e-12);
  EXPECT_NEAR(std::abs(n.frequency_response(0.0)), 1.0, 1e-15);
  const nlohmann::json& band = filters_reference().at("notch_band");
  s.depth_db = 200.0;
  const core::TransferFunction deep = continuous_filter(s);
  EXPECT_NEAR(band.at("upper_hz").get<double>() - band.at("lower_hz").get<double>(), 30.0, 1e-9);
  for (const char* edge : {"lower_hz", "upper_hz"})
    EXPECT_NEAR(std::norm(deep.frequency_response(kFilterTwoPi * band.at(edge).get<double>())), 0.5, 1e-9) << edge;
}

TEST(DriveFilter, ChainIsTheProductOfItsBiquads) {
  // The discrete state space of two filters against the product of their biquads' responses.
  const double ts = 1e-4;
  DriveFilterSpec notch;
  notch.frequency_hz = 300.0;
  notch.width_hz = 90.0;
  notch.depth_db = 20.0;
  DriveFilterSpec low;
  low.type = DriveFilterType::kLowpass;
  low.frequency_hz = 1000.0;
  const std::vector<DriveFilter> filters{make_drive_filter(notch, ts), make_drive_filter(low, ts)};
  const core::DiscreteStateSpace chain = discrete_chain(filters, ts);
  EXPECT_EQ(chain.states(), 3);
  for (double f : {10.0, 250.0, 300.0, 900.0, 3000.0}) {
    const double w = kFilterTwoPi * f;
    const std::complex<double> want = response(*filters[0].discrete, w) * response(*filters[1].discrete, w);
    const std::complex<double> got = core::frequency_response(chain, w)(0, 0);
    EXPECT_LT(std::abs(got - want), 1e-12) << f;
  }
  const core::DiscreteStateSpace none = discrete_chain({}, ts);
  EXPECT_EQ(none.states(), 0);
  EXPECT_EQ(none.D(0, 0), 1.0);
}

TEST(DriveFilter, RefusesWhatNoDriveCanRun) {
  DriveFilterSpec s;
  s.frequency_hz = 100.0;
  s.width_hz = 30.0;
  s.depth_db = -6.0;
  test::expect_input_error([&] { validate(s, 1e-4, "--drive-filter"); }, "--drive-filter", "negative depth");
  s.depth_db = 20.0;
  s.frequency_hz = 6000.0;
  test::expect_input_error([&] { validate(s, 1e-4, "--drive-filter"); }, "--drive-filter", "Nyquist");
  s.frequency_hz = 100.0;
  s.width_hz = 0.0;
  test::expect_input_error([&] { validate(s, 1e-4, "--drive-filter"); }, "--drive-filter", "width");
  DriveFilterSpec b;
  b.type = DriveFilterType::kBiquad;
  b.frequency_hz = 100.0;
  b.pole_frequency_hz = 120.0;
  b.pole_damping = 0.5;
  test::expect_input_error([&] { validate(b, std::nullopt, "--drive-filter"); }, "--drive-filter", "numerator damping");
  b.damping = 0.1;
  b.pole_damping = 0.0;
  test::expect_input_error([&] { validate(b, std::nullopt, "--drive-filter"); }, "--drive-filter", "denominator damping");
}

}  // namespace
}  // namespace servotwin::tuning
