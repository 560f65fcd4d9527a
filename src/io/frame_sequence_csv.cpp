#include "servotwin/io/frame_sequence_csv.hpp"

#include <fmt/format.h>

#include <iterator>

#include "number_format.hpp"

namespace servotwin::io {

void write_frame_sequence_csv(std::ostream& out, const vcnc::FrameSequence& run,
                              const vcnc::FrameSequenceSettings& settings) {
  fmt::memory_buffer buffer;
  auto it = std::back_inserter(buffer);
  fmt::format_to(it,
                 "# servotwin.frame-sequence/1 ts={} setpoint={} load_force={} load_step_time={} stator_force={} "
                 "stator_step_time={}\n",
                 run.ts, settings.setpoint, settings.load_force, settings.load_step_time, settings.stator_force,
                 settings.stator_step_time);
  fmt::format_to(it, "t,setpoint,rotor_velocity,load_velocity,stator_velocity,frame_velocity,motor_force\n");
  const int decimals = detail::time_decimals(0.0, run.ts);
  for (std::size_t k = 0; k < run.time.size(); ++k) {
    detail::append_time(buffer, run.time[k], decimals);
    fmt::format_to(it, ",{},{},{},{},{},{}\n", run.setpoint[k], run.rotor_velocity[k], run.load_velocity[k],
                   run.stator_velocity[k], run.frame_velocity[k], run.motor_force[k]);
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
