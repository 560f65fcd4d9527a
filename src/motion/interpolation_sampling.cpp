// Interpolation step 4: sampling. Walks spans and phases sequentially (no search per sample);
// the only allocation is the output columns.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "interpolation_detail.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/large_buffer.hpp"

namespace servotwin::motion {

namespace {

using detail::Geometry;
using detail::Phase;
using detail::PlanData;
using detail::Span;

/// Output columns: where each requested axis goes. Samples are produced in order and appended
/// to columns reserved for the whole trajectory (no zero-filling pass, no reallocation).
struct Columns {
  std::array<std::vector<double>*, kAxisCount> dst{};
  std::array<std::size_t, kAxisCount> axis{};
  std::size_t count = 0;

  void push(double x, double y, double z) const {
    const double p[kAxisCount] = {x, y, z};
    for (std::size_t c = 0; c < count; ++c) dst[c]->push_back(p[axis[c]]);
  }
  void push(const Point& p) const { push(p[0], p[1], p[2]); }
};

std::vector<Axis> resolve_axes(const PlanData& plan, const std::vector<Axis>& requested) {
  std::array<bool, kAxisCount> want{};
  if (requested.empty()) {
    for (std::size_t i = 0; i < kAxisCount; ++i) want[i] = (plan.used_axes & axis_bit(static_cast<Axis>(i))) != 0;
    if (plan.used_axes == 0) want[0] = true;
  } else {
    for (const Axis a : requested) {
      const auto i = static_cast<std::size_t>(a);
      if (i >= kAxisCount) throw core::InputError(core::SourceLocation{"", 0, 0, "axes"}, "unknown axis");
      if (want[i])
        throw core::InputError(core::SourceLocation{"", 0, 0, "axes"},
                               std::string("axis ") + axis_letter(a) + " is requested twice");
      want[i] = true;
    }
  }
  std::vector<Axis> axes;
  for (std::size_t i = 0; i < kAxisCount; ++i)
    if (want[i]) axes.push_back(static_cast<Axis>(i));
  return axes;
}

/// cos and sin of angles near a reference angle whose cos and sin come from libm: the offset d
/// (|d| <= kMaxOffset) goes through the angle-addition formulas with Taylor polynomials of
/// cos d (to d^10) and sin d (to d^9), whose truncation errors are below 3e-20 and 1.2e-18. The
/// reference is recomputed (not propagated) whenever the offset grows too large, so errors do not
/// accumulate: the result is within a few ulp of cos/sin, i.e. positions within ~1e-15 R.
class NearbyAngle {
 public:
  static constexpr double kMaxOffset = 0.125;

  void reset() noexcept { valid_ = false; }
  void eval(double a, double& c, double& s) noexcept {
    double d = a - ref_;
    if (!valid_ || !(std::abs(d) <= kMaxOffset)) {
      ref_ = a;
      ref_c_ = std::cos(a);
      ref_s_ = std::sin(a);
      valid_ = true;
      d = 0.0;
    }
    const double d2 = d * d;
    const double sd = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0 + d2 * (1.0 / 362880.0)))));
    const double cd_minus_1 =
        d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0 + d2 * (-1.0 / 3628800.0)))));
    c = ref_c_ + (ref_c_ * cd_minus_1 - ref_s_ * sd);
    s = ref_s_ + (ref_s_ * cd_minus_1 + ref_c_ * sd);
  }

 private:
  bool valid_ = false;
  double ref_ = 0.0;
  double ref_c_ = 1.0;
  double ref_s_ = 0.0;
};

/// Samples one chain: samples first+1 .. first+samples (the last is the exact stop point).
void sample_chain(const PlanData& plan, const Span& span, const Columns& out) {
  const std::size_t n = span.samples;
  const double dt = span.duration / static_cast<double>(n);
  std::size_t m = 1;
  NearbyAngle trig;
  std::uint32_t trig_segment = std::numeric_limits<std::uint32_t>::max();
  for (std::size_t ph = span.phase_begin; ph < span.phase_end && m < n; ++ph) {
    const Phase& p = plan.phases[ph];
    const Geometry& g = plan.segments[p.segment].geo;
    const double t_end = ph + 1 == span.phase_end ? detail::kInfinity : p.t1;
    if (!g.is_arc) {
      for (; m < n; ++m) {
        const double t = static_cast<double>(m) * dt;
        if (t > t_end) break;
        const double s = detail::phase_position(p, t);
        out.push(g.start[0] + s * g.dir[0], g.start[1] + s * g.dir[1], g.start[2] + s * g.dir[2]);
      }
    } else {
      if (p.segment != trig_segment) {
        trig.reset();
        trig_segment = p.segment;
      }
      for (; m < n; ++m) {
        const double t = static_cast<double>(m) * dt;
        if (t > t_end) break;
        const double phi = detail::phase_position(p, t) * g.rad_per_s;
        const double a = g.angle0 + g.sense * phi;
        const double r = g.r0 + g.dr * phi;
        double c = 0.0;
        double sn = 0.0;
        trig.eval(a, c, sn);
        const double rc = r * c;
        const double rs = r * sn;
        out.push(g.base[0] + rc * g.e1[0] + rs * g.e2[0] + phi * g.rise[0],
                 g.base[1] + rc * g.e1[1] + rs * g.e2[1] + phi * g.rise[1],
                 g.base[2] + rc * g.e1[2] + rs * g.e2[2] + phi * g.rise[2]);
      }
    }
  }
  out.push(span.end);
}

/// The span containing time t, or nullptr after the last one.
const Span* find_span(const PlanData& plan, double x_samples) {
  const auto it = std::upper_bound(plan.spans.begin(), plan.spans.end(), x_samples,
                                   [](double x, const Span& s) { return x < static_cast<double>(s.first_sample); });
  if (it == plan.spans.begin()) return nullptr;
  return &*(it - 1);
}

const Phase& find_phase(const PlanData& plan, const Span& span, double tau) {
  const auto first = plan.phases.begin() + static_cast<std::ptrdiff_t>(span.phase_begin);
  const auto last = plan.phases.begin() + static_cast<std::ptrdiff_t>(span.phase_end);
  auto it = std::lower_bound(first, last, tau, [](const Phase& p, double t) { return p.t1 < t; });
  if (it == last) --it;
  return *it;
}

}  // namespace

Trajectory sample(const MotionPlan& plan, const std::vector<Axis>& axes) {
  Trajectory tr;
  sample_into(plan, tr, axes);
  return tr;
}

void sample_into(const MotionPlan& plan, Trajectory& tr, const std::vector<Axis>& axes) {
  const PlanData& d = plan.data();
  tr.ts = d.limits.ts;
  tr.axes = resolve_axes(d, axes);
  const std::size_t n = d.sample_count;
  tr.positions.resize(tr.axes.size());
  Columns out;
  out.count = tr.axes.size();
  for (std::size_t c = 0; c < out.count; ++c) {
    tr.positions[c].clear();
    core::reserve_large(tr.positions[c], n);
    out.dst[c] = &tr.positions[c];
    out.axis[c] = static_cast<std::size_t>(tr.axes[c]);
  }
  out.push(d.start);
  for (const Span& span : d.spans) {
    if (span.phase_begin == span.phase_end) {
      for (std::size_t m = 1; m <= span.samples; ++m) out.push(span.end);
    } else {
      sample_chain(d, span, out);
    }
  }
}

Point MotionPlan::position_at(double t) const {
  const PlanData& d = *data_;
  const double x = std::clamp(t, 0.0, duration()) / d.limits.ts;
  const Span* span = find_span(d, x);
  if (span == nullptr) return d.start;
  const double local = x - static_cast<double>(span->first_sample);
  if (span->phase_begin == span->phase_end || local >= static_cast<double>(span->samples)) return span->end;
  const double tau = local * span->duration / static_cast<double>(span->samples);
  const Phase& p = find_phase(d, *span, tau);
  return d.segments[p.segment].geo.position(detail::phase_position(p, tau));
}

double MotionPlan::speed_at(double t) const {
  const PlanData& d = *data_;
  const double x = std::clamp(t, 0.0, duration()) / d.limits.ts;
  const Span* span = find_span(d, x);
  if (span == nullptr) return 0.0;
  const double local = x - static_cast<double>(span->first_sample);
  if (span->phase_begin == span->phase_end || local >= static_cast<double>(span->samples)) return 0.0;
  const double k = static_cast<double>(span->samples) * d.limits.ts / span->duration;
  const double tau = local * span->duration / static_cast<double>(span->samples);
  return detail::phase_speed(find_phase(d, *span, tau), tau) / k;
}

std::vector<double> detail::sample_path_positions(const PlanData& d) {
  std::vector<double> out;
  core::reserve_large(out, d.sample_count);
  double s = 0.0;
  out.push_back(s);
  for (const Span& span : d.spans) {
    if (span.phase_begin != span.phase_end) {
      const double dt = span.duration / static_cast<double>(span.samples);
      std::size_t ph = span.phase_begin;
      for (std::size_t m = 1; m < span.samples; ++m) {
        const double t = static_cast<double>(m) * dt;
        while (ph + 1 < span.phase_end && t > d.phases[ph].t1) ++ph;
        const Phase& p = d.phases[ph];
        out.push_back(d.segments[p.segment].s_begin + detail::phase_position(p, t));
      }
      const Segment& last = d.segments[d.phases[span.phase_end - 1].segment];
      s = last.s_begin + last.geo.length;  // the chain ends exactly at its last segment's end
    }
    out.insert(out.end(), span.phase_begin == span.phase_end ? span.samples : 1, s);
  }
  return out;
}

}  // namespace servotwin::motion
