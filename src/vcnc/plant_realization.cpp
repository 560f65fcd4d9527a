#include "servotwin/vcnc/plant_realization.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "servotwin/core/error.hpp"

namespace servotwin::vcnc {

namespace {

machine::MassChain two_mass_chain(const fit::PlantModel& m) {
  if (m.modes.size() != 1)
    throw core::InputError(core::at_field("model"), fmt::format("a two-mass plant needs one flexible mode; the model "
                                                                "has {}",
                                                                m.modes.size()));
  fit::require_motor_side(m, "the two-mass realization", "model");
  const fit::Mode& mode = m.modes.front();
  const double wz = mode.antiresonance.omega_rad_s, wn = mode.resonance.omega_rad_s;
  if (!(m.gain > 0.0) || !(wn > wz))
    throw core::InputError(core::at_field("model"),
                           fmt::format("not a two-mass plant: gain {} and resonance {:.4g} Hz over antiresonance "
                                       "{:.4g} Hz (a two-mass motor-side response has K > 0 and the antiresonance "
                                       "first)",
                                       m.gain, wn / (2.0 * std::numbers::pi), wz / (2.0 * std::numbers::pi)));
  // With the lag L = 1/(s + τ2) the high-frequency gain of the mechanics is K/τ2.
  const double im = m.lag_pole_rad_s.value_or(1.0) / m.gain;
  const double r = wn / wz;
  const double il = im * (r * r - 1.0);
  const double viscous = m.rigid == fit::RigidKind::kRealPole ? m.rigid_pole_rad_s * (im + il) : 0.0;
  return machine::two_mass(im, il, il * wz * wz, 2.0 * mode.antiresonance.zeta * wz * il, viscous, 0.0);
}

}  // namespace

machine::PlantConfig realize_plant_model(const fit::PlantModel& model, Realization realization, double ts) {
  if (!(std::isfinite(ts) && ts > 0.0))
    throw core::InputError(core::at_field("ts"), fmt::format("expected a sample period > 0 s, got {}", ts));
  machine::PlantConfig config;
  config.settings.ts = ts;
  // A load-side model's output is the load's: a motor-feedback loop must not close on it
  // (drive simulation refuses that pairing by the output kind).
  const bool position = model.output == fit::OutputKind::kPosition;
  const bool load = model.sensor == fit::SensorSide::kLoad;
  config.settings.output = position ? (load ? machine::PlantOutput::LoadPosition : machine::PlantOutput::MotorPosition)
                                    : (load ? machine::PlantOutput::LoadVelocity : machine::PlantOutput::MotorVelocity);
  if (model.delay_s) {
    // A response measured on a sampled drive carries the zero-order hold's half-sample delay in the
    // fitted delay; the simulation holds its input too, so that half sample is not added twice.
    const double samples = std::max(0.0, std::round(*model.delay_s / ts - 0.5));
    if (samples > 100000.0)
      throw core::InputError(core::at_field("ts"), fmt::format("the fitted delay {} s is {} samples of {} s; at most "
                                                               "100000",
                                                               *model.delay_s, samples, ts));
    config.settings.delay_samples = static_cast<int>(samples);
  }
  if (realization == Realization::kTwoMass) {
    config.model = two_mass_chain(model);
    if (model.lag_pole_rad_s) config.settings.current_lag = 1.0 / *model.lag_pole_rad_s;
    config.description = "two-mass realization of a fitted plant model";
  } else {
    config.model = machine::TransferFunctionModel{model.transfer_function()};
    config.description = model.sensor == fit::SensorSide::kLoad
                             ? "transfer-function realization of a load-side fitted plant model (its output is the load's)"
                             : "transfer-function realization of a fitted plant model";
  }
  machine::validate(config);
  return config;
}

}  // namespace servotwin::vcnc
