#include "servotwin/fit/nonlinear.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <numbers>

#include "servotwin/core/error.hpp"

namespace servotwin::fit {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kSameFrequency = 1e-6;   // relative: points of repeated listed frequencies
constexpr double kMinAmplitudeRatio = 1.2;  // velocity amplitudes must differ to separate the DF

/// The dead zone's describing function over k as a function of x = D/(2A) in [0, 1].
double dead_zone_fraction(double x) {
  if (x >= 1.0) return 0.0;
  if (x <= 0.0) return 1.0;
  return (2.0 / std::numbers::pi) * (std::numbers::pi / 2.0 - std::asin(x) - x * std::sqrt(1.0 - x * x));
}

/// Inverse of dead_zone_fraction on [0, 1] (it decreases from 1 to 0).
double dead_zone_ratio(double fraction) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    (dead_zone_fraction(mid) > fraction ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Excitation amplitude of the point nearest `freq_hz` (log distance).
double amplitude_near(const core::FrequencyResponse& r, double freq_hz) {
  double best = std::numeric_limits<double>::infinity(), amplitude = 0.0;
  for (const auto& p : r.points) {
    const double d = std::abs(std::log(p.freq_hz / freq_hz));
    if (d < best) {
      best = d;
      amplitude = p.amplitude;
    }
  }
  return amplitude;
}

}  // namespace

double coulomb_describing_function(double level, double velocity_amplitude) {
  return 4.0 * level / (std::numbers::pi * velocity_amplitude);
}

double dead_zone_describing_function(double stiffness, double width, double amplitude) {
  return stiffness * dead_zone_fraction(width / (2.0 * amplitude));
}

double dead_zone_width(double stiffness, double effective_stiffness, double amplitude) {
  if (!(stiffness > 0.0) || !(amplitude > 0.0) || !(effective_stiffness > 0.0) || effective_stiffness > stiffness)
    throw core::InputError(core::at_field("effective_stiffness"),
                           "expected 0 < effective stiffness <= stiffness and a positive amplitude");
  return 2.0 * amplitude * dead_zone_ratio(effective_stiffness / stiffness);
}

CoulombFrictionEstimate estimate_coulomb_friction(std::span<const core::FrequencyResponse> experiments,
                                                  OutputKind output, double max_freq_hz) {
  // Group the points of all experiments by frequency: x = 1/V, y = Re(1/P_velocity).
  struct Sample {
    double x, y;
  };
  std::map<double, std::vector<Sample>> groups;
  for (const auto& r : experiments) {
    for (const auto& p : r.points) {
      if (p.freq_hz > max_freq_hz || !(p.amplitude > 0.0)) continue;
      const std::complex<double> velocity =
          output == OutputKind::kPosition ? p.value * std::complex<double>(0.0, kTwoPi * p.freq_hz) : p.value;
      const double v_amplitude = std::abs(velocity) * p.amplitude;
      if (!(v_amplitude > 0.0) || !std::isfinite(v_amplitude)) continue;
      auto it = groups.lower_bound(p.freq_hz * (1.0 - kSameFrequency));
      if (it == groups.end() || it->first > p.freq_hz * (1.0 + kSameFrequency)) it = groups.emplace(p.freq_hz, std::vector<Sample>{}).first;
      it->second.push_back({1.0 / v_amplitude, (1.0 / velocity).real()});
    }
  }
  // Least squares with one intercept per frequency: the slope from the centred sums.
  double sxx = 0.0, sxy = 0.0;
  std::size_t points = 0, frequencies = 0;
  std::vector<const std::vector<Sample>*> used;
  for (const auto& [f, samples] : groups) {
    if (samples.size() < 2) continue;
    const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.x < b.x; });
    if (hi->x < kMinAmplitudeRatio * lo->x) continue;
    double mx = 0.0, my = 0.0;
    for (const auto& s : samples) mx += s.x, my += s.y;
    mx /= static_cast<double>(samples.size());
    my /= static_cast<double>(samples.size());
    for (const auto& s : samples) {
      sxx += (s.x - mx) * (s.x - mx);
      sxy += (s.x - mx) * (s.y - my);
    }
    points += samples.size();
    ++frequencies;
    used.push_back(&samples);
  }
  CoulombFrictionEstimate out;
  out.frequencies = frequencies;
  out.points = points;
  if (frequencies == 0 || points <= frequencies + 1 || !(sxx > 0.0)) {
    out.note = "Coulomb friction not estimated: no frequency below " + std::to_string(max_freq_hz) +
               " Hz was measured at two velocity amplitudes differing by 20 % or more";
    return out;
  }
  const double slope = sxy / sxx;
  double rss = 0.0;
  for (const auto* samples : used) {
    double mx = 0.0, my = 0.0;
    for (const auto& s : *samples) mx += s.x, my += s.y;
    mx /= static_cast<double>(samples->size());
    my /= static_cast<double>(samples->size());
    for (const auto& s : *samples) rss += std::pow(s.y - my - slope * (s.x - mx), 2);
  }
  const double sigma2 = rss / static_cast<double>(points - frequencies - 1);
  const double slope_std = std::sqrt(sigma2 / sxx);
  out.estimated = true;
  out.level = std::numbers::pi * slope / 4.0;
  out.level_std = std::numbers::pi * slope_std / 4.0;
  out.significant = out.level > 3.0 * out.level_std;
  out.note = "from Re(1/P) = Re(1/P_lin) + 4M/(pi V) over " + std::to_string(frequencies) + " frequencies below " +
             std::to_string(max_freq_hz) + " Hz measured at several amplitudes (" + std::to_string(points) + " points)" +
             (out.significant ? "" : "; not significant (below 3 standard deviations)");
  return out;
}

BacklashEstimate estimate_backlash(const FitReport& linear, std::span<const core::FrequencyResponse> experiments,
                                   const FitOptions& options) {
  BacklashEstimate out;
  if (!linear.result.physical.parameters) {
    out.note = "backlash not estimated: the linear model has no two-mass reading (" + linear.result.physical.note + ")";
    return out;
  }
  const double il = linear.result.physical.parameters->load_inertia.value;
  for (const auto& r : experiments) {
    FitResult f;
    try {
      f = fit_model(r, 1, linear.result.model.output, options);
    } catch (const core::InputError&) {
      continue;
    }
    if (!f.converged || f.model.modes.size() != 1 || f.mode_estimates.empty()) continue;
    BacklashEstimate::Run run;
    const double wz = f.model.modes[0].antiresonance.omega_rad_s;
    run.antiresonance_hz = wz / kTwoPi;
    run.antiresonance_hz_std = f.mode_estimates[0].antiresonance_omega.std / kTwoPi;
    run.amplitude = amplitude_near(r, run.antiresonance_hz);
    run.effective_stiffness = il * wz * wz;
    run.twist_amplitude = run.amplitude / run.effective_stiffness;
    if (run.amplitude > 0.0) out.runs.push_back(run);
  }
  std::sort(out.runs.begin(), out.runs.end(), [](const auto& a, const auto& b) { return a.amplitude > b.amplitude; });
  if (out.runs.size() < 2 || !(out.runs.front().amplitude > kMinAmplitudeRatio * out.runs.back().amplitude)) {
    out.note = "backlash not estimated: needs two-mass fits of two experiments whose amplitudes at the antiresonance "
               "differ by 20 % or more";
    return out;
  }
  out.estimated = true;
  const auto& large = out.runs.front();
  const auto& small = out.runs.back();
  const double drop = large.antiresonance_hz - small.antiresonance_hz;
  const double drop_std = std::hypot(large.antiresonance_hz_std, small.antiresonance_hz_std);
  out.significant = std::isfinite(drop_std) && drop > 3.0 * drop_std;
  out.stiffness = large.effective_stiffness;
  if (!out.significant) {
    out.note = "no backlash found: the antiresonance does not fall at the small amplitude by more than 3 standard "
               "deviations (" + std::to_string(drop) + " Hz)";
    return out;
  }
  // k and D jointly: both runs see the dead zone, N(A) = k n(D/2A) with A = T/k_eff.
  double k = large.effective_stiffness;
  double width = 0.0;
  for (int i = 0; i < 100; ++i) {
    width = 2.0 * small.twist_amplitude * dead_zone_ratio(std::min(1.0, small.effective_stiffness / k));
    const double fraction = dead_zone_fraction(width / (2.0 * large.twist_amplitude));
    const double next = large.effective_stiffness / std::max(fraction, 1e-12);
    if (std::abs(next - k) <= 1e-12 * k) break;
    k = next;
  }
  out.stiffness = k;
  out.width = width;
  out.note = "from the antiresonance at " + std::to_string(out.runs.size()) +
             " amplitudes: the shaft is softer at small twist (dead-zone describing function, C5.10)";
  return out;
}

NonlinearMechanics analyze_nonlinear_mechanics(const FitReport& linear, std::span<const core::FrequencyResponse> experiments,
                                               const FitOptions& options) {
  require_motor_side(linear.result.model, "the amplitude-series analysis of friction and backlash", "--amplitude-series");
  // The amplitude series measures the distortion itself: points the measurement marked invalid
  // for their THD or SNR are its data here (the linear fit has left them out already).
  std::vector<core::FrequencyResponse> every_point(experiments.begin(), experiments.end());
  for (core::FrequencyResponse& r : every_point)
    for (core::FrequencyPoint& p : r.points) p.valid = true;
  experiments = every_point;
  NonlinearMechanics out;
  const auto& modes = linear.result.model.modes;
  const double max_freq_hz = modes.empty() ? std::numeric_limits<double>::infinity()
                                           : 0.5 * modes.front().antiresonance.omega_rad_s / kTwoPi;
  out.coulomb = estimate_coulomb_friction(experiments, linear.result.model.output, max_freq_hz);
  out.backlash = estimate_backlash(linear, experiments, options);
  return out;
}

}  // namespace servotwin::fit
