// Logarithmic chirp design (excitation_design.hpp): f(t) = f_b (f_e/f_b)^{t/T} over a period of
// T seconds, the instantaneous phase 2π f_b L (e^{t/L} − 1) with L = T / ln(f_e/f_b) (the
// exponential sweep of A. Farina, "Simultaneous measurement of impulse response and distortion
// with a swept-sine technique", AES 108th Convention, 2000, eq. 2), scaled by less than half a
// cycle so that the period ends on a whole cycle: the signal starts at 0, ends at 0, and a
// repeated chirp is continuous.
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_design.hpp"

namespace servotwin::frf::detail {

Excitation design_chirp(const ExcitationRequest& r) {
  const std::size_t periods = r.periods == 0 ? 1 : r.periods;
  const double total = std::floor(r.duration_s / r.ts + 1e-9);
  const auto n = static_cast<std::size_t>(std::floor(total / static_cast<double>(periods)));
  const double sweep_s = static_cast<double>(n) * r.ts;
  // A single sweep is read by H1 with segments of at most half the record: ten cycles of the
  // lowest frequency put its line spacing at f_begin/2.5 or finer. A repeated sweep is read per
  // period: one cycle of the lowest frequency per period puts a line at f_begin.
  const double least_cycles = periods == 1 ? 10.0 : 1.0;
  if (sweep_s * r.f_begin_hz < least_cycles)
    throw core::InputError(core::at_field("duration_s"),
                           fmt::format("a sweep of {} s holds fewer than {} cycle(s) of {} Hz; give at least {} s",
                                       sweep_s, least_cycles, r.f_begin_hz,
                                       static_cast<double>(periods) * least_cycles / r.f_begin_hz));
  const double rate = sweep_s / std::log(r.f_end_hz / r.f_begin_hz);  // L
  const double cycles = rate * (r.f_end_hz - r.f_begin_hz);           // phase at T over 2π
  // Closing on a whole cycle moves every frequency by round(c)/c: at least 20 cycles keep that
  // within 2.5 %.
  if (cycles < 20.0)
    throw core::InputError(core::at_field("duration_s"),
                           fmt::format("a sweep of {} s over {} ... {} Hz holds {:.3g} cycles, fewer than 20; give a "
                                       "longer duration or a wider range",
                                       sweep_s, r.f_begin_hz, r.f_end_hz, cycles));
  const double whole = std::round(cycles) / cycles;

  Excitation e;
  e.period_samples = n;
  e.periods = periods;
  // The lines of a period inside the range: what the per-period estimator reads when repeated.
  const double df = 1.0 / sweep_s;
  for (auto k = static_cast<std::size_t>(std::max(1.0, std::ceil(r.f_begin_hz / df - 1e-9)));
       static_cast<double>(k) * df <= r.f_end_hz * (1.0 + 1e-12) && k < (n + 1) / 2; ++k)
    e.lines.push_back(k);
  if (periods > 1 && e.lines.empty())
    throw core::InputError(core::at_field("periods"),
                           fmt::format("no DFT line of a {} s period lies in {} ... {} Hz; use fewer periods",
                                       sweep_s, r.f_begin_hz, r.f_end_hz));
  e.samples.resize(n * periods);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * r.ts;
    const double phase = 2.0 * std::numbers::pi * whole * r.f_begin_hz * rate * std::expm1(t / rate);
    e.samples[i] = std::sin(phase);
  }
  for (std::size_t k = 1; k < periods; ++k)
    std::copy(e.samples.begin(), e.samples.begin() + static_cast<std::ptrdiff_t>(n),
              e.samples.begin() + static_cast<std::ptrdiff_t>(k * n));
  scale_to_peak(e, r.amplitude);
  return e;
}

}  // namespace servotwin::frf::detail
