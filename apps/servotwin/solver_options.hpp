#pragma once
// Options shared by `identify` and `solve`: method, bounds in Hz, genetic-algorithm settings.

#include "command.hpp"
#include "servotwin/vcnc/identification.hpp"

namespace servotwin::cli {

struct SolverInput {
  rapid::Method method = rapid::Method::Exact;
  double p_min_hz = 0.0, p_max_hz = 0.0, wn_min_hz = 0.0, wn_max_hz = 0.0;
  double zeta_min = 0.2, zeta_max = 2.0;
  std::uint64_t seed = 1;
  std::size_t generations = 500, population = 4000;
};

/// Adds --method, --p-min-hz ... --zeta-max, --seed, --generations, --population.
void add_solver_options(CLI::App& command, SolverInput& input);
/// Bounds (Hz -> rad/s; zeros are filled from ts later) and solver options.
void apply_solver_input(const SolverInput& input, vcnc::IdentificationSettings& settings);

}  // namespace servotwin::cli
