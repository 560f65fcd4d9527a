// Prints the equivalent closed loop of the fadal-pid preset's X axis using the installed library.
#include <cstdio>

#include <servotwin/machine/closed_loop.hpp>
#include <servotwin/machine/presets.hpp>
#include <servotwin/motion/identification_program.hpp>
#include <servotwin/motion/interpolation.hpp>
#include <servotwin/version.hpp>

int main() {
  using namespace servotwin;
  const auto machine = machine::preset("fadal-pid");
  const auto loop = machine::equivalent_closed_loop(machine.axes.front(), machine.ts);
  const auto program = motion::make_identification_program(motion::identification_defaults(motion::IdentificationSet::Standard));
  const auto trajectory = motion::interpolate(program, motion::InterpolationLimits{});
  std::printf("servotwin %s: closed-loop a2 = %.2f, identification program: %zu samples\n", kVersion, loop.coefficients.a2,
              trajectory.size());
  return trajectory.size() > 0 ? 0 : 1;
}
