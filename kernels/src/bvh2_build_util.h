// What the BVH2 builders share (private to kernels/src): a triangle's box,
// the SAH's leaf cost, a total order on float keys for sorting, and the
// binned object split (binned SAH and SBVH builders).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

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

// Binned object split (Wald, "On fast construction of SAH-based bounding
// volume hierarchies", RT 2007): centroids binned into `bins` equal bins per
// axis, every bin boundary evaluated by the SAH.
inline constexpr int kMaxBins = 64;

struct ObjectSplit {
  int axis = -1;  // -1: none (the centroids coincide on every axis)
  int bin = 0;    // centroids in bins [0, bin] go left (centroid_bin)
  float cost = std::numeric_limits<float>::infinity();  // area-weighted leaf tests, not yet divided by the node's area
  BBox left, right;  // the bounds of either side
};

// The bin of centroid coordinate c, bins of 1 / scale from lo; below lo, and
// NaN (the centroid of a broken triangle), fall in bin 0, beyond in the last.
inline int centroid_bin(float c, float lo, float scale, int bins) {
  const float f = (c - lo) * scale;
  if (!(f >= 0.0f)) return 0;
  return f < static_cast<float>(bins) ? static_cast<int>(f) : bins - 1;
}

// The SAH sweep over binned boxes: the plane before bin j (0 < j < bins)
// has bins [0, j) on its left, holding left_counts[0] + ... +
// left_counts[j - 1] primitives, and bins [j, bins) on its right, holding
// right_counts[j] + ... + right_counts[bins - 1]; calls
// consider(j, cost, left box, right box, left count, right count) for each,
// with cost the area-weighted leaf tests of both sides (in packs of
// `granularity`).
template <typename Consider>
void sweep_bins(const std::array<BBox, kMaxBins>& boxes, const std::array<std::size_t, kMaxBins>& left_counts,
                const std::array<std::size_t, kMaxBins>& right_counts, int bins, int granularity, Consider&& consider) {
  std::array<float, kMaxBins> right_cost{};
  std::array<BBox, kMaxBins> right_bounds{};
  std::array<std::size_t, kMaxBins> right_count{};
  BBox acc;
  std::size_t n = 0;
  for (int j = bins - 1; j > 0; --j) {
    acc.extend(boxes[j]);
    n += right_counts[j];
    right_bounds[j] = acc;
    right_count[j] = n;
    right_cost[j] = acc.half_area() * leaf_tests(n, granularity);
  }
  acc = BBox{};
  n = 0;
  for (int j = 1; j < bins; ++j) {
    acc.extend(boxes[j - 1]);
    n += left_counts[j - 1];
    const float cost = acc.half_area() * leaf_tests(n, granularity) + right_cost[j];
    consider(j, cost, acc, right_bounds[j], n, right_count[j]);
  }
}

// The cheapest object split of `refs` (anything with a `bounds` box; the
// centroid is centroid_of(ref)), counting leaf tests in packs of
// `granularity`; both sides non-empty.
template <typename Ref, typename CentroidOf>
ObjectSplit find_object_split(std::span<const Ref> refs, const BBox& centroid_bounds, int bins, int granularity,
                              CentroidOf&& centroid_of) {
  ObjectSplit best;
  for (int axis = 0; axis < 3; ++axis) {
    const float lo = centroid_bounds.lower[axis];
    const float extent = centroid_bounds.upper[axis] - lo;
    if (!(extent > 0.0f)) continue;
    const float scale = static_cast<float>(bins) / extent;
    std::array<BBox, kMaxBins> bin_bounds{};
    std::array<std::size_t, kMaxBins> bin_count{};
    for (const Ref& r : refs) {
      const int b = centroid_bin(centroid_of(r)[axis], lo, scale, bins);
      bin_bounds[b].extend(r.bounds);
      ++bin_count[b];
    }
    sweep_bins(bin_bounds, bin_count, bin_count, bins, granularity,
               [&](int j, float cost, const BBox& left, const BBox& right, std::size_t n, std::size_t) {
                 if (n > 0 && n < refs.size() && cost < best.cost) best = {axis, j - 1, cost, left, right};
               });
  }
  return best;
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
