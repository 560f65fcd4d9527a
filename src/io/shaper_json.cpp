#include "servotwin/io/shaper_json.hpp"

#include <cmath>
#include <numbers>

#include "json_reader.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/program_file.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::io {

namespace {

using detail::JsonObject;
using nlohmann::json;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

std::vector<double> finite_array(const JsonObject& o, std::string_view key) {
  const json& array = o.array(key);
  if (!array.is_array()) o.fail(key, "expected an array of numbers");
  std::vector<double> values;
  values.reserve(array.size());
  for (std::size_t i = 0; i < array.size(); ++i) {
    if (!array[i].is_number() || !std::isfinite(array[i].get<double>()))
      o.fail(key, "expected finite numbers, element " + std::to_string(i) + " is " + array[i].dump());
    values.push_back(array[i].get<double>());
  }
  return values;
}

/// The grid of a discrete shaper: samples consistent with times_s and ts.
DiscreteForm parse_discrete(const JsonObject& o, const shaping::Shaper& s, std::optional<double> ts) {
  if (!ts) o.fail("ts", "a discrete shaper needs the sample period it was discretized for");
  DiscreteForm d;
  const json& samples = o.array("samples");
  if (samples.size() != s.times.size())
    o.fail("samples", "expected " + std::to_string(s.times.size()) + " sample indices (one per impulse), got " +
                          std::to_string(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!samples[i].is_number_unsigned()) o.fail("samples", "expected non-negative whole numbers, element " + std::to_string(i) + " is " + samples[i].dump());
    const auto k = samples[i].get<std::size_t>();
    if (std::abs(static_cast<double>(k) * *ts - s.times[i]) > 1e-9 * *ts + 1e-15 * s.times[i])
      o.fail("samples", "sample " + std::to_string(k) + " is not times_s[" + std::to_string(i) + "] / ts = " +
                            json(s.times[i] / *ts).dump());
    d.samples.push_back(k);
  }
  d.discretization = o.string_or("discretization", "exact");
  if (d.discretization != "exact" && d.discretization != "round")
    o.fail("discretization", "expected exact or round, got '" + d.discretization + "'");
  if (const auto c = o.optional_object("continuous")) {
    c->allow_only({"times_s", "amplitudes"});
    d.continuous.type = s.type;
    d.continuous.omega = s.omega;
    d.continuous.zeta = s.zeta;
    d.continuous.times = finite_array(*c, "times_s");
    d.continuous.amplitudes = finite_array(*c, "amplitudes");
    if (d.continuous.times.size() != d.continuous.amplitudes.size())
      c->fail("amplitudes", "expected one amplitude per time");
  }
  return d;
}

}  // namespace

json shaper_to_json(const shaping::Shaper& shaper, const ShaperFileExtras& extras) {
  json j;
  j["format"] = kShaperFormat;
  j["type"] = shaper.type;
  j["freq_hz"] = shaper.omega / kTwoPi;
  j["zeta"] = shaper.zeta;
  j["times_s"] = shaper.times;
  j["amplitudes"] = shaper.amplitudes;
  j["duration_s"] = shaper.duration();
  j["residual_at_design"] = shaping::residual_vibration(shaper, shaper.omega, shaper.zeta);
  if (!extras.parameters.empty()) j["parameters"] = extras.parameters;
  if (extras.ts) j["ts"] = *extras.ts;
  if (!extras.robustness.empty()) j["robustness"] = extras.robustness;
  if (extras.discrete) {
    j["discrete"] = true;
    j["samples"] = extras.discrete->samples;
    j["discretization"] = extras.discrete->discretization;
    j["continuous"] = {{"times_s", extras.discrete->continuous.times}, {"amplitudes", extras.discrete->continuous.amplitudes}};
  }
  return j;
}

LoadedShaper parse_shaper_json(std::string_view text, std::string_view source_name) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kShaperFormat, source_name);
  const JsonObject o(document, "", source_name);
  o.allow_only({"format", "type", "freq_hz", "zeta", "times_s", "amplitudes", "duration_s", "residual_at_design",
                "parameters", "ts", "robustness", "alternatives", "reasons", "discrete", "samples", "discretization",
                "continuous"});
  LoadedShaper loaded;
  shaping::Shaper& s = loaded.shaper;
  s.type = o.string("type");
  const double freq_hz = o.number("freq_hz");
  if (!(freq_hz > 0.0)) o.fail("freq_hz", "expected a design frequency > 0 Hz, got " + json(freq_hz).dump());
  s.omega = kTwoPi * freq_hz;
  s.zeta = o.number("zeta");
  if (!(s.zeta >= 0.0 && s.zeta < 1.0)) o.fail("zeta", "expected a damping ratio in [0, 1), got " + json(s.zeta).dump());
  s.times = finite_array(o, "times_s");
  s.amplitudes = finite_array(o, "amplitudes");
  if (s.times.front() != 0.0) o.fail("times_s", "expected the first impulse at 0 s, got " + json(s.times.front()).dump());
  for (std::size_t i = 1; i < s.times.size(); ++i)
    if (!(s.times[i] > s.times[i - 1]))
      o.fail("times_s", "expected strictly increasing times, element " + std::to_string(i) + " (" +
                            json(s.times[i]).dump() + ") does not follow " + json(s.times[i - 1]).dump());
  if (s.amplitudes.size() != s.times.size())
    o.fail("amplitudes", "expected " + std::to_string(s.times.size()) + " amplitudes (one per time), got " +
                             std::to_string(s.amplitudes.size()));
  double sum = 0.0;
  for (double a : s.amplitudes) sum += a;
  if (std::abs(sum - 1.0) > 1e-9) o.fail("amplitudes", "expected amplitudes summing to 1 (within 1e-9), sum is " + json(sum).dump());
  if (const auto duration = o.optional_number("duration_s"); duration && std::abs(*duration - s.duration()) > 1e-9)
    o.fail("duration_s", "expected the last impulse time " + json(s.duration()).dump() + ", got " + json(*duration).dump());
  if (o.has("residual_at_design")) (void)o.number("residual_at_design");
  if (o.has("parameters")) {
    (void)o.object("parameters");  // must be an object
    loaded.extras.parameters = document.at("parameters");
  }
  if (const auto ts = o.optional_number("ts")) {
    if (!(*ts > 0.0)) o.fail("ts", "expected a sample period > 0 s, got " + json(*ts).dump());
    loaded.extras.ts = ts;
  }
  if (o.has("robustness")) {
    (void)o.object("robustness");
    loaded.extras.robustness = document.at("robustness");
  }
  if (o.boolean_or("discrete", false)) loaded.extras.discrete = parse_discrete(o, s, loaded.extras.ts);
  return loaded;
}

LoadedShaper load_shaper(const std::string& path) { return parse_shaper_json(read_text_file(path), path); }

}  // namespace servotwin::io
