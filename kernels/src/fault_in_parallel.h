// Faults in fresh memory on all threads at once, one huge page per task,
// before a parallel pass fills it (private to kernels/src).
//
// Why: the first touch of a huge page (raybench/bvh/huge_pages.h) makes the
// kernel zero all 2 MiB of it, while any other thread touching the same
// page waits. A parallel fill starts its second thread half-way through the
// array, often in the first thread's page, so the faults ran one after the
// other (measured: docs/notes/kernels-builders.md).
#pragma once

#include <algorithm>
#include <cstddef>
#include <span>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/huge_pages.h"

namespace raybench::bvh2_build {

// Writes a zero byte into every 4 KiB page of `elements`, which are about to
// be overwritten: the pages of one huge page in one task. Arrays smaller
// than a huge page are left alone (they come from operator new, and fault
// page by page wherever they are filled).
template <typename T>
void fault_in_parallel(std::span<T> elements) {
  static_assert(std::is_trivially_copyable_v<T>, "the zero bytes written must not matter");
  constexpr std::size_t kPageBytes = 4096;
  const std::size_t bytes = elements.size_bytes();
  if (bytes < kHugePageBytes) return;
  auto* const first = reinterpret_cast<unsigned char*>(elements.data());
  const std::size_t huge_pages = (bytes + kHugePageBytes - 1) / kHugePageBytes;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, huge_pages, 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t h = r.begin(); h != r.end(); ++h)
          for (std::size_t at = h * kHugePageBytes; at < std::min(bytes, (h + 1) * kHugePageBytes); at += kPageBytes)
            *static_cast<volatile unsigned char*>(first + at) = 0;
      },
      tbb::simple_partitioner());
}

}  // namespace raybench::bvh2_build
