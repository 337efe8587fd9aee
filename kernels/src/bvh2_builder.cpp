// Binned SAH BVH2 builder: Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", IEEE RT 2007. Subtrees are built in parallel with TBB.
// The tree's shape and leaf contents depend only on the input; with several
// threads the nodes' positions in the array may differ between builds, which
// changes no traversal result.
#include <algorithm>
#include <array>
#include <atomic>
#include <limits>


#include "raybench/bvh/bvh2.h"
#include "bvh2_build_util.h"

namespace raybench {
namespace {

struct PrimRef {
  BBox bounds;
  Vec3f centroid;
  std::uint32_t id;
};

struct Split {
  int axis = -1;
  int bin = 0;  // primitives in bins [0, bin] go left
  float cost = std::numeric_limits<float>::infinity();
};

constexpr int kMaxBins = 64;

class Builder {
 public:
  Builder(std::vector<PrimRef>& refs, std::vector<Bvh2Node>& nodes, const Bvh2BuildOptions& options)
      : refs_(refs), nodes_(nodes), options_(options), bins_(std::clamp(options.bin_count, 2, kMaxBins)) {}

  // Builds the subtree for refs_[begin, end) into nodes_[node_index].
  void build(std::uint32_t node_index, std::size_t begin, std::size_t end, int depth) {
    BBox bounds, centroid_bounds;
    for (std::size_t i = begin; i < end; ++i) {
      bounds.extend(refs_[i].bounds);
      centroid_bounds.extend(refs_[i].centroid);
    }
    Bvh2Node& node = nodes_[node_index];
    node.bounds = bounds;
    const std::size_t count = end - begin;
    const auto make_leaf = [&] {
      node.first_index = static_cast<std::uint32_t>(begin);
      node.prim_count = static_cast<std::uint32_t>(count);
    };
    if (count <= 1) return make_leaf();

    const Split split = depth < options_.max_sah_depth ? find_split(begin, end, centroid_bounds) : Split{};
    const float leaf_cost = tests(count);
    std::size_t middle;
    if (split.axis < 0) {
      // All centroids coincide (e.g. duplicated or degenerate triangles), or the
      // tree is already max_sah_depth deep: halve the range.
      if (count <= static_cast<std::size_t>(options_.max_leaf_size)) return make_leaf();
      middle = begin + count / 2;
    } else {
      const float split_cost = options_.traversal_cost + split.cost / bounds.half_area();
      if (split_cost >= leaf_cost && count <= static_cast<std::size_t>(options_.max_leaf_size)) return make_leaf();
      const int axis = split.axis;
      const float lo = centroid_bounds.lower[axis];
      const float scale = bins_ / (centroid_bounds.upper[axis] - lo);
      auto* mid = std::partition(refs_.data() + begin, refs_.data() + end,
                                 [&](const PrimRef& r) { return bin_of(r.centroid[axis], lo, scale) <= split.bin; });
      middle = static_cast<std::size_t>(mid - refs_.data());
      if (middle == begin || middle == end) middle = begin + count / 2;  // float rounding put all on one side
    }

    const std::uint32_t left = next_node_.fetch_add(2);
    node.first_index = left;
    node.prim_count = 0;
    bvh2_build::build_children(count, options_.parallel_threshold, [&] { build(left, begin, middle, depth + 1); },
                               [&] { build(left + 1, middle, end, depth + 1); });
  }

  std::uint32_t node_count() const { return next_node_.load(); }

 private:
  // Leaf tests for n triangles, in units of one triangle test.
  float tests(std::size_t n) const {
    const auto g = static_cast<std::size_t>(std::max(1, options_.leaf_granularity));
    return static_cast<float>((n + g - 1) / g);
  }

  int bin_of(float c, float lo, float scale) const {
    const int b = static_cast<int>((c - lo) * scale);
    return std::clamp(b, 0, bins_ - 1);
  }

  Split find_split(std::size_t begin, std::size_t end, const BBox& centroid_bounds) const {
    const int bins = bins_;
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      const float lo = centroid_bounds.lower[axis];
      const float extent = centroid_bounds.upper[axis] - lo;
      if (!(extent > 0.0f)) continue;
      const float scale = bins / extent;
      std::array<BBox, kMaxBins> bin_bounds{};
      std::array<std::size_t, kMaxBins> bin_count{};
      for (std::size_t i = begin; i < end; ++i) {
        const int b = bin_of(refs_[i].centroid[axis], lo, scale);
        bin_bounds[b].extend(refs_[i].bounds);
        ++bin_count[b];
      }
      // Sweep from the right to get the right-hand cost of every split plane.
      std::array<float, kMaxBins> right_cost{};
      BBox acc;
      std::size_t n = 0;
      for (int b = bins - 1; b > 0; --b) {
        acc.extend(bin_bounds[b]);
        n += bin_count[b];
        right_cost[b] = acc.half_area() * tests(n);
      }
      acc = BBox{};
      n = 0;
      for (int b = 0; b < bins - 1; ++b) {
        acc.extend(bin_bounds[b]);
        n += bin_count[b];
        const float cost = acc.half_area() * tests(n) + right_cost[b + 1];
        if (n > 0 && n < end - begin && cost < best.cost) best = {axis, b, cost};
      }
    }
    return best;
  }

  std::vector<PrimRef>& refs_;
  std::vector<Bvh2Node>& nodes_;
  const Bvh2BuildOptions& options_;
  const int bins_;
  std::atomic<std::uint32_t> next_node_{1};
};

}  // namespace

Bvh2 build_bvh2_binned_sah(std::span<const Triangle> triangles, const Bvh2BuildOptions& options) {
  Bvh2 bvh;
  std::vector<PrimRef> refs(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    BBox b;
    b.extend(triangles[i].v0);
    b.extend(triangles[i].v1);
    b.extend(triangles[i].v2);
    refs[i] = {b, b.center(), static_cast<std::uint32_t>(i)};
  }
  bvh.nodes.resize(std::max<std::size_t>(1, 2 * triangles.size()));
  if (triangles.empty()) {
    bvh.nodes.resize(1);  // an empty leaf whose empty box no ray enters
    return bvh;
  }
  Builder builder(refs, bvh.nodes, options);
  builder.build(0, 0, refs.size(), 0);
  bvh.nodes.resize(builder.node_count());
  bvh.nodes.shrink_to_fit();
  bvh.prim_ids.resize(refs.size());
  for (std::size_t i = 0; i < refs.size(); ++i) bvh.prim_ids[i] = refs[i].id;
  return bvh;
}

double Bvh2::sah_cost(int leaf_granularity) const {
  const double root_area = nodes.empty() ? 0.0 : nodes[0].bounds.half_area();
  if (!(root_area > 0.0)) return 0.0;
  const auto g = static_cast<std::uint32_t>(std::max(1, leaf_granularity));
  double cost = 0.0;
  for (const Bvh2Node& n : nodes) {
    const double area = n.bounds.half_area();
    cost += n.is_leaf() ? area * ((n.prim_count + g - 1) / g) : area;  // traversal and intersection cost 1
  }
  return cost / root_area;
}

}  // namespace raybench
