// What the BVH2 builders share (private to kernels/src): a triangle's box,
// the SAH's leaf cost, and a total order on float keys for sorting.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

#include <tbb/parallel_invoke.h>

#include "raybench/bvh/bvh2.h"

namespace raybench::bvh2_build {

inline BBox triangle_bounds(const Triangle& t) {
  BBox b;
  b.extend(t.v0);
  b.extend(t.v1);
  b.extend(t.v2);
  return b;
}

// Leaf tests for n triangles tested `granularity` at a time, in units of one
// triangle test (Bvh2BuildOptions::leaf_granularity).
inline float leaf_tests(std::size_t n, int granularity) {
  const auto g = static_cast<std::size_t>(std::max(1, granularity));
  return static_cast<float>((n + g - 1) / g);
}

// A float as an unsigned integer with the same order (negative values
// flipped), and every NaN ordered too: sorting by it is a strict weak order
// even for the NaN centroids of a broken mesh, which std::sort on float
// comparisons is not (undefined behaviour).
inline std::uint32_t ordered_key(float f) {
  const auto bits = std::bit_cast<std::uint32_t>(f);
  return (bits & 0x80000000u) ? ~bits : bits | 0x80000000u;
}

// Builds both children of a split: as two TBB tasks when the range is large
// enough to be worth it (Bvh2BuildOptions::parallel_threshold), else in turn.
template <typename BuildLeft, typename BuildRight>
void build_children(std::size_t count, std::size_t parallel_threshold, BuildLeft&& left, BuildRight&& right) {
  if (count >= parallel_threshold) {
    tbb::parallel_invoke(left, right);
  } else {
    left();
    right();
  }
}

}  // namespace raybench::bvh2_build
