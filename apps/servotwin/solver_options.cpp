#include "solver_options.hpp"

#include <map>
#include <numbers>

namespace servotwin::cli {

void add_solver_options(CLI::App& command, SolverInput& input) {
  const std::map<std::string, rapid::Method> methods{
      {"exact", rapid::Method::Exact}, {"ga", rapid::Method::Ga}, {"ls", rapid::Method::Ls}};
  command.add_option("--method", input.method,
                     "exact: global optimum under the pole bounds; ga: the thesis's genetic algorithm; ls: unconstrained")
      ->transform(choice_of(methods))
      ->capture_default_str();
  command.add_option("--p-min-hz", input.p_min_hz, "Lower bound of the real pole p [Hz] (default 0.2)");
  command.add_option("--p-max-hz", input.p_max_hz, "Upper bound of p [Hz] (default: Nyquist)");
  command.add_option("--wn-min-hz", input.wn_min_hz, "Lower bound of the natural frequency wn [Hz] (default 0.2)");
  command.add_option("--wn-max-hz", input.wn_max_hz, "Upper bound of wn [Hz] (default: Nyquist)");
  command.add_option("--zeta-min", input.zeta_min, "Lower bound of the damping ratio")->capture_default_str();
  command.add_option("--zeta-max", input.zeta_max, "Upper bound of the damping ratio (> 1: two real poles)")
      ->capture_default_str();
  command.add_option("--seed", input.seed, "Seed of the genetic algorithm")->capture_default_str();
  command.add_option("--generations", input.generations, "Generations of the genetic algorithm")->capture_default_str();
  command.add_option("--population", input.population, "Population of the genetic algorithm")->capture_default_str();
}

void apply_solver_input(const SolverInput& input, vcnc::IdentificationSettings& settings) {
  settings.method = input.method;
  settings.bounds.p_min = kTwoPi * input.p_min_hz;
  settings.bounds.p_max = kTwoPi * input.p_max_hz;
  settings.bounds.wn_min = kTwoPi * input.wn_min_hz;
  settings.bounds.wn_max = kTwoPi * input.wn_max_hz;
  settings.bounds.zeta_min = input.zeta_min;
  settings.bounds.zeta_max = input.zeta_max;
  settings.solve.ga.seed = input.seed;
  settings.solve.ga.generations = input.generations;
  settings.solve.ga.population = input.population;
}

}  // namespace servotwin::cli
