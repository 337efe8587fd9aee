// Cache hints for the traversal and batch loops: ask for memory some time
// before it is read (GCC's __builtin_prefetch, a read into every cache
// level). A hint changes no result, only when the data arrives.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "raybench/math/ray.h"

namespace raybench {

// Every 64-byte cache line that holds some of the `bytes` bytes from `p`,
// counted from the line of the first byte: a range that starts inside a
// line (rays of 32 bytes from a 16-byte-aligned array) also gets its last
// line.
inline void prefetch_bytes(const void* p, std::size_t bytes) {
  if (bytes == 0) return;
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t end = begin + bytes;
  for (std::uintptr_t line = begin & ~std::uintptr_t{63}; line < end; line += 64)
    __builtin_prefetch(reinterpret_cast<const void*>(line));
}

// Every cache line of `x` (a node, a pack of triangles).
template <typename T>
inline void prefetch_lines(const T& x) {
  prefetch_bytes(&x, sizeof(T));
}

// rays[first, first + count), the part of it inside the span: the rays a
// batch loop reads next. A loop that traces a packet (or one ray) between
// its reads of the ray array leaves the hardware's stream prefetcher
// behind; asking for the next packet's rays while tracing this one hides
// their load (docs/notes/kernels-packets.md, "the next group's rays prefetched").
inline void prefetch_rays(std::span<const Ray> rays, std::size_t first, std::size_t count) {
  if (first >= rays.size()) return;
  prefetch_bytes(&rays[first], std::min(count, rays.size() - first) * sizeof(Ray));
}

}  // namespace raybench
