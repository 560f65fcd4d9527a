#include "servotwin/io/plant_json.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "json_reader.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/program_file.hpp"
#include "servotwin/machine/flexible_frame.hpp"
#include "servotwin/machine/flexible_presets.hpp"

namespace servotwin::io {

namespace {

using detail::JsonObject;
using nlohmann::json;

// ---- reading -------------------------------------------------------------------------------

double positive(const JsonObject& o, std::string_view key) {
  const double v = o.number(key);
  if (!(v > 0.0)) o.fail(key, "expected a number > 0, found " + json(v).dump());
  return v;
}

double non_negative(const JsonObject& o, std::string_view key) {
  const double v = o.number(key);
  if (v < 0.0) o.fail(key, "expected a number >= 0, found " + json(v).dump());
  return v;
}

double non_negative_or(const JsonObject& o, std::string_view key, double fallback) {
  return o.has(key) ? non_negative(o, key) : fallback;
}

enum class Sign { Any, NonNegative, Positive };

// The reader sees the document itself for what JsonObject does not offer (arrays that may be
// empty, a member's JSON type).
struct Source {
  const json& doc;
  const JsonObject& o;
  [[nodiscard]] const json& raw(std::string_view key) const { return doc.at(std::string(key)); }
};

constexpr std::size_t kAnySize = std::numeric_limits<std::size_t>::max();

// An array of finite numbers; `count` = expected size (kAnySize: any non-empty size).
std::vector<double> number_array(const Source& src, std::string_view key, std::size_t count, Sign sign) {
  const JsonObject& o = src.o;
  const json& a = o.array(key);  // present, an array, non-empty
  if (count != kAnySize && a.size() != count)
    o.fail(key, "expected " + std::to_string(count) + " values, found " + std::to_string(a.size()));
  std::vector<double> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string field = std::string(key) + "[" + std::to_string(i) + "]";
    if (!a[i].is_number()) o.fail(field, std::string("expected a number, found ") + a[i].type_name());
    const double v = a[i].get<double>();
    if (!std::isfinite(v)) o.fail(field, "expected a finite number");
    if (sign == Sign::NonNegative && v < 0.0) o.fail(field, "expected a number >= 0, found " + json(v).dump());
    if (sign == Sign::Positive && !(v > 0.0)) o.fail(field, "expected a number > 0, found " + json(v).dump());
    out.push_back(v);
  }
  return out;
}

// Optional per-mass array: absent = empty, else exactly `count` values >= 0.
std::vector<double> optional_array(const Source& src, std::string_view key, std::size_t count) {
  if (!src.o.has(key)) return {};
  return number_array(src, key, count, Sign::NonNegative);
}

machine::KarnoppFriction friction(const JsonObject& o, std::string_view coulomb_key, double coulomb,
                                  std::string_view stiction_key, std::optional<double> stiction, double band) {
  if (stiction && *stiction < coulomb)
    o.fail(stiction_key, "the stiction level " + json(*stiction).dump() + " must not be below the Coulomb level " +
                             std::string(coulomb_key) + " = " + json(coulomb).dump());
  return machine::KarnoppFriction{coulomb, stiction, band};
}

machine::MassChain read_two_mass(const JsonObject& o) {
  machine::MassChain c = machine::two_mass(positive(o, "motor_inertia"), positive(o, "load_inertia"),
                                           positive(o, "stiffness"), non_negative(o, "damping"),
                                           non_negative(o, "motor_viscous"), non_negative(o, "load_viscous"));
  const double band = non_negative_or(o, "stick_band", 0.0);
  const double load_coulomb = non_negative(o, "coulomb");
  std::optional<double> load_stiction;
  if (o.has("stiction")) load_stiction = non_negative(o, "stiction");
  const double motor_coulomb = non_negative_or(o, "motor_coulomb", 0.0);
  std::optional<double> motor_stiction;
  if (o.has("motor_stiction")) motor_stiction = non_negative(o, "motor_stiction");
  c.friction = {friction(o, "motor_coulomb", motor_coulomb, "motor_stiction", motor_stiction, band),
                friction(o, "coulomb", load_coulomb, "stiction", load_stiction, band)};
  c.backlash = {non_negative(o, "backlash")};
  return c;
}

// A single mass has no shafts: its shaft arrays must be absent or empty.
bool no_shafts(const Source& src, std::string_view key) {
  if (!src.o.has(key)) return true;
  const json& v = src.raw(key);
  if (!v.is_array() || !v.empty()) src.o.fail(key, "expected [] (a single mass has no shafts)");
  return true;
}

machine::MassChain read_mass_chain(const Source& src) {
  const JsonObject& o = src.o;
  machine::MassChain c;
  c.inertia = number_array(src, "inertias", kAnySize, Sign::Positive);
  const std::size_t n = c.inertia.size();
  if (n > 64) o.fail("inertias", "at most 64 masses are supported");
  if (n == 1) {
    no_shafts(src, "stiffnesses");
    no_shafts(src, "dampings");
    no_shafts(src, "backlash");
  } else {
    c.stiffness = number_array(src, "stiffnesses", n - 1, Sign::Positive);
    c.damping = number_array(src, "dampings", n - 1, Sign::NonNegative);
    c.backlash = optional_array(src, "backlash", n - 1);
  }
  c.viscous = optional_array(src, "viscous", n);
  const auto coulomb = optional_array(src, "coulomb", n);
  const auto stiction = optional_array(src, "stiction", n);
  std::vector<double> band(n, 0.0);
  if (o.has("stick_band")) {
    if (src.raw("stick_band").is_array()) band = number_array(src, "stick_band", n, Sign::NonNegative);
    else band.assign(n, non_negative(o, "stick_band"));
  }
  if (!coulomb.empty() || !stiction.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      const double tc = coulomb.empty() ? 0.0 : coulomb[i];
      std::optional<double> ts;
      if (!stiction.empty()) ts = stiction[i];
      if (ts && *ts < tc)
        o.fail("stiction[" + std::to_string(i) + "]", "the stiction level must not be below coulomb[" +
                                                          std::to_string(i) + "] = " + json(tc).dump());
      c.friction.push_back(machine::KarnoppFriction{tc, ts, band[i]});
    }
  }
  return c;
}

machine::TransferFunctionModel read_transfer_function(const Source& src) {
  const JsonObject& o = src.o;
  const auto num = number_array(src, "num", kAnySize, Sign::Any);
  const auto den = number_array(src, "den", kAnySize, Sign::Any);
  const core::Polynomial d(den);
  if (d.is_zero()) o.fail("den", "the denominator must not be zero");
  const core::Polynomial n(num);
  if (n.degree() > d.degree())
    o.fail("num", "the transfer function must be proper: numerator degree " + std::to_string(n.degree()) +
                      " exceeds denominator degree " + std::to_string(d.degree()));
  return machine::TransferFunctionModel{core::TransferFunction(n, d)};
}

// The four-mass frame enters as its rotor-velocity transfer function (eq. 7.172; times 1/s for a
// position output): the linear design and the simulation need nothing more, and the file keeps
// the physical parameters a user can read.
machine::FlexibleFrame read_frame(const JsonObject& o) {
  machine::FlexibleFrame f;
  f.frame_mass = positive(o, "frame_mass");
  f.frame_stiffness = positive(o, "frame_stiffness");
  f.frame_damping = non_negative(o, "frame_damping");
  f.stator_mass = positive(o, "stator_mass");
  f.mount_stiffness = positive(o, "mount_stiffness");
  f.mount_damping = non_negative(o, "mount_damping");
  f.rotor_mass = positive(o, "rotor_mass");
  f.coupling_stiffness = positive(o, "coupling_stiffness");
  f.coupling_damping = non_negative(o, "coupling_damping");
  f.load_mass = positive(o, "load_mass");
  return f;
}

machine::TransferFunctionModel frame_model(const JsonObject& o, const machine::FlexibleFrame& f,
                                           machine::PlantOutput output) {
  const core::TransferFunction velocity = machine::flexible_frame_transfer_function(f);
  switch (output) {
    case machine::PlantOutput::MotorVelocity:
      return machine::TransferFunctionModel{velocity};
    case machine::PlantOutput::MotorPosition:
      return machine::TransferFunctionModel{
          core::TransferFunction(velocity.num(), velocity.den() * core::Polynomial{1.0, 0.0})};
    default:
      o.fail("output", "a flexible-frame plant measures the rotor (motor_velocity or motor_position)");
  }
}

machine::PlantSettings read_settings(const Source& src) {
  const JsonObject& o = src.o;
  machine::PlantSettings s;
  s.ts = positive(o, "ts");
  s.noise_std = non_negative(o, "noise_std");
  s.current_lag = non_negative_or(o, "current_lag", 0.0);
  s.quantization = non_negative_or(o, "quantization", 0.0);
  s.delay_samples = o.integer_or("delay_samples", 0);
  if (s.delay_samples < 0) o.fail("delay_samples", "expected a whole number >= 0");
  s.substeps = o.integer_or("substeps", 0);
  if (s.substeps < 0) o.fail("substeps", "expected a whole number >= 0 (0 = automatic)");
  if (o.has("seed")) {
    const json& seed = src.raw("seed");
    if (!seed.is_number_unsigned()) o.fail("seed", "expected a whole number >= 0");
    s.seed = seed.get<std::uint64_t>();
  }
  const std::string output = o.string_or("output", "motor_velocity");
  const auto parsed = machine::plant_output_from_string(output);
  if (!parsed)
    o.fail("output", "expected motor_velocity, motor_position, load_velocity or load_position, found \"" + output + "\"");
  s.output = *parsed;
  return s;
}

constexpr std::array<std::string_view, 12> kCommon = {
    "format", "type", "name", "description", "ts", "noise_std", "output", "current_lag",
    "delay_samples", "quantization", "seed", "substeps"};

// Unknown members are errors (JsonObject::allow_only takes one fixed list; here the list is the
// common fields plus the type's own).
void allow(const Source& src, std::initializer_list<std::string_view> specific) {
  std::vector<std::string_view> all(kCommon.begin(), kCommon.end());
  all.insert(all.end(), specific.begin(), specific.end());
  for (const auto& [key, value] : src.doc.items()) {
    if (std::find(all.begin(), all.end(), key) != all.end()) continue;
    std::string list;
    for (auto k : all) list += (list.empty() ? "" : ", ") + std::string(k);
    src.o.fail(key, "unknown field (expected one of: " + list + ")");
  }
}

// ---- writing -------------------------------------------------------------------------------

json settings_to_json(const machine::PlantSettings& s) {
  return {{"ts", s.ts},
          {"noise_std", s.noise_std},
          {"output", std::string(machine::to_string(s.output))},
          {"current_lag", s.current_lag},
          {"delay_samples", s.delay_samples},
          {"quantization", s.quantization},
          {"seed", s.seed},
          {"substeps", s.substeps}};
}

bool fits_two_mass(const machine::MassChain& c) {
  if (c.masses() != 2) return false;
  const auto m = c.friction_of(0), l = c.friction_of(1);
  // One common stick band (a mass without friction has no band to disagree with).
  return !(m.active() && l.active() && m.stick_band != l.stick_band);
}

json two_mass_to_json(const machine::MassChain& c) {
  const auto m = c.friction_of(0), l = c.friction_of(1);
  json j = {{"type", "two-mass"},
            {"motor_inertia", c.inertia[0]},
            {"load_inertia", c.inertia[1]},
            {"stiffness", c.stiffness[0]},
            {"damping", c.damping_of(0)},
            {"motor_viscous", c.viscous_of(0)},
            {"load_viscous", c.viscous_of(1)},
            {"coulomb", l.coulomb},
            {"backlash", c.backlash_of(0)}};
  if (l.stiction) j["stiction"] = *l.stiction;
  if (m.coulomb > 0.0) j["motor_coulomb"] = m.coulomb;
  if (m.stiction) j["motor_stiction"] = *m.stiction;
  const double band = l.active() ? l.stick_band : m.stick_band;
  if (band > 0.0) j["stick_band"] = band;
  return j;
}

json mass_chain_to_json(const machine::MassChain& c) {
  const std::size_t n = c.masses();
  std::vector<double> damping, viscous, backlash, coulomb, stiction, band;
  for (std::size_t i = 0; i + 1 < n; ++i) damping.push_back(c.damping_of(i)), backlash.push_back(c.backlash_of(i));
  bool any_stiction = false;
  for (std::size_t i = 0; i < n; ++i) {
    const auto f = c.friction_of(i);
    viscous.push_back(c.viscous_of(i));
    coulomb.push_back(f.coulomb);
    stiction.push_back(f.static_level());
    any_stiction = any_stiction || f.stiction.has_value();
    band.push_back(f.stick_band);
  }
  json j = {{"type", "mass-chain"}, {"inertias", c.inertia}, {"stiffnesses", c.stiffness},
            {"dampings", damping},  {"viscous", viscous},    {"backlash", backlash},
            {"coulomb", coulomb},   {"stick_band", band}};
  if (any_stiction) j["stiction"] = stiction;
  return j;
}


/// The member of a `type` plant file that machine::validate's field (the chain's "stiffness[0]")
/// came from, so that a message names what the user wrote.
std::string json_field(const std::string& type, const std::string& field) {
  static const std::vector<std::pair<std::string, std::string>> two_mass{
      {"inertia[0]", "motor_inertia"}, {"inertia[1]", "load_inertia"}, {"stiffness[0]", "stiffness"},
      {"damping[0]", "damping"},       {"viscous[0]", "motor_viscous"}, {"viscous[1]", "load_viscous"},
      {"backlash[0]", "backlash"}};
  if (type == "two-mass") {
    for (const auto& [from, to] : two_mass)
      if (field == from) return to;
    return field;
  }
  static const std::vector<std::pair<std::string, std::string>> chain{
      {"inertia", "inertias"}, {"stiffness", "stiffnesses"}, {"damping", "dampings"}};
  if (type == "mass-chain")
    for (const auto& [from, to] : chain)
      if (field.rfind(from + "[", 0) == 0) return to + field.substr(from.size());
  return field;
}

}  // namespace

machine::PlantConfig parse_plant_json(std::string_view text, std::string_view source_name) {
  json document;
  try {
    document = detail::parse_json_text(text, source_name);
  } catch (const json::exception& e) {
    // parse_json_text converts syntax errors; nlohmann reports a number beyond the double range
    // (e.g. 1e999) as out_of_range instead, which must not escape as a non-input error.
    throw core::InputError({std::string(source_name), 0, 0, ""}, std::string("invalid JSON: ") + e.what());
  }
  check_format(document, kPlantFormat, source_name);
  const JsonObject root(document, "", source_name);
  const Source src{document, root};
  machine::PlantConfig plant;
  const std::string type = root.string("type");
  if (type == "two-mass") {
    allow(src, {"motor_inertia", "load_inertia", "stiffness", "damping", "motor_viscous", "load_viscous", "coulomb",
                 "stiction", "motor_coulomb", "motor_stiction", "stick_band", "backlash"});
    plant.model = read_two_mass(root);
  } else if (type == "mass-chain") {
    allow(src, {"inertias", "stiffnesses", "dampings", "viscous", "coulomb", "stiction", "stick_band", "backlash"});
    plant.model = read_mass_chain(src);
  } else if (type == "transfer-function") {
    allow(src, {"num", "den"});
    plant.model = read_transfer_function(src);
  } else if (type == "flexible-frame") {
    allow(src, {"frame_mass", "frame_stiffness", "frame_damping", "stator_mass", "mount_stiffness", "mount_damping",
                 "rotor_mass", "coupling_stiffness", "coupling_damping", "load_mass"});
  } else {
    root.fail("type", "unknown plant type \"" + type +
                          "\" (expected two-mass, mass-chain, transfer-function or flexible-frame)");
  }
  plant.settings = read_settings(src);
  if (type == "flexible-frame") {
    plant.frame = read_frame(root);
    plant.model = frame_model(root, *plant.frame, plant.settings.output);
  }
  plant.name = root.string_or("name", std::filesystem::path(std::string(source_name)).stem().string());
  plant.description = root.string_or("description", "");
  try {
    machine::validate(plant);
  } catch (const core::InputError& e) {
    throw core::InputError({std::string(source_name), 0, 0, json_field(type, e.where().field)}, e.reason());
  }
  return plant;
}

machine::PlantConfig load_plant(const std::string& name_or_path) {
  for (const auto& name : machine::flexible_preset_names())
    if (name == name_or_path) return machine::flexible_preset(name);
  std::error_code ec;
  if (!std::filesystem::exists(name_or_path, ec)) {
    std::string names;
    for (const auto& n : machine::flexible_preset_names()) names += (names.empty() ? "" : ", ") + n;
    throw core::InputError({name_or_path, 0, 0, "--plant"}, "no such plant preset or file (presets: " + names + ")");
  }
  return parse_plant_json(read_text_file(name_or_path), name_or_path);
}

json plant_to_json(const machine::PlantConfig& plant) {
  machine::validate(plant);
  json j;
  if (plant.frame) {
    const machine::FlexibleFrame& f = *plant.frame;
    j = {{"type", "flexible-frame"},         {"frame_mass", f.frame_mass},
         {"frame_stiffness", f.frame_stiffness}, {"frame_damping", f.frame_damping},
         {"stator_mass", f.stator_mass},       {"mount_stiffness", f.mount_stiffness},
         {"mount_damping", f.mount_damping},   {"rotor_mass", f.rotor_mass},
         {"coupling_stiffness", f.coupling_stiffness}, {"coupling_damping", f.coupling_damping},
         {"load_mass", f.load_mass}};
  } else if (const auto* chain = std::get_if<machine::MassChain>(&plant.model)) {
    j = fits_two_mass(*chain) ? two_mass_to_json(*chain) : mass_chain_to_json(*chain);
  } else {
    const auto& tf = std::get<machine::TransferFunctionModel>(plant.model).tf;
    const auto coefficients = [](const core::Polynomial& p) {
      return std::vector<double>(p.coefficients().begin(), p.coefficients().end());
    };
    j = {{"type", "transfer-function"}, {"num", coefficients(tf.num())}, {"den", coefficients(tf.den())}};
  }
  j["format"] = kPlantFormat;
  j["name"] = plant.name;
  j["description"] = plant.description;
  j.update(settings_to_json(plant.settings));
  return j;
}

}  // namespace servotwin::io
