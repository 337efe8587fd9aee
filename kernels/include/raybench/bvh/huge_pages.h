// Memory for large BVH arrays, backed by transparent huge pages where the
// kernel offers them (Linux, THP in "madvise" mode, Debian's default).
//
// Why: a fresh allocation faults on the first touch of every 4 KiB page,
// and a BVH build touches all of its memory once, at once; 2 MiB pages
// fault 512 times less often (measured: docs/notes/kernels-builders.md).
// Where the kernel gives no huge pages the memory is ordinary pages, with
// the same contents. Embree advises its build
// memory the same way (MADV_HUGEPAGE in its os_malloc). Small arrays stay
// with operator new. The advice is a process-wide switch (set_huge_pages):
// a run's memory policy holds for every backend alike (docs/backends.md).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace raybench {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

// `bytes` rounded up to whole huge pages: what allocate_huge_pages maps and
// free_huge_pages unmaps for an array of kHugePageBytes or more.
inline constexpr std::size_t huge_page_rounded(std::size_t bytes) {
  return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

namespace huge_pages_detail {
inline std::atomic<bool> advise_huge_pages{true};
}  // namespace huge_pages_detail

// Whether allocate_huge_pages advises its large arrays as huge pages (on by
// default). Off, they are the same 2 MiB-aligned allocations without the
// advice: ordinary pages wherever the kernel's THP mode is "madvise".
// Arrays allocated before a change are freed correctly either way.
inline void set_huge_pages(bool advise) noexcept {
  huge_pages_detail::advise_huge_pages.store(advise, std::memory_order_relaxed);
}
inline bool huge_pages_enabled() noexcept {
  return huge_pages_detail::advise_huge_pages.load(std::memory_order_relaxed);
}

// `bytes` of memory aligned to `alignment` (at most kHugePageBytes); from
// bytes >= kHugePageBytes on, a fresh huge-page-aligned mapping, advised as
// huge pages while huge_pages_enabled(). Fresh, not from the heap: memory
// the heap hands out again was faulted in as small pages before, and stays
// so whatever the advice (measured: docs/notes/memory-policy.md); Embree's
// os_malloc maps afresh too.
// Release with free_huge_pages(p, bytes) with the same bytes.
inline void* allocate_huge_pages(std::size_t bytes, std::size_t alignment) {
  if (bytes < kHugePageBytes) return ::operator new(bytes, std::align_val_t(alignment));
  const std::size_t rounded = huge_page_rounded(bytes);
#if defined(__linux__)
  // One huge page more than needed, then the slack on either side unmapped.
  const std::size_t mapped = rounded + kHugePageBytes;
  void* raw = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  auto* const start = static_cast<char*>(raw);
  const std::size_t lead = (kHugePageBytes - reinterpret_cast<std::uintptr_t>(start) % kHugePageBytes) % kHugePageBytes;
  char* const p = start + lead;
  if (lead != 0) munmap(start, lead);
  munmap(p + rounded, mapped - lead - rounded);
#if defined(MADV_HUGEPAGE)
  if (huge_pages_enabled()) madvise(p, rounded, MADV_HUGEPAGE);  // advice only: refused, the memory just faults page by page
#endif
  return p;
#else
  void* p = std::aligned_alloc(kHugePageBytes, rounded);
  if (p == nullptr) throw std::bad_alloc();
  return p;
#endif
}

inline void free_huge_pages(void* p, std::size_t bytes, std::size_t alignment) {
  if (bytes < kHugePageBytes) {
    ::operator delete(p, std::align_val_t(alignment));
    return;
  }
#if defined(__linux__)
  munmap(p, huge_page_rounded(bytes));
#else
  std::free(p);
#endif
}

// A standard allocator over allocate_huge_pages, for the std::vectors of a
// BVH (WideBvh's nodes and packs), whose elements it default-initialises.
template <typename T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) { return static_cast<T*>(allocate_huge_pages(n * sizeof(T), alignof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_huge_pages(p, n * sizeof(T), alignof(T)); }

  // resize(n) default-initialises: trivial elements (nodes, packs) are left
  // unwritten, for the collapse to fill in parallel. Value-initialising them
  // would first zero the whole array serially, and touch every page there.
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// A std::vector in huge-page-backed memory.
template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace raybench
