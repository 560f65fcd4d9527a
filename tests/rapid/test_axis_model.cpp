// AxisModel in the frequency domain: poles and zeros against the thesis's Tables 3.3-3.5,
// frequency responses, poles, zeros and bandwidth against tools/reference/axis_model_reference.py
// (numpy.roots, scipy.signal.freqs, brentq), DC gains and a bandwidth against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "test_axis_model_support.hpp"

namespace servotwin::rapid {
namespace {

using test::axis_model_reference;
using test::reference_model;

constexpr double kTs = 1e-3;

struct Printed {
  double freq_hz;
  double zeta;
};

// Thesis values are printed with two decimals, from coefficients printed with two decimals: the
// roots are compared with half a unit of the last printed digit plus `rel` of the frequency.
void expect_printed(const std::vector<core::ModalInfo>& actual, std::vector<Printed> expected, double rel,
                    const std::string& what) {
  ASSERT_EQ(actual.size(), expected.size()) << what;
  std::vector<core::ModalInfo> sorted = actual;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.freq_hz < b.freq_hz; });
  std::sort(expected.begin(), expected.end(), [](const auto& a, const auto& b) { return a.freq_hz < b.freq_hz; });
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(sorted[i].freq_hz, expected[i].freq_hz, 0.005 + rel * expected[i].freq_hz) << what << " #" << i;
    EXPECT_NEAR(sorted[i].zeta, expected[i].zeta, 0.005 + rel) << what << " #" << i;
  }
}

TEST(AxisModelPolesZeros, ThesisTable33PPiActual) {
  const AxisModel m({.a1 = 372.76, .a2 = 62009.83, .a3 = 1527104.87, .b2 = 11106.33, .d0 = 441, .d1 = -302}, kTs);
  expect_printed(m.poles(), {{36.26, 0.75}, {36.26, 0.75}, {4.68, 1.00}}, 0.0, "poles");
  expect_printed(m.zeros(), {{21.88, 1.00}}, 0.0, "zeros");
  EXPECT_TRUE(m.is_stable());
}

TEST(AxisModelPolesZeros, ThesisTable33PPiEstimated) {
  // Estimated coefficients printed with 2 decimals: the fast real pole and the right-half-plane
  // zero pair move by up to 0.1 % within that rounding.
  const AxisModel m({.a1 = 2648.46, .a2 = 776813.58, .a3 = 21349028.29, .b0 = 1.08, .b1 = -415.03, .b2 = 65194.67}, kTs);
  expect_printed(m.poles(), {{368.80, 1.00}, {47.84, 1.00}, {4.88, 1.00}}, 1e-3, "poles");
  expect_printed(m.zeros(), {{58.91, -0.72}, {58.91, -0.72}, {23.00, 1.00}}, 1e-3, "zeros");
}

TEST(AxisModelPolesZeros, ThesisTable34PidActual) {
  const AxisModel m({.a1 = 192.65, .a2 = 44356.23, .a3 = 316830.21, .b0 = 0, .b1 = 190.10, .b2 = 44356.23}, kTs);
  expect_printed(m.poles(), {{33.00, 0.45}, {33.00, 0.45}, {1.17, 1.00}}, 0.0, "poles");
  expect_printed(m.zeros(), {{35.96, 1.00}, {1.17, 1.00}}, 0.0, "zeros");
  // The y axis of the same table.
  const AxisModel y({.a1 = 178.75, .a2 = 41031.98, .a3 = 293085.57, .b1 = 175.85, .b2 = 41031.98}, kTs);
  expect_printed(y.poles(), {{31.74, 0.43}, {31.74, 0.43}, {1.17, 1.00}}, 0.0, "y poles");
  expect_printed(y.zeros(), {{35.96, 1.00}, {1.17, 1.00}}, 0.0, "y zeros");
}

TEST(AxisModelPolesZeros, ThesisTable34PidEstimated) {
  const AxisModel m({.a1 = 214.13, .a2 = 60040.19, .a3 = 685295.65, .b0 = -0.35, .b1 = 203.86, .b2 = 60043.78}, kTs);
  expect_printed(m.poles(), {{38.21, 0.42}, {38.21, 0.42}, {1.89, 1.00}}, 0.0, "poles");
  // The right-half-plane zero -b1/b0 ~ 2 pi 129.5 Hz depends on b0 = -0.35 printed to +-0.005
  // (1.4 %); the thesis prints 129.50 where the printed coefficients give 127.3.
  const std::vector<core::ModalInfo> z = m.zeros();
  ASSERT_EQ(z.size(), 3u);
  expect_printed({z[0], z[1]}, {{1.89, 1.00}, {32.88, 1.00}}, 0.006, "slow zeros");
  EXPECT_NEAR(z[2].freq_hz, 129.50, 0.02 * 129.50);
  EXPECT_DOUBLE_EQ(z[2].zeta, -1.0);
  EXPECT_GT(z[2].root.real(), 0.0);
}

TEST(AxisModelPolesZeros, ThesisTable35SlidingMode) {
  const AxisModel actual({.a1 = 390.10, .a2 = 57029.44, .a3 = 3801962.50, .b0 = 1.0, .b1 = 390.10, .b2 = 57029.44}, kTs);
  expect_printed(actual.poles(), {{31.83, 1.00}, {21.94, 0.69}, {21.94, 0.69}}, 0.0, "poles");
  expect_printed(actual.zeros(), {{31.83, 1.00}, {21.94, 0.69}, {21.94, 0.69}}, 0.0, "zeros");
  const AxisModel est({.a1 = 566.95, .a2 = 370137.94, .a3 = 15346572.85, .b0 = 0.85, .b1 = 574.83, .b2 = 370142.25},
                      kTs);
  expect_printed(est.poles(), {{93.76, 0.44}, {93.76, 0.44}, {7.04, 1.00}}, 0.0, "estimated poles");
  expect_printed(est.zeros(), {{101.62, 0.50}, {101.62, 0.50}, {7.05, 1.00}}, 1e-3, "estimated zeros");
}

void expect_modal_matches(const std::vector<core::ModalInfo>& actual, const nlohmann::json& expected,
                          const std::string& what) {
  ASSERT_EQ(actual.size(), expected.size()) << what;
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const auto& e = expected[i];
    const double scale = std::hypot(e.at("re").get<double>(), e.at("im").get<double>());
    EXPECT_NEAR(actual[i].root.real(), e.at("re").get<double>(), 1e-9 * scale) << what << " #" << i;
    EXPECT_NEAR(actual[i].root.imag(), e.at("im").get<double>(), 1e-9 * scale) << what << " #" << i;
    EXPECT_NEAR(actual[i].freq_hz, e.at("freq_hz").get<double>(), 1e-9 * e.at("freq_hz").get<double>()) << what;
    EXPECT_NEAR(actual[i].zeta, e.at("zeta").get<double>(), 1e-9) << what << " #" << i;
  }
}

TEST(AxisModelPolesZeros, MatchNumpyRootsForAllReferenceModels) {
  for (const auto& [name, model] : axis_model_reference().at("models").items()) {
    const AxisModel m(test::coefficients_from_json(model.at("coefficients")), kTs);
    expect_modal_matches(m.poles(), model.at("poles"), name + " poles");
    expect_modal_matches(m.zeros(), model.at("zeros"), name + " zeros");
    EXPECT_EQ(m.is_stable(), name != "unstable") << name;
  }
}

TEST(AxisModelPolesZeros, WithoutIntegratorTheCommonFactorSIsCancelled) {
  // a3 = 0: (b0 s^3 + b1 s^2 + b2 s)/(s^3 + a1 s^2 + a2 s) is (b1 s + b2)/(s^2 + a1 s + a2).
  const AxisModel m(reference_model("no_integrator"), kTs);
  EXPECT_EQ(m.tracking().den().degree(), 2);
  EXPECT_EQ(m.poles().size(), 2u);
  EXPECT_EQ(m.zeros().size(), 1u);
  EXPECT_TRUE(m.is_stable());
  EXPECT_DOUBLE_EQ(m.tracking_dc_gain(), 1.0);  // b2 = a2
  EXPECT_DOUBLE_EQ(m.disturbance_dc_gain(), -1.0 / 30000.0);
  // Closed form of the static gain b2/a2 and deflection -1/a2 when b2 != a2.
  const AxisModel p({.a1 = 100.0, .a2 = 2500.0, .a3 = 0.0, .b2 = 2000.0}, kTs);
  EXPECT_DOUBLE_EQ(p.tracking_dc_gain(), 0.8);
  EXPECT_DOUBLE_EQ(p.disturbance_dc_gain(), -1.0 / 2500.0);
  EXPECT_NEAR(std::abs(p.tracking().frequency_response(1e-6)), 0.8, 1e-12);
  // Double integrator left in the loop (a2 = a3 = 0): a pole at 0, not stable, infinite DC gain.
  const AxisModel q({.a1 = 100.0, .b2 = 2000.0}, kTs);
  EXPECT_FALSE(q.is_stable());
  EXPECT_TRUE(std::isinf(q.tracking_dc_gain()));
  EXPECT_TRUE(std::isnan(q.bandwidth_hz()));
}

TEST(AxisModelPolesZeros, DcGainsWithIntegrator) {
  const AxisModel m(reference_model("ppi_x_actual"), kTs);
  EXPECT_DOUBLE_EQ(m.tracking_dc_gain(), 1.0);
  EXPECT_DOUBLE_EQ(m.disturbance_dc_gain(), 0.0);
  EXPECT_NEAR(std::abs(m.tracking().frequency_response(1e-10) - 1.0), 0.0, 1e-10);
  EXPECT_NEAR(std::abs(m.disturbance().frequency_response(1e-10)), 0.0, 1e-14);
}

TEST(AxisModelFrequencyResponse, MatchesScipyFreqs) {
  for (const auto& c : axis_model_reference().at("frf")) {
    const std::string name = c.at("model");
    const AxisModel m(reference_model(name), kTs);
    const std::vector<double> omega = test::doubles(c.at("omega"));
    const auto track = m.tracking_response(omega);
    const auto dist = m.disturbance_response(omega);
    const auto tre = test::doubles(c.at("tracking_re")), tim = test::doubles(c.at("tracking_im"));
    const auto dre = test::doubles(c.at("disturbance_re")), dim = test::doubles(c.at("disturbance_im"));
    for (std::size_t i = 0; i < omega.size(); ++i) {
      const std::complex<double> t_ref(tre[i], tim[i]), d_ref(dre[i], dim[i]);
      EXPECT_LE(std::abs(track[i] - t_ref), 1e-11 * std::abs(t_ref)) << name << " tracking at " << omega[i];
      EXPECT_LE(std::abs(dist[i] - d_ref), 1e-11 * std::abs(d_ref)) << name << " disturbance at " << omega[i];
    }
  }
}

TEST(AxisModelBandwidth, MatchesScipyBrentq) {
  for (const auto& [name, model] : axis_model_reference().at("models").items()) {
    if (model.at("bandwidth_hz").is_null()) continue;
    const AxisModel m(test::coefficients_from_json(model.at("coefficients")), kTs);
    if (model.at("bandwidth_hz").is_string()) {  // "inf": JSON has no infinity
      EXPECT_TRUE(std::isinf(m.bandwidth_hz())) << name;
    } else {
      const double expected = model.at("bandwidth_hz").get<double>();
      EXPECT_NEAR(m.bandwidth_hz(), expected, 1e-9 * expected) << name;
    }
  }
}

TEST(AxisModelBandwidth, ThirdOrderButterworthClosedForm) {
  // a3/((s + w)(s^2 + w s + w^2)): |G|^2 = 1/(1 + (omega/w)^6), so the -3 dB point is
  // omega = w (10^0.3 - 1)^(1/6).
  const double w = 2.0 * std::numbers::pi * 20.0;
  const AxisModel m({.a1 = 2 * w, .a2 = 2 * w * w, .a3 = w * w * w}, kTs);
  const double expected = w * std::pow(std::pow(10.0, 0.3) - 1.0, 1.0 / 6.0) / (2.0 * std::numbers::pi);
  EXPECT_NEAR(m.bandwidth_hz(), expected, 1e-10 * expected);
}

TEST(AxisModelBandwidth, FullFeedforwardNeverDrops) {
  // Perfect feedforward (Table 3.5 actual): tracking == 1, no -3 dB point below Nyquist.
  EXPECT_TRUE(std::isinf(AxisModel(reference_model("smc_x_actual"), kTs).bandwidth_hz()));
}

TEST(AxisModelBandwidth, NarrowNotchIsNotSteppedOver) {
  // G = (s^2 + wz^2)(s + p) / ((s^2 + 2 zp wz s + wz^2)(s + p)): unit gain except a notch at wz
  // about 1 % wide, narrower than one step of the 200-per-decade grid. With x = omega/wz and
  // r = 10^(-3/20), |G| = r where (1 - x^2) = c x, c = 2 zp r / sqrt(1 - r^2), so the first
  // crossing is x = (sqrt(c^2 + 4) - c)/2.
  const double wz = 2 * std::numbers::pi * 40.0, p = 2 * std::numbers::pi * 5.0, zp = 0.004;
  const ModelCoefficients c{.a1 = 2 * zp * wz + p, .a2 = wz * wz + 2 * zp * wz * p, .a3 = wz * wz * p,
                            .b0 = 1.0, .b1 = p, .b2 = wz * wz};
  const AxisModel m(c, kTs);
  const double r = std::pow(10.0, -3.0 / 20.0);
  const double cc = 2 * zp * r / std::sqrt(1 - r * r);
  const double expected = 40.0 * (std::sqrt(cc * cc + 4) - cc) / 2;
  EXPECT_NEAR(m.bandwidth_hz(), expected, 1e-9 * expected);
}

TEST(AxisModelConstruction, RejectsBadInput) {
  ModelCoefficients c = reference_model("pid_x_actual");
  EXPECT_THROW(AxisModel(c, 0.0), core::InputError);
  EXPECT_THROW(AxisModel(c, std::numeric_limits<double>::infinity()), core::InputError);
  c.b1 = std::numeric_limits<double>::quiet_NaN();
  try {
    AxisModel bad(c, kTs);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "b1");
  }
}

}  // namespace
}  // namespace servotwin::rapid
