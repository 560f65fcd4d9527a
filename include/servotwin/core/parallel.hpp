#pragma once
// Splitting independent work over the machine's cores.
//
// Long traces are worked sample by sample with no dependence between samples (contour errors) or
// axis by axis (simulations, identifications): such work is cut into contiguous parts, one per
// worker, so that the result is the same, bit for bit, for any number of workers.

#include <cstddef>
#include <functional>

namespace servotwin::core {

/// Number of workers for `requested`: 0 means every core this process may run on (its CPU
/// affinity on Linux, else what the machine reports; at least 1).
[[nodiscard]] std::size_t worker_count(std::size_t requested) noexcept;

/// Calls body(begin, end) on contiguous parts covering [0, n): at most worker_count(workers)
/// parts, none shorter than `min_part` (short work stays on the calling thread). The first part
/// runs on the calling thread, and so does any part no thread could be started for. When parts
/// throw, the first part's exception (in index order) is rethrown after every part has finished.
void parallel_parts(std::size_t n, std::size_t workers, std::size_t min_part,
                    const std::function<void(std::size_t begin, std::size_t end)>& body);

}  // namespace servotwin::core
