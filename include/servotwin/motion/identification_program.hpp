#pragma once
/// \file
/// Generator of rapid-identification programs (thesis section 3.4, Table 3.2, and section 4.3.3,
/// Tables 4.3/4.4): random straight moves uniformly distributed within +-range around a centre.

#include <cstdint>
#include <string>
#include <vector>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

/// Which of the thesis's programs to imitate.
enum class IdentificationSet {
  Standard,  ///< Table 3.2: G00 to the centre, then `moves` random G01 moves, back to the centre
  Low,       ///< Table 4.3: very short moves (tens of um) for the low-speed/friction regime
  High       ///< Table 4.4: a full-range sweep each way, random moves, a sweep, back to the centre
};

struct IdentificationOptions {
  std::vector<Axis> axes{Axis::X};  ///< axes moved together (each move draws every axis)
  IdentificationSet set = IdentificationSet::Standard;
  std::size_t moves = 200;          ///< number of random moves
  double range_mm = 10.0;           ///< targets are uniform in [centre - range, centre + range]
  double feed_mm_min = 12000.0;     ///< programmed feed
  Point center{};                   ///< centre of the motion range [mm]
  std::uint64_t seed = 1;           ///< same seed -> same program, on every platform
  std::string name = "RAPIDIDENT";  ///< program name (Heidenhain BEGIN PGM)
  int decimals = 3;                 ///< targets are rounded to this many decimals (1 um)
};

/// Defaults of each set as in the thesis: Standard 200 moves, +-10 mm, F12000 (Table 3.2);
/// Low 200 moves, +-0.03 mm, F15000 (Table 4.3); High 100 moves, +-10 mm, F15000 (Table 4.4).
IdentificationOptions identification_defaults(IdentificationSet set);

/// Builds the program. Throws core::InputError for no axes, zero moves, range <= 0, feed <= 0.
Program make_identification_program(const IdentificationOptions& options);

}  // namespace servotwin::motion
