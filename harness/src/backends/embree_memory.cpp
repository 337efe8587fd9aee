// Embree 3's memory policy through its device config (embree_memory.h).
// What: "on" sets a thread block of exactly Embree 3.13's maxAllocationSize,
// which routes every block of its tree through its advised os_malloc; "off"
// keeps its main blocks below that size, so none is advised.
// Why: only blocks of exactly that size reach os_malloc (by default only
// trees above ~40 MiB); Embree's allocator and the measurements:
// docs/notes/memory-policy.md.
#include "backends/embree_memory.h"

#include <cstddef>
#include <string>

namespace raybench {

namespace {

// Embree 3's FastAllocator::maxAllocationSize: 2 MiB less its maxAlignment.
constexpr std::size_t kEmbreeMaxAllocationBytes = (std::size_t{2} << 20) - 64;
// Below kEmbreeMaxAllocationBytes, so that no main block reaches os_malloc
// (whose 4 KiB fallback advises MADV_HUGEPAGE whatever `hugepages` says).
// maxGrowSize caps it below 1 MiB for trees estimated under ~20 MiB, whose
// blocks so stay as the default makes them.
constexpr std::size_t kOrdinaryMainBlockBytes = std::size_t{1} << 20;

}  // namespace

std::string embree_memory_config(bool huge_pages) {
  if (huge_pages) return "hugepages=1,alloc_thread_block_size=" + std::to_string(kEmbreeMaxAllocationBytes);
  return "hugepages=0,alloc_main_block_size=" + std::to_string(kOrdinaryMainBlockBytes);
}

}  // namespace raybench
