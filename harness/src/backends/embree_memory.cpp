// Embree 3's memory policy through its device config (embree_memory.h).
// Embree 3.13's FastAllocator (kernels/common/alloc.h) takes its tree's memory
// in main blocks of min(growSize, maxGrowSize) bytes, maxGrowSize being a
// twentieth of the estimated tree, at most maxAllocationSize = 2 MiB - 64.
// Blocks below that go to alignedMalloc (no huge-page advice); blocks of
// exactly that size, in a static scene, go to os_malloc, which tries
// MAP_HUGETLB (with `hugepages=1`) and else mmaps and advises MADV_HUGEPAGE.
// So by default only trees estimated above ~40 MiB get huge pages, and
// `alloc_main_block_size` cannot help: it sets growSize, which maxGrowSize
// caps. What routes every block to os_malloc is a thread block of exactly
// maxAllocationSize: each thread-local refill then asks for a whole main
// block of that size. Measured (AnonHugePages before and after a build, the
// sizes per scene): docs/notes/memory-policy.md.
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
