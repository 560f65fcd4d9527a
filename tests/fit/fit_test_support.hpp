#pragma once
// Shared helpers of the fit tests: the reference fixture (tools/reference/fit_reference.py) and
// synthetic frequency responses of known plants.
#include <cmath>
#include <complex>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "json_fixture.hpp"
#include "servotwin/core/frequency_response.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit::test {

inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

inline const nlohmann::json& fixture() {
  static const nlohmann::json data = test_support::read_json_fixture("fit/fit_reference.json", "fit_reference.py");
  return data;
}

inline const nlohmann::json& fixture_model(const std::string& name) {
  for (const auto& m : fixture()["models"])
    if (m["name"] == name) return m;
  throw std::runtime_error("no model " + name + " in fit_reference.json");
}

/// The catalog's E10 / Table 5.1 plant: K = 0.5, a = 0.2, ωz = 1, ζz = 0.06, ωn = 3, ζn = 0.15.
inline PlantModel e10_plant() {
  PlantModel m;
  m.gain = 0.5;
  m.rigid_pole_rad_s = 0.2;
  m.modes = {Mode{{1.0, 0.06}, {3.0, 0.15}}};
  return m;
}

/// E37 test-bed configuration 1 or 2 as printed ("τ" values as pole locations, catalog defect 29).
inline PlantModel e37_plant(int configuration) {
  PlantModel m;
  if (configuration == 1) {
    m.gain = 544.6;
    m.rigid_pole_rad_s = 0.16;
    m.modes = {Mode{{35.3, 0.19}, {70.8, 0.02}}, Mode{{114.6, 0.11}, {260.1, 0.005}}};
    m.lag_pole_rad_s = 0.0038;
  } else {
    m.gain = 454.5;
    m.rigid_pole_rad_s = 0.15;
    m.modes = {Mode{{49.9, 0.24}, {254.0, 0.02}}};
    m.lag_pole_rad_s = 0.0022;
  }
  return m;
}

/// Exact response of `tf` on log-spaced frequencies [rad/s].
inline core::FrequencyResponse sample(const core::TransferFunction& tf, double w_lo, double w_hi, std::size_t count) {
  core::FrequencyResponse r;
  for (double w : core::log_space(w_lo, w_hi, count)) {
    core::FrequencyPoint p;
    p.freq_hz = w / kTwoPi;
    p.value = tf.frequency_response(w);
    r.points.push_back(p);
  }
  return r;
}

/// Response of a plant model (through its transfer function, so the model's own response() is not
/// what generates the data), with an optional pure delay.
inline core::FrequencyResponse sample(const PlantModel& m, double w_lo, double w_hi, std::size_t count) {
  core::FrequencyResponse r = sample(m.transfer_function(), w_lo, w_hi, count);
  if (m.delay_s)
    for (auto& p : r.points) p.value *= std::polar(1.0, -kTwoPi * p.freq_hz * *m.delay_s);
  return r;
}

/// Gaussian noise of `sigma_db` on the magnitude (dB) and `sigma_deg` on the phase (degrees).
inline void add_polar_noise(core::FrequencyResponse& r, double sigma_db, double sigma_deg, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto& p : r.points) {
    const double mag_db = 20.0 * std::log10(std::abs(p.value)) + sigma_db * n(rng);
    const double phase = std::arg(p.value) + sigma_deg * std::numbers::pi / 180.0 * n(rng);
    p.value = std::polar(std::pow(10.0, mag_db / 20.0), phase);
  }
}

/// Circular complex noise of relative size `relative` (std of the value = relative·|P|); sets std_dev.
inline void add_relative_noise(core::FrequencyResponse& r, double relative, unsigned seed, bool set_std) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto& p : r.points) {
    const double s = relative * std::abs(p.value);
    p.value += std::complex<double>(s / std::sqrt(2.0) * n(rng), s / std::sqrt(2.0) * n(rng));
    if (set_std) p.std_dev = s;
  }
}

}  // namespace servotwin::fit::test
