#pragma once
// Private to vcnc: what the open- and closed-loop frequency-response experiments share.

#include "servotwin/frf/rfid_block.hpp"
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

}  // namespace servotwin::vcnc::detail
