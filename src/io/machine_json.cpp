#include "servotwin/io/machine_json.hpp"

#include <cmath>
#include <filesystem>

#include "json_reader.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/program_file.hpp"
#include "servotwin/machine/presets.hpp"

namespace servotwin::io {

namespace {

using detail::JsonObject;
using nlohmann::json;

// ---- reading -------------------------------------------------------------------------------

machine::RigidPlant read_plant(const JsonObject& o) {
  o.allow_only({"inertia", "damping", "gain"});
  return {o.number("inertia"), o.number_or("damping", 0.0), o.number("gain")};
}

machine::Controller read_controller(const JsonObject& o) {
  const std::string type = o.string("type");
  if (type == "p-pi") {
    o.allow_only({"type", "kp", "kv", "ki", "vel_ff", "acc_ff"});
    return machine::PPiController{o.number("kp"), o.number("kv"), o.number("ki"), o.number_or("vel_ff", 0.0),
                                  o.number_or("acc_ff", 0.0)};
  }
  if (type == "pid") {
    o.allow_only({"type", "kp", "ki", "kd", "vel_ff", "acc_ff"});
    return machine::PidController{o.number("kp"), o.number("ki"), o.number("kd"), o.number_or("vel_ff", 0.0),
                                  o.number_or("acc_ff", 0.0)};
  }
  if (type == "sliding-mode") {
    o.allow_only({"type", "lambda", "ks", "rho", "model_inertia", "model_damping", "model_gain"});
    machine::SlidingModeController c;
    c.lambda = o.number("lambda");
    c.ks = o.number("ks");
    c.rho = o.number("rho");
    c.model_inertia = o.optional_number("model_inertia");
    c.model_damping = o.optional_number("model_damping");
    c.model_gain = o.optional_number("model_gain");
    return c;
  }
  if (type == "pole-placement") {
    o.allow_only({"type", "wn_hz", "zeta", "zpetc", "kalman_process_noise", "kalman_measurement_noise"});
    machine::PolePlacementController c;
    c.wn_hz = o.number("wn_hz");
    c.zeta = o.number("zeta");
    c.zpetc = o.boolean_or("zpetc", true);
    c.kalman_process_noise = o.number_or("kalman_process_noise", c.kalman_process_noise);
    c.kalman_measurement_noise = o.number_or("kalman_measurement_noise", c.kalman_measurement_noise);
    return c;
  }
  o.fail("type", "unknown controller type '" + type + "' (expected p-pi, pid, sliding-mode or pole-placement)");
}

void read_nonlinearities(const JsonObject& axis, machine::Nonlinearities& n) {
  if (auto f = axis.optional_object("friction")) {
    f->allow_only({"coulomb_pos", "coulomb_neg", "static_pos", "static_neg"});
    n.friction.coulomb_pos = f->number_or("coulomb_pos", 0.0);
    n.friction.coulomb_neg = f->number_or("coulomb_neg", 0.0);
    n.friction.static_pos = f->optional_number("static_pos");
    n.friction.static_neg = f->optional_number("static_neg");
  }
  if (auto b = axis.optional_object("backlash")) {
    b->allow_only({"width", "feedback"});
    n.backlash.width = b->number_or("width", 0.0);
    const std::string feedback = b->string_or("feedback", "motor");
    if (feedback == "motor") n.backlash.feedback = machine::Feedback::Motor;
    else if (feedback == "table") n.backlash.feedback = machine::Feedback::Table;
    else b->fail("feedback", "expected \"motor\" or \"table\", found \"" + feedback + "\"");
  }
  if (auto s = axis.optional_object("saturation")) {
    s->allow_only({"u_max"});
    n.u_max = s->optional_number("u_max").value_or(n.u_max);
  }
  if (auto d = axis.optional_object("dac")) {
    d->allow_only({"bits", "range"});
    n.dac_bits = d->integer_or("bits", 0);
    n.dac_range = d->number_or("range", n.dac_range);
  }
  if (auto e = axis.optional_object("encoder")) {
    e->allow_only({"resolution", "noise_std"});
    n.encoder_resolution = e->number_or("resolution", 0.0);
    n.encoder_noise_std = e->number_or("noise_std", 0.0);
  }
  n.delay_samples = axis.integer_or("delay_samples", 0);
}

machine::AxisConfig read_axis(const JsonObject& o) {
  o.allow_only({"name", "home", "plant", "controller", "friction", "backlash", "saturation", "dac", "encoder",
                "delay_samples"});
  machine::AxisConfig axis;
  axis.name = o.string("name");
  axis.home = o.number_or("home", 0.0);
  axis.plant = read_plant(o.object("plant"));
  axis.controller = read_controller(o.object("controller"));
  read_nonlinearities(o, axis.nonlinear);
  return axis;
}

machine::CncSettings read_cnc(const JsonObject& o) {
  o.allow_only({"accel", "jerk", "rapid_feed_mm_min", "corner_angle_deg", "exact_stop_every_block"});
  machine::CncSettings cnc;
  cnc.accel = o.number_or("accel", cnc.accel);
  cnc.jerk = o.optional_number("jerk");
  cnc.rapid_feed_mm_min = o.number_or("rapid_feed_mm_min", cnc.rapid_feed_mm_min);
  cnc.corner_angle_deg = o.number_or("corner_angle_deg", cnc.corner_angle_deg);
  cnc.exact_stop_every_block = o.boolean_or("exact_stop_every_block", cnc.exact_stop_every_block);
  return cnc;
}

// ---- writing -------------------------------------------------------------------------------

json optional_to_json(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json controller_to_json(const machine::Controller& controller) {
  return std::visit(
      [](const auto& c) -> json {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, machine::PPiController>) {
          return {{"type", "p-pi"}, {"kp", c.kp}, {"kv", c.kv}, {"ki", c.ki}, {"vel_ff", c.vel_ff}, {"acc_ff", c.acc_ff}};
        } else if constexpr (std::is_same_v<T, machine::PidController>) {
          return {{"type", "pid"}, {"kp", c.kp}, {"ki", c.ki}, {"kd", c.kd}, {"vel_ff", c.vel_ff}, {"acc_ff", c.acc_ff}};
        } else if constexpr (std::is_same_v<T, machine::SlidingModeController>) {
          json j = {{"type", "sliding-mode"}, {"lambda", c.lambda}, {"ks", c.ks}, {"rho", c.rho}};
          if (c.model_inertia) j["model_inertia"] = *c.model_inertia;
          if (c.model_damping) j["model_damping"] = *c.model_damping;
          if (c.model_gain) j["model_gain"] = *c.model_gain;
          return j;
        } else {
          return {{"type", "pole-placement"},
                  {"wn_hz", c.wn_hz},
                  {"zeta", c.zeta},
                  {"zpetc", c.zpetc},
                  {"kalman_process_noise", c.kalman_process_noise},
                  {"kalman_measurement_noise", c.kalman_measurement_noise}};
        }
      },
      controller);
}

json axis_to_json(const machine::AxisConfig& a) {
  const auto& n = a.nonlinear;
  json j = {{"name", a.name},
            {"home", a.home},
            {"plant", {{"inertia", a.plant.inertia}, {"damping", a.plant.damping}, {"gain", a.plant.gain}}},
            {"controller", controller_to_json(a.controller)},
            {"friction",
             {{"coulomb_pos", n.friction.coulomb_pos},
              {"coulomb_neg", n.friction.coulomb_neg},
              {"static_pos", optional_to_json(n.friction.static_pos)},
              {"static_neg", optional_to_json(n.friction.static_neg)}}},
            {"backlash",
             {{"width", n.backlash.width}, {"feedback", n.backlash.feedback == machine::Feedback::Motor ? "motor" : "table"}}},
            {"saturation", {{"u_max", std::isfinite(n.u_max) ? json(n.u_max) : json(nullptr)}}},
            {"dac", {{"bits", n.dac_bits}, {"range", n.dac_range}}},
            {"encoder", {{"resolution", n.encoder_resolution}, {"noise_std", n.encoder_noise_std}}},
            {"delay_samples", n.delay_samples}};
  return j;
}

json modal_to_json(const core::ModalInfo& m) {
  return {{"hz", std::isfinite(m.freq_hz) ? json(m.freq_hz) : json(nullptr)},
          {"zeta", m.zeta},
          {"re", m.root.real()},
          {"im", m.root.imag()}};
}

json z_root_to_json(std::complex<double> z, double ts) {
  json j = modal_to_json(core::modal_info_discrete(z, ts));
  j["z_re"] = z.real();
  j["z_im"] = z.imag();
  return j;
}

}  // namespace

void check_format(const json& document, std::string_view expected, std::string_view source_name) {
  const std::string source(source_name);
  if (!document.is_object()) throw core::InputError({source, 0, 0, ""}, "expected a JSON object");
  const auto it = document.find("format");
  if (it == document.end() || !it->is_string())
    throw core::InputError({source, 0, 0, "format"}, "missing \"format\": expected \"" + std::string(expected) + "\"");
  const std::string format = it->get<std::string>();
  const auto family = [](std::string_view f) { return f.substr(0, f.find('/')); };
  if (family(format) != family(expected))
    throw core::InputError({source, 0, 0, "format"},
                           "this is a \"" + format + "\" file, expected \"" + std::string(expected) + "\"");
  const auto major = [](std::string_view f) {
    const auto slash = f.find('/');
    const auto dot = f.find('.', slash);
    return slash == std::string_view::npos ? std::string_view() : f.substr(slash + 1, dot - slash - 1);
  };
  if (major(format) != major(expected))
    throw core::InputError({source, 0, 0, "format"}, "unsupported version \"" + format + "\"; this servotwin reads \"" +
                                                         std::string(expected) + "\"");
}

machine::MachineConfig parse_machine_json(std::string_view text, std::string_view source_name) {
  const json document = detail::parse_json_text(text, source_name);
  check_format(document, kMachineFormat, source_name);
  const JsonObject root(document, "", source_name);
  root.allow_only({"format", "name", "description", "ts", "cnc", "axes"});
  machine::MachineConfig m;
  m.name = root.string_or("name", std::filesystem::path(std::string(source_name)).stem().string());
  m.description = root.string_or("description", "");
  m.ts = root.number("ts");
  if (auto cnc = root.optional_object("cnc")) m.cnc = read_cnc(*cnc);
  const json& axes = root.array("axes");
  for (std::size_t i = 0; i < axes.size(); ++i)
    m.axes.push_back(read_axis(JsonObject(axes[i], "axes[" + std::to_string(i) + "]", source_name)));
  try {
    machine::validate(m);
  } catch (const core::InputError& e) {
    throw core::InputError({std::string(source_name), 0, 0, e.where().field}, e.reason());
  }
  return m;
}

machine::MachineConfig load_machine(const std::string& name_or_path) {
  for (const auto& name : machine::preset_names())
    if (name == name_or_path) return machine::preset(name);
  std::error_code ec;
  if (!std::filesystem::exists(name_or_path, ec)) {
    std::string names;
    for (const auto& n : machine::preset_names()) names += (names.empty() ? "" : ", ") + n;
    throw core::InputError({name_or_path, 0, 0, "--machine"},
                           "no such preset or file (presets: " + names + ")");
  }
  return parse_machine_json(read_text_file(name_or_path), name_or_path);
}

json machine_to_json(const machine::MachineConfig& m) {
  json axes = json::array();
  for (const auto& a : m.axes) axes.push_back(axis_to_json(a));
  return {{"format", kMachineFormat},
          {"name", m.name},
          {"description", m.description},
          {"ts", m.ts},
          {"cnc",
           {{"accel", m.cnc.accel},
            {"jerk", optional_to_json(m.cnc.jerk)},
            {"rapid_feed_mm_min", m.cnc.rapid_feed_mm_min},
            {"corner_angle_deg", m.cnc.corner_angle_deg},
            {"exact_stop_every_block", m.cnc.exact_stop_every_block}}},
          {"axes", axes}};
}

json closed_loop_report(const machine::MachineConfig& m) {
  json axes = json::array();
  for (const auto& axis : m.axes) {
    const auto loop = machine::equivalent_closed_loop(axis, m.ts);
    const auto& c = loop.coefficients;
    json poles = json::array(), zeros = json::array(), zpoles = json::array(), zzeros = json::array();
    for (const auto& p : loop.poles) poles.push_back(modal_to_json(p));
    for (const auto& z : loop.zeros) zeros.push_back(modal_to_json(z));
    for (const auto& p : loop.discrete_poles) zpoles.push_back(z_root_to_json(p, m.ts));
    for (const auto& z : loop.discrete_zeros) zzeros.push_back(z_root_to_json(z, m.ts));
    axes.push_back({{"name", axis.name},
                    {"controller", controller_to_json(axis.controller)["type"]},
                    {"closed_loop",
                     {{"a1", c.a1}, {"a2", c.a2}, {"a3", c.a3}, {"b0", c.b0}, {"b1", c.b1}, {"b2", c.b2}, {"d0", c.d0},
                      {"d1", c.d1}}},
                    {"exact", loop.exact},
                    {"method", loop.method},
                    {"poles", poles},
                    {"zeros", zeros},
                    {"discrete", {{"ts", m.ts}, {"poles", zpoles}, {"zeros", zzeros}}}});
  }
  return {{"format", "servotwin.closed-loop/1"}, {"machine", m.name}, {"ts", m.ts}, {"axes", axes}};
}

}  // namespace servotwin::io
