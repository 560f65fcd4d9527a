#pragma once
/// \file
/// Multi-mode input shapers by convolution of single-mode shapers (catalog C6.4, option 2):
/// h12 = Σ_i Σ_j A_i¹ A_j² δ(t − t_i¹ − t_j²). The result cancels every mode each factor cancels
/// (its transform is the product of the factors'), its duration is the sum of the durations and
/// its pulse count at most the product — suboptimal against the direct LP synthesis
/// (lp_shaper.hpp), but needs no solver and keeps each factor's robustness.
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// Convolution of two shapers. Impulses that land within `merge_tolerance` seconds of each other
/// are merged into one (their amplitudes added) so that, e.g., ZV*ZV at one frequency is exactly
/// ZVD. The result has type "multi", omega/zeta of `first`, amplitudes summing to 1. Throws
/// core::InputError when either shaper is empty, has times and amplitudes of different lengths,
/// or amplitudes that do not sum to a positive value.
Shaper convolve_shapers(const Shaper& first, const Shaper& second, double merge_tolerance = 1e-12);

/// Convolution of a non-empty list of shapers, in order (see convolve_shapers). A list of one
/// shaper returns it unchanged.
Shaper convolve_shapers(const std::vector<Shaper>& shapers, double merge_tolerance = 1e-12);

}  // namespace servotwin::shaping
