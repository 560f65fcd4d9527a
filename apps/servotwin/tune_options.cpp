// The options `servotwin tune` and `servotwin tune compare` share (tune_options.hpp).
#include "tune_options.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/tuning/uncertainty.hpp"

namespace servotwin::cli {

namespace {

/// W2 as the tightest stable envelope of the fitted model's relative error on the measured points.
core::TransferFunction weight_from_residuals(const TuneSpecArgs& a, const TunePlant& plant) {
  if (!plant.fitted) {
    throw core::InputError(core::at_field("--w2-from-frf"),
                           "needs a fitted plant model (servotwin.plant-model/1) to compare the measurement with");
  }
  const core::FrequencyResponse measured = io::read_frf_file(a.w2_from_frf);
  try {
    const tuning::UncertaintyEnvelope e = tuning::uncertainty_weight_from_residuals(plant.model, measured, a.w2_order);
    const auto& n = e.w2.num().coefficients();
    const auto& d = e.w2.den().coefficients();
    fmt::print("uncertainty weight from {}: W2(s) = ({}) / ({}) (s in rad/s), log-area {:.3g}\n", a.w2_from_frf,
               fmt::join(n.begin(), n.end(), ", "), fmt::join(d.begin(), d.end(), ", "), e.log_area);
    return e.w2;
  } catch (const core::InputError& e) {
    throw core::InputError({a.w2_from_frf, 0, 0, e.where().field}, e.reason());
  }
}

}  // namespace

void add_spec_options(CLI::App& cmd, TuneSpecArgs& a) {
  cmd.add_option("--ms", a.ms, "Limit on the sensitivity peak ||S||")->capture_default_str();
  cmd.add_option("--mt", a.mt, "Limit on the tracking peak ||wl/w*|| (motor side without a load side)")
      ->capture_default_str();
  cmd.add_option("--min-damping", a.min_damping,
                 "Least damping of the visible closed-loop poles (0..1): also required by the automatic search; "
                 "for plants with higher modes, where a pole near an antiresonance can leave the load or frame ringing");
  cmd.add_option("--load-side", a.load_side,
                 "Where the load is: auto (a two-mass plant's load; none with higher modes) or chain (the higher modes "
                 "lie in the drive train between motor and load, e.g. a test bed: estimate the load through them)")
      ->check(CLI::IsMember({"auto", "chain"}))
      ->capture_default_str();
  cmd.add_option("--w2-num", a.w2_num, "Uncertainty weight W2(s) numerator, descending powers of s [rad/s], e.g. \"2.6,0\"");
  cmd.add_option("--w2-den", a.w2_den, "Uncertainty weight W2(s) denominator, e.g. \"1,15\"");
  cmd.add_option("--w2-from-frf", a.w2_from_frf,
                 "Uncertainty weight fitted above the model's relative error on this measured response (servotwin.frf/1); "
                 "needs a fitted plant model")
      ->check(CLI::ExistingFile);
  cmd.add_option("--w2-order", a.w2_order, "Order of the fitted weight (1 or 2)")->check(CLI::IsMember({1, 2}))->capture_default_str();
  cmd.add_option("--current-lag", a.current_lag, "Current-loop time constant [s] (evaluated, not designed for)");
  cmd.add_option("--filter", a.filter, "Velocity-measurement filter time constant [s]");
  cmd.add_option("--delay", a.delay, "Loop delay [s] (computation, communication, half a sample of hold)");
  cmd.add_option("--ts", a.ts, "Drive sample period [s]: also write the Tustin-discretized controller");
}

void apply_spec(const TuneSpecArgs& a, const TunePlant& plant, tuning::TuneOptions& o) {
  o.ms = a.ms;
  o.mt = a.mt;
  o.min_damping = a.min_damping;
  o.chain_load = a.load_side == "chain";
  if (a.w2_num.empty() != a.w2_den.empty()) {
    throw core::InputError(core::at_field(a.w2_num.empty() ? "--w2-num" : "--w2-den"), "give both --w2-num and --w2-den");
  }
  if (!a.w2_num.empty() && !a.w2_from_frf.empty()) {
    throw core::InputError(core::at_field("--w2-from-frf"), "give either --w2-num/--w2-den or --w2-from-frf, not both");
  }
  if (!a.w2_num.empty()) {
    o.w2 = core::TransferFunction(parse_coefficients(a.w2_num, "--w2-num"), parse_coefficients(a.w2_den, "--w2-den"));
  }
  if (!a.w2_from_frf.empty()) o.w2 = weight_from_residuals(a, plant);
  o.hf = plant.hf;
  // Options override what a plant description says.
  if (a.current_lag) o.hf.current_lag_s = *a.current_lag;
  if (a.filter) o.hf.feedback_filter_s = *a.filter;
  if (a.delay) o.hf.delay_s = *a.delay;
  o.ts = a.ts ? a.ts : plant.ts;
  if (o.ts) check_sample_period(*o.ts, "--ts");
}

}  // namespace servotwin::cli
