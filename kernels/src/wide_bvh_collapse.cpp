#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "raybench/bvh/wide_bvh.h"

namespace raybench {
namespace {

// WideNode::far_to_near: for each octant, the lanes sorted by how far their
// box centre lies along the octant's diagonal (+x+y+z for octant 0, -x for
// bit 0 ...), farthest first; empty lanes go first, as no ray enters them
// (so do NaN boxes of a broken mesh, which no ray enters either).
// Ties keep lane order, so the result depends only on the boxes.
template <int W>
void order_children(WideNode<W>& node) {
  for (int octant = 0; octant < 8; ++octant) {
    float along[W];
    int lanes[W];
    for (int lane = 0; lane < W; ++lane) {
      lanes[lane] = lane;
      along[lane] = std::numeric_limits<float>::infinity();
      if (node.child[lane] == WideBvh<W>::kEmptyChild) continue;
      along[lane] = 0.0f;
      for (int a = 0; a < 3; ++a) {
        const float centre2 = node.bounds.lower[a][lane] + node.bounds.upper[a][lane];
        along[lane] += (octant >> a & 1) ? -centre2 : centre2;
      }
      // A NaN box must not break the sort's strict weak order.
      if (std::isnan(along[lane])) along[lane] = std::numeric_limits<float>::infinity();
    }
    std::stable_sort(lanes, lanes + W, [&](int a, int b) { return along[a] > along[b]; });
    std::uint32_t order = 0;
    for (int rank = 0; rank < W; ++rank)
      order |= static_cast<std::uint32_t>(lanes[rank]) << (WideNode<W>::kOrderBits * rank);
    node.far_to_near[octant] = static_cast<typename WideNode<W>::Order>(order);
  }
}

template <int W>
class Collapser {
 public:
  Collapser(const Bvh2& bvh2, std::span<const Triangle> triangles, WideLeaves leaves, WideBvh<W>& out)
      : bvh2_(bvh2), triangles_(triangles), leaves_(leaves), out_(out) {}

  // A BVH2 leaf becomes one pack.
  std::uint32_t make_pack(const Bvh2Node& leaf) {
    if (leaf.prim_count > W)
      throw std::logic_error("collapse_bvh2: a BVH2 leaf holds more than " + std::to_string(W) + " triangles");
    Triangle tris[W];
    for (std::uint32_t i = 0; i < leaf.prim_count; ++i) tris[i] = triangles_[bvh2_.prim_ids[leaf.first_index + i]];
    const auto index = static_cast<std::uint32_t>(out_.pack_prims.size() / W);
    if constexpr (W == 8) {
      if (leaves_ == WideLeaves::kVertices) out_.vertex_packs.push_back(TriangleVertices8::pack({tris, leaf.prim_count}));
      else out_.packs.push_back(TrianglePack<W>::pack({tris, leaf.prim_count}));
    } else {
      out_.packs.push_back(TrianglePack<W>::pack({tris, leaf.prim_count}));
    }
    for (std::uint32_t i = 0; i < W; ++i)
      out_.pack_prims.push_back(i < leaf.prim_count ? static_cast<std::int32_t>(bvh2_.prim_ids[leaf.first_index + i]) : -1);
    return WideBvh<W>::kLeafBit | index;
  }

  // Turns the BVH2 subtree at `n2` (an inner node) into a wide node; returns its index.
  std::uint32_t collapse(std::uint32_t n2, std::size_t level) {
    out_.depth = std::max(out_.depth, level);
    const auto index = static_cast<std::uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    std::vector<std::uint32_t> kids{bvh2_.nodes[n2].first_index, bvh2_.nodes[n2].first_index + 1};
    while (kids.size() < W) {
      int best = -1;
      float best_area = -1.0f;
      for (std::size_t i = 0; i < kids.size(); ++i) {
        const Bvh2Node& k = bvh2_.nodes[kids[i]];
        if (!k.is_leaf() && k.bounds.half_area() > best_area) {
          best_area = k.bounds.half_area();
          best = static_cast<int>(i);
        }
      }
      if (best < 0) break;
      const std::uint32_t opened = kids[static_cast<std::size_t>(best)];
      kids[static_cast<std::size_t>(best)] = bvh2_.nodes[opened].first_index;
      kids.push_back(bvh2_.nodes[opened].first_index + 1);
    }
    BBox boxes[W];
    std::uint32_t children[W];
    std::fill(children, children + W, WideBvh<W>::kEmptyChild);
    for (std::size_t i = 0; i < kids.size(); ++i) {
      const Bvh2Node& k = bvh2_.nodes[kids[i]];
      boxes[i] = k.bounds;
      children[i] = k.is_leaf() ? make_pack(k) : collapse(kids[i], level + 1);  // may grow out_.nodes
    }
    WideNode<W>& node = out_.nodes[index];
    node.bounds = BBoxWide<W>::pack({boxes, kids.size()});
    std::copy(children, children + W, node.child);
    order_children(node);
    return index;
  }

 private:
  const Bvh2& bvh2_;
  std::span<const Triangle> triangles_;
  WideLeaves leaves_;
  WideBvh<W>& out_;
};

}  // namespace

template <int W>
WideBvh<W> collapse_bvh2(const Bvh2& bvh2, std::span<const Triangle> triangles, WideLeaves leaves) {
  if (W != 8 && leaves == WideLeaves::kVertices)
    throw std::invalid_argument("collapse_bvh2: vertex leaves (the watertight test) are 8 wide only");
  WideBvh<W> out;
  Collapser<W> c(bvh2, triangles, leaves, out);
  if (triangles.empty()) return out;  // no nodes: traversal returns at once
  const Bvh2Node& root = bvh2.nodes[0];
  if (root.is_leaf()) {
    // A single leaf: a root node with one child.
    out.nodes.emplace_back();
    const std::uint32_t pack = c.make_pack(root);
    const BBox box = root.bounds;
    out.nodes[0].bounds = BBoxWide<W>::pack({&box, 1});
    std::fill(out.nodes[0].child, out.nodes[0].child + W, WideBvh<W>::kEmptyChild);
    out.nodes[0].child[0] = pack;
    order_children(out.nodes[0]);
  } else {
    c.collapse(0, 0);
  }
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
