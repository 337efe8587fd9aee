#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/wide_bvh.h"

namespace raybench {
namespace {

// WideNode::far_to_near: for each octant, the lanes sorted by how far their
// box centre lies along the octant's diagonal (+x+y+z for octant 0, -x for
// bit 0 ...), farthest first; empty lanes go first, as no ray enters them
// (so do NaN boxes of a broken mesh, which no ray enters either).
// Ties keep lane order (a stable insertion sort of at most 8 lanes), so the
// result depends only on the boxes.
template <int W>
void order_children(WideNode<W>& node) {
  for (int octant = 0; octant < 8; ++octant) {
    float along[W];
    int lanes[W];
    for (int lane = 0; lane < W; ++lane) {
      along[lane] = std::numeric_limits<float>::infinity();
      if (node.child[lane] != WideBvh<W>::kEmptyChild) {
        along[lane] = 0.0f;
        for (int a = 0; a < 3; ++a) {
          const float centre2 = node.bounds.lower[a][lane] + node.bounds.upper[a][lane];
          along[lane] += (octant >> a & 1) ? -centre2 : centre2;
        }
        // A NaN box must not break the sort's strict weak order.
        if (std::isnan(along[lane])) along[lane] = std::numeric_limits<float>::infinity();
      }
      int at = lane;
      for (; at > 0 && along[lanes[at - 1]] < along[lane]; --at) lanes[at] = lanes[at - 1];
      lanes[at] = lane;
    }
    std::uint32_t order = 0;
    for (int rank = 0; rank < W; ++rank)
      order |= static_cast<std::uint32_t>(lanes[rank]) << (WideNode<W>::kOrderBits * rank);
    node.far_to_near[octant] = static_cast<typename WideNode<W>::Order>(order);
  }
}

// The collapse in two passes. The first, serial and cheap, decides the wide
// tree's shape from the BVH2 alone: which BVH2 nodes become each wide node's
// children (the inner child of largest area opened until W children), and
// the index of every wide node and pack, in depth-first order. The second
// fills nodes and packs, which costs most (boxes, child orders, triangle
// packs), in parallel: each writes only its own slot, so the result is the
// same for any thread count.
template <int W>
class Collapser {
 public:
  Collapser(const Bvh2& bvh2, std::span<const Triangle> triangles, WideLeaves leaves, WideBvh<W>& out)
      : bvh2_(bvh2), triangles_(triangles), leaves_(leaves), out_(out) {}

  void run() {
    const Bvh2Node& root = bvh2_.nodes[0];
    if (root.is_leaf()) {
      // A single leaf: a root node with one child.
      plans_.push_back({});
      plans_[0].kids[0] = 0;
      plans_[0].child[0] = add_pack(0);
      plans_[0].count = 1;
    } else {
      plan(0, 0);
    }
    out_.nodes.resize(plans_.size());
    out_.pack_prims.resize(pack_leaves_.size() * W);
    if (leaves_ == WideLeaves::kVertices) out_.vertex_packs.resize(pack_leaves_.size());
    else out_.packs.resize(pack_leaves_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, plans_.size(), 1024), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) fill_node(i);
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pack_leaves_.size(), 1024), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) fill_pack(i);
    });
  }

 private:
  struct Plan {
    std::uint32_t kids[W];   // BVH2 nodes
    std::uint32_t child[W];  // what WideNode::child will hold for each
    int count = 0;
  };

  std::uint32_t add_pack(std::uint32_t bvh2_leaf) {
    if (bvh2_.nodes[bvh2_leaf].prim_count > W)
      throw std::logic_error("collapse_bvh2: a BVH2 leaf holds more than " + std::to_string(W) + " triangles");
    pack_leaves_.push_back(bvh2_leaf);
    return WideBvh<W>::kLeafBit | static_cast<std::uint32_t>(pack_leaves_.size() - 1);
  }

  // Plans the wide node for the BVH2 subtree at `n2` (an inner node), then
  // its subtrees; returns its index.
  std::uint32_t plan(std::uint32_t n2, std::size_t level) {
    out_.depth = std::max(out_.depth, level);
    const auto index = static_cast<std::uint32_t>(plans_.size());
    Plan p;
    p.kids[0] = bvh2_.nodes[n2].first_index;
    p.kids[1] = bvh2_.nodes[n2].first_index + 1;
    p.count = 2;
    while (p.count < W) {
      int best = -1;
      float best_area = -1.0f;
      for (int i = 0; i < p.count; ++i) {
        const Bvh2Node& k = bvh2_.nodes[p.kids[i]];
        if (!k.is_leaf() && k.bounds.half_area() > best_area) {
          best_area = k.bounds.half_area();
          best = i;
        }
      }
      if (best < 0) break;
      const std::uint32_t opened = p.kids[best];
      p.kids[best] = bvh2_.nodes[opened].first_index;
      p.kids[p.count++] = bvh2_.nodes[opened].first_index + 1;
    }
    plans_.push_back(p);
    for (int i = 0; i < p.count; ++i) {
      const std::uint32_t kid = p.kids[i];
      const std::uint32_t child = bvh2_.nodes[kid].is_leaf() ? add_pack(kid) : plan(kid, level + 1);  // grows plans_
      plans_[index].child[i] = child;
    }
    return index;
  }

  void fill_node(std::size_t i) {
    const Plan& p = plans_[i];
    BBox boxes[W];
    for (int k = 0; k < p.count; ++k) boxes[k] = bvh2_.nodes[p.kids[k]].bounds;
    WideNode<W>& node = out_.nodes[i];
    node.bounds = BBoxWide<W>::pack({boxes, static_cast<std::size_t>(p.count)});
    std::fill(node.child, node.child + W, WideBvh<W>::kEmptyChild);
    std::copy(p.child, p.child + p.count, node.child);
    order_children(node);
  }

  // A BVH2 leaf becomes one pack.
  void fill_pack(std::size_t i) {
    const Bvh2Node& leaf = bvh2_.nodes[pack_leaves_[i]];
    Triangle tris[W];
    for (std::uint32_t k = 0; k < leaf.prim_count; ++k) tris[k] = triangles_[bvh2_.prim_ids[leaf.first_index + k]];
    const std::span<const Triangle> used(tris, leaf.prim_count);
    if constexpr (W == 8) {
      if (leaves_ == WideLeaves::kVertices) out_.vertex_packs[i] = TriangleVertices8::pack(used);
      else out_.packs[i] = TrianglePack<W>::pack(used);
    } else {
      out_.packs[i] = TrianglePack<W>::pack(used);
    }
    for (std::uint32_t k = 0; k < W; ++k)
      out_.pack_prims[i * W + k] = k < leaf.prim_count ? static_cast<std::int32_t>(bvh2_.prim_ids[leaf.first_index + k]) : -1;
  }

  const Bvh2& bvh2_;
  std::span<const Triangle> triangles_;
  WideLeaves leaves_;
  WideBvh<W>& out_;
  std::vector<Plan> plans_;
  std::vector<std::uint32_t> pack_leaves_;  // the BVH2 leaf of each pack
};

}  // namespace

template <int W>
WideBvh<W> collapse_bvh2(const Bvh2& bvh2, std::span<const Triangle> triangles, WideLeaves leaves) {
  if (W != 8 && leaves == WideLeaves::kVertices)
    throw std::invalid_argument("collapse_bvh2: vertex leaves (the watertight test) are 8 wide only");
  WideBvh<W> out;
  if (triangles.empty()) return out;  // no nodes: traversal returns at once
  Collapser<W>(bvh2, triangles, leaves, out).run();
  return out;
}

template <int W>
double WideBvh<W>::sah_cost() const {
  if (nodes.empty()) return 0.0;
  BBox root;
  for (int lane = 0; lane < W; ++lane) root.extend(nodes[0].bounds.lane(lane));  // empty lanes add nothing
  const double root_area = root.half_area();
  if (!(root_area > 0.0)) return 0.0;
  double cost = root_area;  // the root is always visited
  for (const WideNode<W>& n : nodes)
    for (int lane = 0; lane < W; ++lane)
      if (n.child[lane] != kEmptyChild) cost += n.bounds.lane(lane).half_area();  // an inner node or a pack
  return cost / root_area;
}

template struct WideBvh<4>;
template struct WideBvh<8>;
template WideBvh<4> collapse_bvh2<4>(const Bvh2&, std::span<const Triangle>, WideLeaves);
template WideBvh<8> collapse_bvh2<8>(const Bvh2&, std::span<const Triangle>, WideLeaves);

}  // namespace raybench
