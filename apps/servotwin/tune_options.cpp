// The options `servotwin tune` and `servotwin tune compare` share (tune_options.hpp).
#include "tune_options.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <numbers>
#include <string>
#include <vector>

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

namespace {

constexpr const char* kDriveFilterForms =
    "notch:auto, notch:F_HZ:WIDTH_HZ:DEPTH_DB, lowpass:F_HZ, lowpass:F_HZ:ZETA or biquad:FZ_HZ:ZETA_Z:FP_HZ:ZETA_P";

/// The numbers after the filter's name.
std::vector<double> filter_numbers(const std::string& text, const std::vector<std::string>& fields) {
  std::vector<double> out;
  for (std::size_t i = 1; i < fields.size(); ++i) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(fields[i], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != fields[i].size())
      throw core::InputError(core::at_field("--drive-filter"),
                             fmt::format("\"{}\": field {} (\"{}\") is not a number; expected {}", text, i + 1,
                                         fields[i], kDriveFilterForms));
    out.push_back(v);
  }
  return out;
}

std::vector<std::string> split_colons(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t pos; (pos = text.find(':', start)) != std::string::npos; start = pos + 1)
    out.push_back(text.substr(start, pos - start));
  out.push_back(text.substr(start));
  return out;
}

}  // namespace

void apply_drive_filters(const std::vector<std::string>& texts, std::optional<double> rolloff_hz,
                         tuning::TuneOptions& o) {
  using tuning::DriveFilterSpec;
  using tuning::DriveFilterType;
  for (const std::string& text : texts) {
    const std::vector<std::string> f = split_colons(text);
    const auto fail = [&](const std::string& why) {
      throw core::InputError(core::at_field("--drive-filter"),
                             fmt::format("\"{}\": {}; expected {}", text, why, kDriveFilterForms));
    };
    if (f[0] == "notch" && f.size() == 2 && f[1] == "auto") {
      if (o.auto_notch) fail("notch:auto given twice");
      o.auto_notch = true;
      continue;
    }
    DriveFilterSpec s;
    const std::vector<double> v = (f[0] == "notch" || f[0] == "lowpass" || f[0] == "biquad")
                                      ? filter_numbers(text, f)
                                      : (fail("unknown filter \"" + f[0] + "\""), std::vector<double>{});
    if (f[0] == "notch") {
      if (v.size() != 3) fail("a notch takes its centre, width and depth");
      s.type = DriveFilterType::kNotch;
      s.frequency_hz = v[0];
      s.width_hz = v[1];
      s.depth_db = v[2];
    } else if (f[0] == "lowpass") {
      if (v.empty() || v.size() > 2) fail("a lowpass takes its corner and, for second order, its damping");
      s.type = DriveFilterType::kLowpass;
      s.frequency_hz = v[0];
      if (v.size() == 2) s.damping = v[1];
    } else {
      if (v.size() != 4) fail("a biquad takes the numerator's frequency and damping, then the denominator's");
      s.type = DriveFilterType::kBiquad;
      s.frequency_hz = v[0];
      s.damping = v[1];
      s.pole_frequency_hz = v[2];
      s.pole_damping = v[3];
    }
    o.drive_filters.push_back(s);
  }
  if (rolloff_hz) {
    // The lowpass case: H-infinity designs with it as its roll-off; a PI/PID carries it as a filter.
    if (tuning::is_hinf(o.structure)) {
      o.rolloff_rad_s = 2.0 * std::numbers::pi * *rolloff_hz;
    } else {
      DriveFilterSpec s;
      s.type = DriveFilterType::kLowpass;
      s.frequency_hz = *rolloff_hz;
      o.drive_filters.push_back(s);
    }
  }
}

}  // namespace servotwin::cli
