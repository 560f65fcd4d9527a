#include "tune_input.hpp"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <variant>

#include "servotwin/core/error.hpp"
#include "servotwin/io/plant_json.hpp"
#include "servotwin/io/plant_model_json.hpp"
#include "servotwin/machine/flexible_plant.hpp"

namespace servotwin::cli {

namespace {

/// Motor velocity per torque of a plant description (the chain's, or a given TF's).
core::TransferFunction velocity_tf(const machine::PlantConfig& config, const std::string& source) {
  if (const auto* chain = std::get_if<machine::MassChain>(&config.model)) {
    return machine::mass_chain_transfer_function(*chain, machine::PlantOutput::MotorVelocity);
  }
  const core::TransferFunction& tf = std::get<machine::TransferFunctionModel>(config.model).tf;
  switch (config.settings.output) {
    case machine::PlantOutput::MotorVelocity:
      return tf;
    case machine::PlantOutput::MotorPosition: {
      // Position = velocity/s: the velocity function is the TF times s, i.e. the den's root at 0 removed.
      const std::span<const double> d = tf.den().coefficients();
      if (d.empty() || d.back() != 0.0) {
        throw core::InputError({source, 0, 0, "den"}, "a motor-position TF must have a pole at s = 0 (the integrator)");
      }
      return {tf.num(), core::Polynomial(std::vector<double>(d.begin(), d.end() - 1))};
    }
    default:
      throw core::InputError({source, 0, 0, "settings.output"},
                             "the tuner needs the motor-side (collocated) response; this TF is a load-side output");
  }
}

TunePlant from_description(const machine::PlantConfig& config, const std::string& source) {
  TunePlant p;
  try {
    p.model = fit::plant_model_from_transfer_function(velocity_tf(config, source), "model");
  } catch (const core::InputError& e) {
    throw core::InputError({source, 0, 0, e.where().field}, e.reason());
  }
  const machine::PlantSettings& s = config.settings;
  if (s.current_lag > 0.0) p.hf.current_lag_s = s.current_lag;
  // The drive holds each command for a sample: on average half a sample of delay, on top of the
  // configured transport delay.
  p.hf.delay_s = (static_cast<double>(s.delay_samples) + 0.5) * s.ts;
  p.ts = s.ts;
  p.description = config;
  if (const auto* chain = std::get_if<machine::MassChain>(&config.model)) {
    bool friction = false, backlash = false;
    for (std::size_t i = 0; i < chain->masses(); ++i) friction = friction || chain->friction_of(i).active();
    for (std::size_t i = 0; i + 1 < chain->masses(); ++i) backlash = backlash || chain->backlash_of(i) > 0.0;
    if (friction) p.notes.push_back("Coulomb/stiction friction of the description is not in the linear design (integral action removes its steady-state error)");
    if (backlash) p.notes.push_back("backlash of the description is not in the linear design: expect a limit cycle in the loop with it");
  }
  return p;
}

}  // namespace

TunePlant load_tune_plant(const std::string& name_or_path) {
  if (io::is_plant_model_file(name_or_path)) {
    TunePlant p;
    p.model = io::load_plant_model(name_or_path).model;
    p.fitted = true;
    try {
      fit::require_motor_side(p.model, "controller tuning (C7)", "model.sensor");
    } catch (const core::InputError& e) {
      throw core::InputError({name_or_path, 0, 0, e.where().field}, e.reason());
    }
    return p;
  }
  return from_description(io::load_plant(name_or_path), name_or_path);
}

std::optional<double> parse_auto(const std::string& text, const char* flag, bool zero_ok, const char* what) {
  if (text == "auto") return std::nullopt;
  const std::optional<double> v = parse_number(text);
  if (!v || *v < 0.0 || (!zero_ok && *v == 0.0)) {
    throw core::InputError(core::at_field(flag), fmt::format("expected \"auto\" or {}, got \"{}\"", what, text));
  }
  return v;
}

std::optional<double> parse_number(const std::string& text) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

core::Polynomial parse_coefficients(const std::string& text, const std::string& option) {
  std::string cleaned = text;
  for (char& ch : cleaned) {
    if (ch == ',') ch = ' ';
  }
  std::istringstream in(cleaned);
  std::vector<double> c;
  std::string token;
  while (in >> token) {
    const std::optional<double> v = parse_number(token);
    if (!v) {
      throw core::InputError(core::at_field(option),
                             fmt::format("expected coefficients in descending powers of s (e.g. \"2.6,0\"), got \"{}\"", token));
    }
    c.push_back(*v);
  }
  const core::Polynomial p(c);
  if (p.is_zero()) throw core::InputError(core::at_field(option), "expected at least one non-zero coefficient");
  return p;
}

}  // namespace servotwin::cli
