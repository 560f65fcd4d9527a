// The response of a recorded excitation (excitation_recording.hpp): align, then the estimator
// the excitation's structure allows.
#include "servotwin/frf/excitation_recording.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/offline.hpp"

namespace servotwin::frf {

namespace {

/// Per-period DFTs over the whole periods that lie in the recording after the skipped ones.
RecordedEstimate periodic(const Excitation& e, std::span<const double> x, std::span<const double> y,
                          const Alignment& a, const RecordedOptions& options) {
  const auto n = static_cast<std::ptrdiff_t>(e.period_samples);
  const auto record = static_cast<std::ptrdiff_t>(x.size());
  // First period wholly recorded, at least the skipped ones later; periods end with the sequence.
  std::ptrdiff_t first = std::max<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(options.skip_periods),
                                                  a.offset >= 0 ? 0 : (-a.offset + n - 1) / n);
  std::ptrdiff_t end = std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(e.periods), (record - a.offset) / n);
  const std::ptrdiff_t used = end - first;
  if (used < 2)
    throw core::InputError(core::at_field("skip_periods"),
                           fmt::format("the recording holds {} whole period(s) of the excitation after the first {} "
                                       "(skipped as transient or not recorded); at least 2 are needed",
                                       std::max<std::ptrdiff_t>(0, used), first));
  const auto start = static_cast<std::size_t>(a.offset + first * n);
  const auto length = static_cast<std::size_t>(used * n);
  MultisineOptions o;
  o.period_samples = e.period_samples;
  o.periods = static_cast<std::size_t>(used);
  o.excited_lines = e.lines;
  MultisineEstimate m = estimate_multisine(x.subspan(start, length), y.subspan(start, length), e.ts, o);
  RecordedEstimate r;
  r.response = std::move(m.response);
  r.response.duration_s = static_cast<double>(x.size()) * e.ts;
  r.periods_used = static_cast<std::size_t>(used);
  r.method = fmt::format("per-period DFT over periods {} ... {} of {} ({} samples each), {} lines", first + 1, end,
                         e.periods, e.period_samples, e.lines.size());
  return r;
}

/// A single sweep: H1 over the sweep and what the recording holds of its ring-out (an eighth
/// of the sweep at most).
RecordedEstimate single_sweep(const Excitation& e, std::span<const double> x, std::span<const double> y,
                              const Alignment& a) {
  const auto record = static_cast<std::ptrdiff_t>(x.size());
  const auto n = static_cast<std::ptrdiff_t>(e.samples.size());
  const std::ptrdiff_t first = std::max<std::ptrdiff_t>(0, a.offset);
  const std::ptrdiff_t end = std::min(record, a.offset + n + n / 8);
  WelchOptions o;
  o.min_freq_hz = e.f_begin_hz;
  o.max_freq_hz = e.f_end_hz;
  const auto start = static_cast<std::size_t>(first);
  const auto length = static_cast<std::size_t>(end - first);
  RecordedEstimate r;
  r.response = estimate_h1(x.subspan(start, length), y.subspan(start, length), e.ts, o);
  r.response.duration_s = static_cast<double>(x.size()) * e.ts;
  r.method = fmt::format("H1 (Welch) over the sweep, samples {} ... {} of the recording", first, end - 1);
  return r;
}

}  // namespace

RecordedEstimate estimate_recorded(const Excitation& e, std::span<const double> x, std::span<const double> y,
                                   const RecordedOptions& options) {
  if (x.size() != y.size())
    throw core::InputError(core::at_field("output"), "input and output must have the same number of samples");
  const Alignment a = align_excitation(x, e.samples);
  RecordedEstimate r;
  if (e.type == ExcitationType::kSineSteps) {
    r.response = estimate_sine_steps(x, y, e.ts, e.steps, a.offset);
    r.steps_used = r.response.size();
    if (r.steps_used < 2)
      throw core::InputError(core::at_field("output"),
                             fmt::format("only {} of the {} steps' measuring windows lie in the recording; at least 2 "
                                         "are needed",
                                         r.steps_used, e.steps.size()));
    r.method = fmt::format("single-line DFT per step, {} of {} steps", r.steps_used, e.steps.size());
  } else if (e.periods >= 2) {
    r = periodic(e, x, y, a, options);
  } else {
    r = single_sweep(e, x, y, a);
  }
  r.alignment = a;
  return r;
}

}  // namespace servotwin::frf
