#pragma once
// Interfaces between the solver's source files (not installed).

#include <cstdint>
#include <string>
#include <vector>

#include "servotwin/rapid/solver.hpp"
#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid::detail {

/// Outcome of the exact branch and bound (search variables only; solver.cpp builds the Solution).
struct ExactResult {
  double p = 0.0, wn = 0.0, zeta = 0.0;
  double excess = 0.0;        ///< g at the returned point
  double lower_excess = 0.0;  ///< certified lower bound on g over the bounds
  bool certified = false;
  std::uint64_t boxes = 0;
  std::vector<std::string> warnings;
};
ExactResult exact_search(const ReducedProblem& reduced, const Bounds& bounds, const SolveOptions& options);

/// Outcome of the genetic algorithm.
struct GaResult {
  double p = 0.0, wn = 0.0, zeta = 0.0;
  std::vector<GaGeneration> history;
};
GaResult genetic_search(const ReducedProblem& reduced, const Bounds& bounds, const GaOptions& options);

}  // namespace servotwin::rapid::detail
