#pragma once
// Reserving the long columns of a trace (hundreds of thousands of samples and more).
//
// Filling a freshly reserved column costs one page fault per 4 KiB page the first time each page
// is written; on a virtual machine a fault costs microseconds, and for the ten-minute prediction
// (fifteen columns of 4.8 MB) the faults were a third of the command's time. Asking the kernel
// for transparent huge pages on the column (madvise MADV_HUGEPAGE, where Linux offers it) makes
// one fault fill 2 MiB instead. Only the advice differs: the contents and every result are the
// same, and where the advice is not available nothing changes; the resident size may grow in
// 2 MiB steps (a column's unused capacity up to its next huge page). The advice stays on the
// address range after the column is freed, for whatever the allocator puts there next.

#include <cstddef>
#include <vector>

namespace servotwin::core {

/// Columns shorter than this many bytes are reserved plainly (a huge page is 2 MiB).
inline constexpr std::size_t kLargeBufferBytes = std::size_t{4} << 20;

/// Advises the kernel to back [data, data + bytes) with huge pages where whole 2 MiB pages fit.
void advise_huge_pages(void* data, std::size_t bytes) noexcept;

/// v.reserve(n), with the huge-page advice for a long column.
template <typename T>
void reserve_large(std::vector<T>& v, std::size_t n) {
  const bool grows = n > v.capacity();
  v.reserve(n);
  if (grows && n * sizeof(T) >= kLargeBufferBytes) advise_huge_pages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace servotwin::core
