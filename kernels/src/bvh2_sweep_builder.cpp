// Full-sweep SAH BVH2 builder, the quality reference for the binned builder.
// At every node it evaluates every object partition between neighbours in
// centroid order on all three axes, with the prefix and suffix bounds of one
// sweep each way (MacDonald & Booth, "Heuristics for ray tracing using space
// subdivision", The Visual Computer 1990; Wald, Boulos & Shirley, "Ray tracing
// deformable scenes using dynamic bounding volume hierarchies", ACM TOG 2007,
// which the binned builder approximates with 16 buckets).
//
// Instead of sorting at every node, the three axis orders are sorted once and
// each split partitions them stably, so every node finds its primitives
// already sorted on every axis (the presorting of Wald & Havran, "On building
// fast kd-trees for ray tracing, and on doing that in O(N log N)", RT 2006):
// O(n log n) up front, O(n) per tree level. Ties in centroid are ordered by
// triangle index, so the tree depends only on the input. Subtrees are built
// in parallel with TBB, as in the binned builder.
#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <numeric>

#include <tbb/parallel_sort.h>

#include "bvh2_build_util.h"

namespace raybench {
namespace {

using bvh2_build::leaf_tests;
using bvh2_build::ordered_key;

struct Split {
  int axis = -1;
  std::size_t left_count = 0;  // the first left_count primitives in this axis' order go left
  float cost = std::numeric_limits<float>::infinity();  // area-weighted, not yet divided by the node's area
};

class SweepBuilder {
 public:
  SweepBuilder(std::span<const Triangle> triangles, std::vector<Bvh2Node>& nodes, const Bvh2BuildOptions& options)
      : nodes_(nodes), options_(options) {
    const std::size_t n = triangles.size();
    bounds_.resize(n);
    for (std::size_t i = 0; i < n; ++i) bounds_[i] = triangle_bounds(triangles[i]);
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<std::uint64_t> keyed(n);  // centroid key in the high half, index in the low half
      for (std::size_t i = 0; i < n; ++i)
        keyed[i] = std::uint64_t{ordered_key(bounds_[i].center()[axis])} << 32 | i;
      tbb::parallel_sort(keyed.begin(), keyed.end());
      order_[axis].resize(n);
      for (std::size_t i = 0; i < n; ++i) order_[axis][i] = static_cast<std::uint32_t>(keyed[i]);
    }
    right_cost_.resize(n);
    goes_left_.resize(n);
    scratch_.resize(n);
  }

  // Builds the subtree of order_[*][begin, end) into nodes_[node_index].
  void build(std::uint32_t node_index, std::size_t begin, std::size_t end, int depth) {
    BBox bounds, centroid_bounds;
    for (std::size_t i = begin; i < end; ++i) {
      bounds.extend(bounds_[order_[0][i]]);
      centroid_bounds.extend(bounds_[order_[0][i]].center());
    }
    Bvh2Node& node = nodes_[node_index];
    node.bounds = bounds;
    const std::size_t count = end - begin;
    const bool may_be_leaf = count <= static_cast<std::size_t>(options_.max_leaf_size);
    const auto make_leaf = [&] {
      node.first_index = static_cast<std::uint32_t>(begin);
      node.prim_count = static_cast<std::uint32_t>(count);
    };
    if (count <= 1) return make_leaf();
    // A node without area (all its triangles on one point) costs nothing to
    // enter, so the SAH cannot choose; a leaf avoids the extra nodes.
    const float area = bounds.half_area();
    if (!(area > 0.0f) && may_be_leaf) return make_leaf();

    Split split;
    if (depth < options_.max_sah_depth && area > 0.0f) split = find_split(begin, end);
    if (split.axis >= 0) {
      const float split_cost = options_.traversal_cost + split.cost / area;
      if (split_cost >= leaf_tests(count, options_.leaf_granularity) && may_be_leaf) return make_leaf();
    } else {
      // max_sah_depth reached, no area, or no finite cost (infinite
      // coordinates): halve the range along the widest centroid extent, as
      // the binned builder does, which bounds the depth by max_sah_depth + 32.
      if (may_be_leaf) return make_leaf();
      split = {centroid_bounds.largest_axis(), count / 2, 0.0f};
    }
    partition(begin, end, split);
    const std::size_t middle = begin + split.left_count;

    const std::uint32_t left = next_node_.fetch_add(2);
    node.first_index = left;
    node.prim_count = 0;
    bvh2_build::build_children(count, options_.parallel_threshold, [&] { build(left, begin, middle, depth + 1); },
                               [&] { build(left + 1, middle, end, depth + 1); });
  }

  std::uint32_t node_count() const { return next_node_.load(); }
  // Leaf order: any of the three orders holds each leaf's primitives at its
  // range; the x order is as good as another.
  std::vector<std::uint32_t> take_prim_ids() { return std::move(order_[0]); }

 private:
  // The cheapest partition over all axes and positions; equal costs prefer
  // the more balanced split (coincident triangles then halve instead of
  // peeling one off per level).
  Split find_split(std::size_t begin, std::size_t end) {
    const std::size_t count = end - begin;
    const int g = options_.leaf_granularity;
    Split best;
    std::size_t best_imbalance = count;
    for (int axis = 0; axis < 3; ++axis) {
      const std::vector<std::uint32_t>& order = order_[axis];
      // Right to left: right_cost_[i] is the cost of order[i, end) as one side.
      BBox acc;
      for (std::size_t i = end - 1; i > begin; --i) {
        acc.extend(bounds_[order[i]]);
        right_cost_[i] = acc.half_area() * leaf_tests(end - i, g);
      }
      acc = BBox{};
      for (std::size_t i = begin; i + 1 < end; ++i) {
        acc.extend(bounds_[order[i]]);
        const std::size_t left_count = i + 1 - begin;
        const float cost = acc.half_area() * leaf_tests(left_count, g) + right_cost_[i + 1];
        const std::size_t imbalance = left_count > count / 2 ? left_count - count / 2 : count / 2 - left_count;
        if (cost < best.cost || (cost == best.cost && imbalance < best_imbalance)) {
          best = {axis, left_count, cost};
          best_imbalance = imbalance;
        }
      }
    }
    return best;
  }

  // Moves the split's left primitives to the front of every axis order,
  // keeping each order sorted (a stable partition by a per-triangle flag).
  void partition(std::size_t begin, std::size_t end, const Split& split) {
    const std::vector<std::uint32_t>& chosen = order_[split.axis];
    const std::size_t middle = begin + split.left_count;
    for (std::size_t i = begin; i < end; ++i) goes_left_[chosen[i]] = i < middle;
    for (int axis = 0; axis < 3; ++axis) {
      if (axis == split.axis) continue;
      std::vector<std::uint32_t>& order = order_[axis];
      std::size_t l = begin, r = middle;
      for (std::size_t i = begin; i < end; ++i) scratch_[goes_left_[order[i]] ? l++ : r++] = order[i];
      std::copy(scratch_.begin() + static_cast<std::ptrdiff_t>(begin), scratch_.begin() + static_cast<std::ptrdiff_t>(end),
                order.begin() + static_cast<std::ptrdiff_t>(begin));
    }
  }

  std::vector<Bvh2Node>& nodes_;
  const Bvh2BuildOptions& options_;
  std::vector<BBox> bounds_;                      // per triangle
  std::array<std::vector<std::uint32_t>, 3> order_;  // triangle indices sorted by centroid on x, y, z
  // Scratch indexed by position (right_cost_, scratch_) or by triangle
  // (goes_left_): concurrent subtrees touch disjoint parts.
  std::vector<float> right_cost_;
  std::vector<std::uint8_t> goes_left_;
  std::vector<std::uint32_t> scratch_;
  std::atomic<std::uint32_t> next_node_{1};
};

}  // namespace

Bvh2 build_bvh2_sweep_sah(std::span<const Triangle> triangles, const Bvh2BuildOptions& options) {
  Bvh2 bvh;
  if (triangles.empty()) {
    bvh.nodes.resize(1);  // an empty leaf whose empty box no ray enters
    return bvh;
  }
  bvh.nodes.resize(2 * triangles.size());
  SweepBuilder builder(triangles, bvh.nodes, options);
  builder.build(0, 0, triangles.size(), 0);
  bvh.nodes.resize(builder.node_count());
  bvh.nodes.shrink_to_fit();
  bvh.prim_ids = builder.take_prim_ids();
  return bvh;
}

}  // namespace raybench
