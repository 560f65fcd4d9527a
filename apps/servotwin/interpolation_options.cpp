#include "interpolation_options.hpp"

#include "servotwin/io/machine_json.hpp"
#include "servotwin/vcnc/machine_run.hpp"

namespace servotwin::cli {

void add_interpolation_options(CLI::App& cmd, InterpolationInput& a, bool with_ts) {
  cmd.add_option("-m,--machine", a.machine, "Take the CNC limits (and ts) and the start position from a machine preset or JSON file");
  if (with_ts) a.ts_opt = cmd.add_option("--ts", a.ts, "Sample period [s]")->capture_default_str();
  a.accel_opt = cmd.add_option("--accel", a.accel, "Acceleration limit along the path [mm/s^2]")->capture_default_str();
  a.jerk_opt = cmd.add_option("--jerk", a.jerk, "Jerk limit [mm/s^3] (S-curve); default: none (trapezoidal)");
  a.rapid_opt = cmd.add_option("--rapid-feed", a.rapid, "Feed of G00 / F MAX moves [mm/min]")->capture_default_str();
  a.max_feed_opt = cmd.add_option("--max-feed", a.max_feed, "Cap on programmed feeds [mm/min]");
  a.corner_opt = cmd.add_option("--corner-angle", a.corner, "Exact stop where the path turns more than this [deg]")
                     ->capture_default_str();
  cmd.add_flag("--exact-stop", a.exact_stop, "Stop exactly at the end of every block (G61, no look-ahead)");
}

ResolvedInterpolation resolve_interpolation(const InterpolationInput& a) {
  ResolvedInterpolation r;
  if (!a.machine.empty()) {
    const auto machine = io::load_machine(a.machine);
    r.limits = vcnc::limits_of(machine);
    r.start = vcnc::machine_start(machine);
  }
  if (a.ts_opt != nullptr && a.ts_opt->count() > 0) r.limits.ts = a.ts;
  if (a.accel_opt->count() > 0) r.limits.accel = a.accel;
  if (a.jerk_opt->count() > 0) r.limits.jerk = a.jerk;
  if (a.rapid_opt->count() > 0) r.limits.rapid_feed_mm_min = a.rapid;
  if (a.max_feed_opt->count() > 0) r.limits.max_feed_mm_min = a.max_feed;
  if (a.corner_opt->count() > 0) r.limits.corner_angle_deg = a.corner;
  if (a.exact_stop) r.limits.exact_stop_every_block = true;
  return r;
}

void rethrow_interpolation_error(const core::InputError& e, const InterpolationInput& a,
                                 const core::SourceLocation* ts_source) {
  if (!e.where().file.empty()) return;
  const std::string& field = e.where().field;
  struct Limit {
    const char* field;
    const CLI::Option* option;
    const char* name;
  };
  // The sample budget is exceeded by a program too long for its sample period: name the period.
  const Limit limits[] = {{"ts", a.ts_opt, "--ts"},
                          {"max_samples", a.ts_opt, "--ts"},
                          {"accel", a.accel_opt, "--accel"},
                          {"jerk", a.jerk_opt, "--jerk"},
                          {"rapid_feed_mm_min", a.rapid_opt, "--rapid-feed"},
                          {"max_feed_mm_min", a.max_feed_opt, "--max-feed"},
                          {"corner_angle_deg", a.corner_opt, "--corner-angle"}};
  for (const Limit& l : limits) {
    if (field != l.field) continue;
    const bool typed = l.option != nullptr && l.option->count() > 0;
    const bool is_ts = field == "ts" || field == "max_samples";
    if (is_ts && ts_source != nullptr) throw core::InputError(*ts_source, e.reason());
    if (typed) throw core::InputError(core::at_field(l.name), e.reason());
    if (!a.machine.empty()) throw core::InputError({a.machine, 0, 0, is_ts ? "ts" : "cnc." + field}, e.reason());
    throw core::InputError(core::at_field(l.name), e.reason());
  }
}

}  // namespace servotwin::cli
