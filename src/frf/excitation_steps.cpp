// Stepped-sine design (excitation_design.hpp): log-spaced frequencies, equal time per step, each
// step a settling part and a measuring window of whole cycles. The played frequency is the
// window's DFT line (cycles / window length), so the single-line DFT of the recording over the
// window has no leakage; the phase runs on from step to step, so the signal never jumps.
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_design.hpp"

namespace servotwin::frf::detail {

namespace {

// Fewest whole cycles in a measuring window (the estimator fits harmonics and needs residual
// degrees of freedom).
constexpr double kMinCycles = 3.0;

std::size_t step_count(const ExcitationRequest& r) {
  if (r.steps > 0) return r.steps;
  const double decades = std::log10(r.f_end_hz / r.f_begin_hz);
  return std::max<std::size_t>(2, static_cast<std::size_t>(std::llround(10.0 * decades)) + 1);
}

}  // namespace

Excitation design_sine_steps(const ExcitationRequest& r) {
  const std::size_t count = step_count(r);
  const double total = std::floor(r.duration_s / r.ts + 1e-9);
  const auto step_samples = static_cast<std::size_t>(std::floor(total / static_cast<double>(count)));
  const auto settle = static_cast<std::size_t>(std::floor(r.settle_fraction * static_cast<double>(step_samples)));
  const std::size_t window = step_samples - settle;
  const double window_s = static_cast<double>(window) * r.ts;
  if (window_s * r.f_begin_hz < kMinCycles) {
    const double needed = kMinCycles / r.f_begin_hz / (1.0 - r.settle_fraction) * static_cast<double>(count);
    throw core::InputError(core::at_field("duration_s"),
                           fmt::format("{} steps of {:.4g} s leave {:.4g} s to measure each, fewer than {} cycles of {} Hz; "
                                       "give at least {:.4g} s or fewer steps",
                                       count, static_cast<double>(step_samples) * r.ts, window_s, kMinCycles,
                                       r.f_begin_hz, needed));
  }

  Excitation e;
  e.samples.resize(step_samples * count);
  const double ratio = r.f_end_hz / r.f_begin_hz;
  double phase = 0.0;
  for (std::size_t j = 0; j < count; ++j) {
    const double wanted = r.f_begin_hz * std::pow(ratio, static_cast<double>(j) / static_cast<double>(count - 1));
    SineStep s;
    // The nearest line, kept inside the requested range.
    const double lowest = std::ceil(r.f_begin_hz * window_s - 1e-9), highest = std::floor(r.f_end_hz * window_s + 1e-9);
    if (lowest + static_cast<double>(count) - 1.0 > highest)
      throw core::InputError(core::at_field(r.steps > 0 ? "steps" : "duration_s"),
                             fmt::format("windows of {:.4g} s hold only {:.0f} distinct frequencies in {} ... {} Hz "
                                         "(lines {:.4g} Hz apart), fewer than {} steps; use fewer steps or a longer "
                                         "duration",
                                         window_s, std::max(0.0, highest - lowest + 1.0), r.f_begin_hz, r.f_end_hz,
                                         1.0 / window_s, count));
    s.cycles = static_cast<std::size_t>(std::max(kMinCycles, std::clamp(std::round(wanted * window_s), lowest, highest)));
    // Below the window's Nyquist line: f_end < 1/(2 ts) keeps cycles < window/2 but rounding up
    // could reach it.
    s.cycles = std::min(s.cycles, (window - 1) / 2);
    // Strictly rising frequencies: where rounding or the floor of three cycles would repeat one,
    // take the next line.
    if (!e.steps.empty()) s.cycles = std::max(s.cycles, e.steps.back().cycles + 1);
    if (2 * s.cycles >= window)
      throw core::InputError(core::at_field("steps"),
                             fmt::format("{} steps do not fit distinct frequencies below the Nyquist frequency in "
                                         "windows of {} samples; use fewer steps",
                                         count, window));
    s.freq_hz = static_cast<double>(s.cycles) / window_s;
    s.begin = j * step_samples;
    s.settle_samples = settle;
    s.measure_samples = window;
    const double increment = 2.0 * std::numbers::pi * s.freq_hz * r.ts;
    // The phase from the step's start (no running sum, so no drift over long steps).
    for (std::size_t i = 0; i < step_samples; ++i)
      e.samples[s.begin + i] = std::sin(phase + increment * static_cast<double>(i));
    phase = std::fmod(phase + increment * static_cast<double>(step_samples), 2.0 * std::numbers::pi);
    e.steps.push_back(s);
  }
  scale_to_peak(e, r.amplitude);
  return e;
}

}  // namespace servotwin::frf::detail
