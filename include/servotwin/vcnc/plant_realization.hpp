#pragma once
/// \file
/// A simulated plant from a fitted plant model (issue 25 §7), so that measure → fit → tune →
/// simulate works on files: `simulate` runs a controller on the plant the fit found.
///
/// Two realizations:
/// * transfer function: P(s) as fitted (rigid mode, modes, lag and output integrator; the delay
///   as whole samples, less the half sample of the zero-order hold that the simulation adds
///   itself), exact in the frequency domain; one output, the measured one;
/// * two-mass: the chain of C3.12 from K, the antiresonance and the resonance ratio (Im = 1/K,
///   or τ2/K with a lag L = 1/(s + τ2), which becomes the current lag 1/(τ2 s + 1); Il = Im(r² − 1),
///   k = Il ωz², b = 2 ζz ωz Il, the rigid pole a as motor viscous friction a·(Im + Il), which
///   leaves the antiresonance as fitted); it has the load side a load-side controller needs, and
///   reproduces the fitted resonance damping only when the model's damping consistency
///   ζp/(r ζz) is 1.
/// A fitted model is linear: its simulation has no friction, backlash or noise.

#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_plant.hpp"

namespace servotwin::vcnc {

/// Which simulated plant a fitted model becomes.
enum class Realization { kTransferFunction, kTwoMass };

/// The plant at sample period ts. Throws core::InputError naming "ts" (not > 0, or a delay
/// beyond 100 000 samples) or "model" (kTwoMass for a model that is not one mode with K > 0 and
/// the resonance above the antiresonance, naming which).
machine::PlantConfig realize_plant_model(const fit::PlantModel& model, Realization realization, double ts);

}  // namespace servotwin::vcnc
