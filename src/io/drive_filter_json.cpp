#include "drive_filter_json.hpp"

#include <cmath>
#include <string>

namespace servotwin::io::detail {

namespace {

using nlohmann::json;
using tuning::DriveFilterType;

json coefficients(std::span<const double> c) { return json(std::vector<double>(c.begin(), c.end())); }

json optional_number(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::optional<DriveFilterType> type_from_string(const std::string& name) {
  for (DriveFilterType t : {DriveFilterType::kNotch, DriveFilterType::kLowpass, DriveFilterType::kBiquad})
    if (tuning::to_string(t) == name) return t;
  return std::nullopt;
}

bool agree(double a, double b, double scale) { return std::abs(a - b) <= 1e-6 * std::max(scale, 1e-300); }

/// The numbers of array `key` must equal `expected` (1e-6 relative to the largest magnitude).
void check_coefficients(const JsonObject& o, std::string_view key, const std::vector<double>& expected) {
  const json& a = o.array(key);
  double scale = 0.0;
  for (double v : expected) scale = std::max(scale, std::abs(v));
  bool ok = a.size() == expected.size();
  for (std::size_t i = 0; ok && i < a.size(); ++i) ok = a[i].is_number() && agree(a[i].get<double>(), expected[i], scale);
  if (!ok)
    o.fail(key, "is " + a.dump() + " but the filter's parameters give " + json(expected).dump() +
                    " (agreement within 1e-6 relative expected)");
}

std::vector<double> as_vector(std::span<const double> c) { return {c.begin(), c.end()}; }

tuning::DriveFilterSpec read_spec(const JsonObject& o) {
  tuning::DriveFilterSpec s;
  const std::string type = o.string("type");
  const auto parsed = type_from_string(type);
  if (!parsed) o.fail("type", "expected \"notch\", \"lowpass\" or \"biquad\", got \"" + type + "\"");
  s.type = *parsed;
  s.frequency_hz = o.number("frequency_hz");
  s.width_hz = o.number_or("width_hz", 0.0);
  s.depth_db = o.number_or("depth_db", 0.0);
  s.damping = o.optional_number("damping");
  s.pole_frequency_hz = o.number_or("pole_frequency_hz", 0.0);
  s.pole_damping = o.number_or("pole_damping", 0.0);
  s.automatic = o.boolean_or("automatic", false);
  return s;
}

}  // namespace

json drive_filters_json(const std::vector<tuning::DriveFilter>& filters) {
  json out = json::array();
  for (const tuning::DriveFilter& f : filters) {
    const tuning::DriveFilterSpec& s = f.spec;
    json j = {{"type", tuning::to_string(s.type)}, {"frequency_hz", s.frequency_hz}};
    if (s.type == DriveFilterType::kNotch) {
      j["width_hz"] = s.width_hz;
      j["depth_db"] = s.depth_db;
    } else {
      j["damping"] = optional_number(s.damping);
    }
    if (s.type == DriveFilterType::kBiquad) {
      j["pole_frequency_hz"] = s.pole_frequency_hz;
      j["pole_damping"] = s.pole_damping;
    }
    j["automatic"] = s.automatic;
    j["reason"] = f.reason;
    j["continuous"] = {{"num", coefficients(f.continuous.num().coefficients())},
                       {"den", coefficients(f.continuous.den().coefficients())}};
    if (f.discrete) {
      const tuning::DiscreteBiquad& q = *f.discrete;
      j["discrete"] = {{"ts", q.ts}, {"method", "tustin"}, {"prewarp_hz", q.prewarp_hz},
                       {"b", {q.b0, q.b1, q.b2}}, {"a", {1.0, q.a1, q.a2}}};
    } else {
      j["discrete"] = nullptr;
    }
    out.push_back(std::move(j));
  }
  return out;
}

std::vector<tuning::DriveFilter> read_drive_filters(const json& parent, const JsonObject& object, std::string_view key,
                                                    std::optional<double> controller_ts) {
  std::vector<tuning::DriveFilter> out;
  const auto it = parent.find(key);
  if (it == parent.end() || (it->is_array() && it->empty())) return out;
  if (!it->is_array()) object.fail(key, std::string("expected an array of filters, found ") + it->type_name());
  for (std::size_t i = 0; i < it->size(); ++i) {
    const std::string path = object.member_path(key) + "[" + std::to_string(i) + "]";
    const json& item = (*it)[i];
    if (!item.is_object()) object.fail(std::string(key) + "[" + std::to_string(i) + "]", "expected a filter object");
    const JsonObject o(item, path, object.source());
    o.allow_only({"type", "frequency_hz", "width_hz", "depth_db", "damping", "pole_frequency_hz", "pole_damping",
                  "automatic", "reason", "continuous", "discrete"});
    const tuning::DriveFilterSpec spec = read_spec(o);
    std::optional<double> ts;
    const auto d = item.find("discrete");
    if (d != item.end() && !d->is_null()) ts = o.object("discrete").number("ts");
    try {
      tuning::validate(spec, std::nullopt, path);
    } catch (const core::InputError& e) {
      o.fail("type", "this " + tuning::to_string(spec.type) + ": " + e.reason());
    }
    if (ts && controller_ts && std::abs(*ts - *controller_ts) > 1e-12 * *controller_ts)
      o.object("discrete").fail("ts", "is " + std::to_string(*ts) + " s but the controller is discretized at " +
                                          std::to_string(*controller_ts) + " s");
    tuning::DriveFilter f;
    try {
      f = tuning::make_drive_filter(spec, ts, path);
    } catch (const core::InputError& e) {
      o.object("discrete").fail("ts", e.reason());
    }
    f.reason = o.string_or("reason", "");
    const JsonObject c = o.object("continuous");
    c.allow_only({"num", "den"});
    check_coefficients(c, "num", as_vector(f.continuous.num().coefficients()));
    check_coefficients(c, "den", as_vector(f.continuous.den().coefficients()));
    if (f.discrete) {
      const JsonObject q = o.object("discrete");
      q.allow_only({"ts", "method", "prewarp_hz", "b", "a"});
      if (q.string("method") != "tustin") q.fail("method", "expected \"tustin\"");
      const tuning::DiscreteBiquad& b = *f.discrete;
      if (!agree(q.number("prewarp_hz"), b.prewarp_hz, b.prewarp_hz))
        q.fail("prewarp_hz", "expected the filter's own frequency " + std::to_string(b.prewarp_hz) + " Hz");
      check_coefficients(q, "b", {b.b0, b.b1, b.b2});
      check_coefficients(q, "a", {1.0, b.a1, b.a2});
    }
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace servotwin::io::detail
