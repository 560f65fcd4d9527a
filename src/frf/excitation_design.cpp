// Checks an excitation request and hands it to the design of its type (excitation_design.hpp).
#include "servotwin/frf/excitation_design.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "servotwin/core/error.hpp"

namespace servotwin::frf {

namespace {

// Longer sequences do not fit a drive's signal-generator table nor a reasonable file.
constexpr double kMaxSamples = 1e8;

void require_positive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0)
    throw core::InputError(core::at_field(field), fmt::format("expected a finite value > 0, got {}", value));
}

void check_request(const ExcitationRequest& r) {
  require_positive(r.ts, "ts");
  require_positive(r.f_begin_hz, "f_begin_hz");
  require_positive(r.f_end_hz, "f_end_hz");
  require_positive(r.duration_s, "duration_s");
  require_positive(r.amplitude, "amplitude");
  const double nyquist = 0.5 / r.ts;
  if (r.f_end_hz >= nyquist)
    throw core::InputError(core::at_field("f_end_hz"),
                           fmt::format("{} Hz is at or beyond the Nyquist frequency {} Hz of the sample period {} s: a "
                                       "drive sampling at that period cannot play it",
                                       r.f_end_hz, nyquist, r.ts));
  if (r.f_begin_hz >= r.f_end_hz)
    throw core::InputError(core::at_field("f_begin_hz"),
                           fmt::format("the range must rise: {} Hz is not below {} Hz", r.f_begin_hz, r.f_end_hz));
  if (r.duration_s / r.ts > kMaxSamples)
    throw core::InputError(core::at_field("duration_s"),
                           fmt::format("{} s at {} s per sample is {:.3g} samples; at most {:.0e}", r.duration_s, r.ts,
                                       r.duration_s / r.ts, kMaxSamples));
  if (r.spacing == LineSpacing::kLogarithmic && r.lines_per_decade == 0)
    throw core::InputError(core::at_field("lines_per_decade"), "expected at least 1 line per decade");
  if (!(r.settle_fraction >= 0.0 && r.settle_fraction < 1.0))
    throw core::InputError(core::at_field("settle_fraction"),
                           fmt::format("expected a fraction in [0, 1), got {}", r.settle_fraction));
  if (r.type == ExcitationType::kSineSteps && r.steps == 1)
    throw core::InputError(core::at_field("steps"), "expected at least 2 frequencies (0 = 10 per decade)");
}

}  // namespace

Excitation design_excitation(const ExcitationRequest& request) {
  check_request(request);
  Excitation e;
  switch (request.type) {
    case ExcitationType::kMultisine: e = detail::design_multisine(request); break;
    case ExcitationType::kChirp: e = detail::design_chirp(request); break;
    case ExcitationType::kSineSteps: e = detail::design_sine_steps(request); break;
  }
  e.type = request.type;
  e.ts = request.ts;
  e.f_begin_hz = request.f_begin_hz;
  e.f_end_hz = request.f_end_hz;
  return e;
}

double crest_factor(const std::vector<double>& u) noexcept {
  double peak = 0.0, sum_squares = 0.0;
  for (double v : u) {
    peak = std::max(peak, std::abs(v));
    sum_squares += v * v;
  }
  if (sum_squares == 0.0) return 0.0;
  return peak / std::sqrt(sum_squares / static_cast<double>(u.size()));
}

std::string_view excitation_type_name(ExcitationType type) noexcept {
  switch (type) {
    case ExcitationType::kMultisine: return "multisine";
    case ExcitationType::kChirp: return "chirp";
    case ExcitationType::kSineSteps: return "sine-steps";
  }
  return "?";
}

namespace detail {

void scale_to_peak(Excitation& e, double amplitude) {
  double peak = 0.0;
  for (double v : e.samples) peak = std::max(peak, std::abs(v));
  const double gain = amplitude / peak;
  for (double& v : e.samples) v *= gain;
  // The largest sample is exactly ±amplitude (a drive's limit is the peak the user typed).
  for (double& v : e.samples)
    if (std::abs(std::abs(v) - amplitude) <= 4.0 * std::numeric_limits<double>::epsilon() * amplitude)
      v = std::copysign(amplitude, v);
  e.amplitude = amplitude;
  e.crest_factor = crest_factor(e.samples);
}

}  // namespace detail

}  // namespace servotwin::frf
