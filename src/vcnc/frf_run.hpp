#pragma once
// Private to vcnc: what the open- and closed-loop frequency-response experiments share.

#include <algorithm>
#include <cmath>
#include <numbers>

#include "servotwin/frf/rfid_block.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/vcnc/frf_experiment.hpp"

namespace servotwin::vcnc::detail {

/// The block's outcome, points and response (with the run's duration) into `out`; `timed_out`:
/// the run stopped at its sample limit.
inline void collect_results(const frf::RfidBlock& block, bool timed_out, FrfExperiment& out) {
  out.timed_out = timed_out;
  out.final_state = block.state();
  out.abort_reason = block.abort_reason();
  out.points.assign(block.points().begin(), block.points().end());
  out.response = block.frequency_response();
  out.response.duration_s = block.elapsed_s();
}

/// The sample loop both experiments run: the block steps on the measured output y and on the
/// control value `next_cv(o)` of its previous output (the open loop's DC hold; 0 inside a loop),
/// the plant on `torque(o, y)` (the block's output itself in open loop, the controller's answer to
/// it inside a loop), until the block ends or `max_time_s` passes; the trace when asked, progress
/// once per second of machine time, then collect_results(). The callables must not allocate.
template <class NextCv, class Torque>
void run_block(frf::RfidBlock& block, machine::FlexiblePlant& plant, double max_time_s, bool keep_trace,
               const FrfProgress& progress, FrfExperiment& out, NextCv&& next_cv, Torque&& torque) {
  constexpr double kTurn = 2.0 * std::numbers::pi;  // rad per cycle
  plant.reset();
  const double ts = plant.ts();
  const auto max_samples = static_cast<long>(std::ceil(max_time_s / ts));
  const long report_every = std::max(1L, std::lround(1.0 / ts));
  if (keep_trace) out.trace.reserve(static_cast<std::size_t>(std::min(max_samples, 20'000'000L)));
  double y = plant.measure().y;
  double cv = 0.0;
  long k = 0;
  for (; k < max_samples; ++k) {
    const frf::RfidOutput o = block.step(true, y, cv);
    cv = next_cv(o);
    if (keep_trace) out.trace.push_back({static_cast<double>(k) * ts, o.mv, y, o.omega / kTurn, o.amplitude, o.thd, o.state});
    if (o.state == frf::RfidState::kDone || o.state == frf::RfidState::kAborted) break;
    y = plant.step(torque(o, y)).y;
    if (progress && k % report_every == 0) progress(static_cast<double>(k) * ts, block.points().size(), o.omega / kTurn);
  }
  collect_results(block, k >= max_samples, out);
}

}  // namespace servotwin::vcnc::detail
