// Linear BVH (LBVH) builder: Lauterbach, Garland, Sengupta, Luebke & Manocha,
// "Fast BVH construction on GPUs", Eurographics 2009. Triangle centroids,
// quantised to 2^21 cells per axis of the centroid bounds, are sorted along
// a 63-bit Morton (Z-order) curve; a range of sorted primitives is split
// where its highest differing Morton bit changes from 0 to 1, found by binary
// search. That is the binary radix tree of Karras, "Maximizing parallelism in
// the construction of BVHs, octrees, and k-d trees", HPG 2012, which builds
// the same topology one inner node per GPU thread; on two CPU cores a
// top-down recursion with TBB tasks is simpler and as fast. Ranges whose
// codes are all equal are halved (Karras appends the index to the key, which
// splits them as evenly).
//
// Bounds are refitted bottom-up as the recursion returns. A range of at most
// max_leaf_size primitives becomes a leaf when the SAH cost of the leaf is no
// more than that of the best Morton subtree below it (collapsing subtrees
// into leaves by SAH as Karras & Aila, "Fast parallel construction of
// high-quality bounding volume hierarchies", HPG 2013, do); larger ranges are
// always split.
//
// Depth: each Morton split lengthens the common prefix, so at most 63 levels
// split by code (and none past max_sah_depth), then at most 32 halvings:
// within max_sah_depth + 32 as for the SAH builders.
#include <algorithm>
#include <atomic>
#include <bit>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include "bvh2_build_util.h"

namespace raybench {
namespace {

using bvh2_build::leaf_tests;

constexpr int kBitsPerAxis = 21;  // 3 x 21 = 63 bits: a million triangles rarely share a code

// The 21 low bits of x spread to every third bit of the result.
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffffu;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// A coordinate's cell in [0, 2^21 - 1]; NaN and anything below the bounds
// fall in cell 0, so a broken centroid still gets a code.
std::uint64_t quantise(float c, float lower, float scale) {
  constexpr float kTop = static_cast<float>((1u << kBitsPerAxis) - 1);
  const float q = (c - lower) * scale;
  return static_cast<std::uint64_t>(q >= 0.0f ? std::min(q, kTop) : 0.0f);
}

struct MortonPrim {
  std::uint64_t code;
  std::uint32_t id;
  // Ties in code are ordered by index, so the tree depends only on the input.
  bool operator<(const MortonPrim& o) const { return code != o.code ? code < o.code : id < o.id; }
};

class LbvhBuilder {
 public:
  LbvhBuilder(std::vector<MortonPrim> prims, std::vector<BBox> bounds, std::vector<Bvh2Node>& nodes,
              const Bvh2BuildOptions& options)
      : prims_(std::move(prims)), bounds_(std::move(bounds)), nodes_(nodes), options_(options) {}

  // Builds the subtree of prims_[begin, end) into nodes_[node_index] and
  // returns its bounds (the bottom-up refit).
  BBox build(std::uint32_t node_index, std::size_t begin, std::size_t end, int depth) {
    const std::size_t count = end - begin;
    Bvh2Node& node = nodes_[node_index];
    if (count <= static_cast<std::size_t>(std::max(1, options_.max_leaf_size))) {
      const Subtree best = evaluate(begin, end, depth);
      if (best.leaf) {
        node.bounds = best.bounds;
        node.first_index = static_cast<std::uint32_t>(begin);
        node.prim_count = static_cast<std::uint32_t>(count);
        return best.bounds;
      }
    }
    const std::size_t middle = split_position(begin, end, depth);
    const std::uint32_t left = next_node_.fetch_add(2);
    node.first_index = left;
    node.prim_count = 0;
    BBox left_bounds, right_bounds;
    if (count >= options_.parallel_threshold) {
      tbb::parallel_invoke([&] { left_bounds = build(left, begin, middle, depth + 1); },
                           [&] { right_bounds = build(left + 1, middle, end, depth + 1); });
    } else {
      left_bounds = build(left, begin, middle, depth + 1);
      right_bounds = build(left + 1, middle, end, depth + 1);
    }
    node.bounds = left_bounds;
    node.bounds.extend(right_bounds);
    return node.bounds;
  }

  std::uint32_t node_count() const { return next_node_.load(); }

  std::vector<std::uint32_t> prim_ids() const {
    std::vector<std::uint32_t> ids(prims_.size());
    for (std::size_t i = 0; i < prims_.size(); ++i) ids[i] = prims_[i].id;
    return ids;
  }

 private:
  struct Subtree {
    BBox bounds;
    float cost;  // area-weighted SAH cost of the cheaper choice
    bool leaf;   // whether that choice is a leaf
  };

  // Where the Morton split puts the range's first primitive whose highest
  // differing bit is 1; ranges with one code, or past max_sah_depth, halve.
  std::size_t split_position(std::size_t begin, std::size_t end, int depth) const {
    const std::uint64_t first = prims_[begin].code, last = prims_[end - 1].code;
    if (first == last || depth >= options_.max_sah_depth) return begin + (end - begin) / 2;
    const std::uint64_t bit = std::uint64_t{1} << (63 - std::countl_zero(first ^ last));
    const auto* split = std::partition_point(prims_.data() + begin, prims_.data() + end,
                                             [&](const MortonPrim& p) { return (p.code & bit) == 0; });
    return static_cast<std::size_t>(split - prims_.data());
  }

  // The cheaper of a leaf and the best Morton subtree for a small range
  // (at most max_leaf_size primitives, so the recursion is short).
  Subtree evaluate(std::size_t begin, std::size_t end, int depth) const {
    BBox bounds;
    for (std::size_t i = begin; i < end; ++i) bounds.extend(bounds_[prims_[i].id]);
    const float area = bounds.half_area();
    const float leaf_cost = area * leaf_tests(end - begin, options_.leaf_granularity);
    if (end - begin == 1) return {bounds, leaf_cost, true};
    const std::size_t middle = split_position(begin, end, depth);
    const float split_cost =
        area * options_.traversal_cost + evaluate(begin, middle, depth + 1).cost + evaluate(middle, end, depth + 1).cost;
    if (leaf_cost <= split_cost) return {bounds, leaf_cost, true};
    return {bounds, split_cost, false};
  }

  std::vector<MortonPrim> prims_;  // sorted by Morton code
  std::vector<BBox> bounds_;       // per triangle, by input index
  std::vector<Bvh2Node>& nodes_;
  const Bvh2BuildOptions& options_;
  std::atomic<std::uint32_t> next_node_{1};
};

}  // namespace

Bvh2 build_bvh2_lbvh(std::span<const Triangle> triangles, const Bvh2BuildOptions& options) {
  Bvh2 bvh;
  const std::size_t n = triangles.size();
  if (n == 0) {
    bvh.nodes.resize(1);  // an empty leaf whose empty box no ray enters
    return bvh;
  }
  std::vector<BBox> bounds(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) bounds[i] = triangle_bounds(triangles[i]);
  });
  const BBox centroid_bounds = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n), BBox{},
      [&](const tbb::blocked_range<std::size_t>& r, BBox acc) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) acc.extend(bounds[i].center());
        return acc;
      },
      [](BBox a, const BBox& b) {
        a.extend(b);
        return a;
      });

  // Cells per unit length on each axis; a flat (or non-finite) extent puts
  // every centroid in cell 0 of that axis.
  Vec3f scale;
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = centroid_bounds.upper[axis] - centroid_bounds.lower[axis];
    scale[axis] = extent > 0.0f ? static_cast<float>(1u << kBitsPerAxis) / extent : 0.0f;
  }
  std::vector<MortonPrim> prims(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Vec3f c = bounds[i].center();
      std::uint64_t code = 0;
      for (int axis = 0; axis < 3; ++axis)
        code |= spread_bits(quantise(c[axis], centroid_bounds.lower[axis], scale[axis])) << (2 - axis);
      prims[i] = {code, static_cast<std::uint32_t>(i)};
    }
  });
  tbb::parallel_sort(prims.begin(), prims.end());

  bvh.nodes.resize(2 * n);
  LbvhBuilder builder(std::move(prims), std::move(bounds), bvh.nodes, options);
  builder.build(0, 0, n, 0);
  bvh.nodes.resize(builder.node_count());
  bvh.nodes.shrink_to_fit();
  bvh.prim_ids = builder.prim_ids();
  return bvh;
}

}  // namespace raybench
