// Interpolation: validation of the limits, the planning pipeline and the MotionPlan accessors.
#include "servotwin/motion/interpolation.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "gcode_common.hpp"
#include "interpolation_detail.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::motion {

namespace {

[[noreturn]] void bad_limit(const char* field, const std::string& expected, double value) {
  throw core::InputError(core::SourceLocation{"", 0, 0, field}, "must be " + expected + ", got " + detail::format_number(value));
}

void require_positive(const char* field, double value) {
  if (!std::isfinite(value) || value <= 0.0) bad_limit(field, "a finite value > 0", value);
}

/// Issue 27 §3: --ts 10 sampled a 1.3 s circle four times, a trajectory no controller runs. CNC
/// interpolation periods lie between tens of microseconds and tens of milliseconds.
constexpr double kMaxInterpolationPeriod = 0.1;

void validate(const InterpolationLimits& l) {
  require_positive("ts", l.ts);
  if (l.ts > kMaxInterpolationPeriod)
    bad_limit("ts", "at most 0.1 s (a CNC's interpolation period: controllers use 0.1 to 10 ms)", l.ts);
  require_positive("accel", l.accel);
  if (l.jerk) require_positive("jerk", *l.jerk);
  require_positive("rapid_feed_mm_min", l.rapid_feed_mm_min);
  require_positive("max_feed_mm_min", l.max_feed_mm_min);
  if (!(l.corner_angle_deg >= 0.0 && l.corner_angle_deg <= 180.0))
    bad_limit("corner_angle_deg", "in [0, 180] degrees", l.corner_angle_deg);
  if (!(l.arc_tangential_ratio > 0.0 && l.arc_tangential_ratio < 1.0))
    bad_limit("arc_tangential_ratio", "in (0, 1)", l.arc_tangential_ratio);
  if (!(l.junction_share > 0.0 && l.junction_share < 1.0)) bad_limit("junction_share", "in (0, 1)", l.junction_share);
  if (l.max_samples < 1) bad_limit("max_samples", ">= 1", 0.0);
  if (l.jerk && !std::isfinite(l.accel * l.accel / *l.jerk))
    bad_limit("jerk", "such that accel^2 / jerk is finite", *l.jerk);
}

}  // namespace

MotionPlan::MotionPlan() : data_(std::make_shared<const detail::PlanData>()) {}

MotionPlan::MotionPlan(std::shared_ptr<const detail::PlanData> data) : data_(std::move(data)) {}

const InterpolationLimits& MotionPlan::limits() const noexcept { return data_->limits; }
double MotionPlan::ts() const noexcept { return data_->limits.ts; }
std::size_t MotionPlan::sample_count() const noexcept { return data_->sample_count; }
double MotionPlan::duration() const noexcept { return static_cast<double>(data_->sample_count - 1) * data_->limits.ts; }
std::uint8_t MotionPlan::used_axes() const noexcept { return data_->used_axes; }
Point MotionPlan::start_point() const noexcept { return data_->start; }
Point MotionPlan::end_point() const noexcept { return data_->end; }
const std::vector<PlannedMove>& MotionPlan::moves() const noexcept { return data_->moves; }

MotionPlan plan_motion(const Program& program, const InterpolationLimits& limits) {
  validate(limits);
  detail::Path path = detail::build_path(program, limits);
  if (path.segments.size() >= std::numeric_limits<std::uint32_t>::max())
    throw core::InputError("the program has too many motion blocks (more than 2^32)");
  const std::vector<detail::Piece> pieces = detail::make_pieces(path, limits);
  auto plan = std::make_shared<detail::PlanData>();
  plan->limits = limits;
  // Arcs move both axes of their plane even when they end where they start (full circles).
  std::uint8_t used = program.used_axes();
  for (const detail::Segment& seg : path.segments)
    if (seg.geo.is_arc)
      for (std::size_t i = 0; i < kAxisCount; ++i)
        if (seg.geo.e1[i] != 0.0 || seg.geo.e2[i] != 0.0) used = static_cast<std::uint8_t>(used | axis_bit(static_cast<Axis>(i)));
  plan->used_axes = used;
  plan->start = path.start;
  plan->end = path.start;
  detail::plan_profiles(path, pieces, program, *plan);
  plan->segments = std::move(path.segments);
  return MotionPlan(std::move(plan));
}

Trajectory interpolate(const Program& program, const InterpolationLimits& limits, const std::vector<Axis>& axes) {
  return sample(plan_motion(program, limits), axes);
}

}  // namespace servotwin::motion
