#pragma once
/// \file
/// Nonlinear mechanics from frequency responses measured at several excitation amplitudes
/// (dissertation C5.10–C5.11): Coulomb friction and backlash quantified through their describing
/// functions, reported beside the fitted linear model.
///
/// Coulomb friction M sign(v) acting where the velocity is measured (or anywhere below the first
/// antiresonance, where the masses move together) has the describing function 4M/(πV) for a
/// velocity sine of amplitude V: an extra viscous damping that fades with amplitude. So at every
/// frequency 1/P_meas(V) = 1/P_lin + 4M/(πV): Re(1/P) is linear in 1/V with slope 4M/π. Points
/// measured at the same frequency with different amplitudes give M by least squares with one
/// intercept per frequency (which absorbs the linear part, viscous friction included).
///
/// Backlash of width D in the shaft is a dead zone on the twist; with the shaft stiffness k its
/// describing function N(A) (C5.10, E11) makes the shaft softer at small twist amplitudes A. At the
/// antiresonance the motor barely moves, so the shaft carries the applied torque T and
/// A = T/k_eff with k_eff = N(A) = Il ω_z,eff². The antiresonance measured at a large and at a
/// small amplitude give k and D (solved jointly: the large amplitude is not free of backlash
/// either).

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/fit.hpp"

namespace servotwin::fit {

/// 4M/(πV): the Coulomb friction's first harmonic over the velocity amplitude V (> 0).
double coulomb_describing_function(double level, double velocity_amplitude);

/// Describing function of a dead zone of total width D (±D/2) in a spring of stiffness k at
/// twist amplitude A: 0 for A ≤ D/2, else (2k/π)(π/2 − γ − (D/2A)√(1 − D²/4A²)), γ = asin(D/2A)
/// (C5.10 with the catalog's fix of γ). Tends to k for A ≫ D.
double dead_zone_describing_function(double stiffness, double width, double amplitude);

/// The width D at which the dead zone's describing function at amplitude A equals
/// `effective_stiffness` (0 < effective_stiffness ≤ stiffness); bisection on the monotonic N.
double dead_zone_width(double stiffness, double effective_stiffness, double amplitude);

/// Coulomb friction from responses at several amplitudes.
struct CoulombFrictionEstimate {
  bool estimated = false;        ///< enough repeated frequencies with different amplitudes
  double level = 0.0;            ///< M, in the input's units (torque, force, current)
  double level_std = 0.0;
  bool significant = false;      ///< level > 3 level_std
  std::size_t frequencies = 0;   ///< frequencies measured at two or more amplitudes
  std::size_t points = 0;
  std::string note;              ///< how it was obtained, or why not
};

/// Backlash from the antiresonance at several amplitudes.
struct BacklashEstimate {
  bool estimated = false;
  double width = 0.0;              ///< D, in the output's angle/length unit (rad for rad/s data)
  double stiffness = 0.0;          ///< k corrected for the backlash seen at the large amplitude
  struct Run {
    double amplitude = 0.0;        ///< excitation amplitude at the antiresonance
    double antiresonance_hz = 0.0;
    double antiresonance_hz_std = 0.0;
    double effective_stiffness = 0.0;  ///< Il ω_z²
    double twist_amplitude = 0.0;      ///< T / k_eff
  };
  std::vector<Run> runs;           ///< by decreasing amplitude
  bool significant = false;        ///< the small-amplitude antiresonance is lower by more than 3 std
  std::string note;
};

struct NonlinearMechanics {
  CoulombFrictionEstimate coulomb;
  BacklashEstimate backlash;
};

/// Coulomb friction from `experiments` (same plant, different amplitudes), using only points below
/// `max_freq_hz` (e.g. half the first antiresonance). `output` says whether the responses are
/// velocity or position over the input (positions are turned into velocities by jω).
CoulombFrictionEstimate estimate_coulomb_friction(std::span<const core::FrequencyResponse> experiments,
                                                  OutputKind output, double max_freq_hz);

/// Backlash from the antiresonance of a two-mass fit of each experiment, with the load inertia of
/// `linear` (the fit of the largest-amplitude experiment, which must have physical parameters).
BacklashEstimate estimate_backlash(const FitReport& linear, std::span<const core::FrequencyResponse> experiments,
                                   const FitOptions& options);

/// Both, for `servotwin fit --amplitude-series`: `experiments` holds every measurement (the one
/// `linear` was fitted to included). Every point is used, including those the measurement marked
/// invalid (FrequencyPoint::valid): their distortion is what the series measures. core::InputError
/// (field `--amplitude-series`) when `linear` is a load-side model (require_motor_side).
NonlinearMechanics analyze_nonlinear_mechanics(const FitReport& linear, std::span<const core::FrequencyResponse> experiments,
                                               const FitOptions& options);

}  // namespace servotwin::fit
