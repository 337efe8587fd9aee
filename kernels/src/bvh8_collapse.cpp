#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "raybench/bvh/bvh8.h"

namespace raybench {
namespace {

// Bvh8Node::far_to_near: for each octant, the lanes sorted by how far their
// box centre lies along the octant's diagonal (+x+y+z for octant 0, -x for
// bit 0 ...), farthest first; empty lanes go first, as no ray enters them
// (so do NaN boxes of a broken mesh, which no ray enters either).
// Ties keep lane order, so the result depends only on the boxes.
void order_children(Bvh8Node& node) {
  for (int octant = 0; octant < 8; ++octant) {
    float along[8];
    int lanes[8];
    for (int lane = 0; lane < 8; ++lane) {
      lanes[lane] = lane;
      along[lane] = std::numeric_limits<float>::infinity();
      if (node.child[lane] == Bvh8::kEmptyChild) continue;
      along[lane] = 0.0f;
      for (int a = 0; a < 3; ++a) {
        const float centre2 = node.bounds.lower[a][lane] + node.bounds.upper[a][lane];
        along[lane] += (octant >> a & 1) ? -centre2 : centre2;
      }
      // A NaN box must not break the sort's strict weak order.
      if (std::isnan(along[lane])) along[lane] = std::numeric_limits<float>::infinity();
    }
    std::stable_sort(lanes, lanes + 8, [&](int a, int b) { return along[a] > along[b]; });
    node.far_to_near[octant] = 0;
    for (int rank = 0; rank < 8; ++rank) node.far_to_near[octant] |= static_cast<std::uint32_t>(lanes[rank]) << (3 * rank);
  }
}

class Collapser {
 public:
  Collapser(const Bvh2& bvh2, std::span<const Triangle> triangles, Bvh8Leaves leaves, Bvh8& out)
      : bvh2_(bvh2), triangles_(triangles), leaves_(leaves), out_(out) {}

  // A BVH2 leaf becomes one pack.
  std::uint32_t make_pack(const Bvh2Node& leaf) {
    if (leaf.prim_count > 8) throw std::logic_error("collapse_to_bvh8: a BVH2 leaf holds more than 8 triangles");
    Triangle tris[8];
    for (std::uint32_t i = 0; i < leaf.prim_count; ++i) tris[i] = triangles_[bvh2_.prim_ids[leaf.first_index + i]];
    const auto index = static_cast<std::uint32_t>(out_.pack_prims.size() / 8);
    if (leaves_ == Bvh8Leaves::kVertices) out_.vertex_packs.push_back(TriangleVertices8::pack({tris, leaf.prim_count}));
    else out_.packs.push_back(Triangle8::pack({tris, leaf.prim_count}));
    for (std::uint32_t i = 0; i < 8; ++i)
      out_.pack_prims.push_back(i < leaf.prim_count ? static_cast<std::int32_t>(bvh2_.prim_ids[leaf.first_index + i]) : -1);
    return Bvh8::kLeafBit | index;
  }

  // Turns the BVH2 subtree at `n2` (an inner node) into a Bvh8 node; returns its index.
  std::uint32_t collapse(std::uint32_t n2, std::size_t level) {
    out_.depth = std::max(out_.depth, level);
    const auto index = static_cast<std::uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    std::vector<std::uint32_t> kids{bvh2_.nodes[n2].first_index, bvh2_.nodes[n2].first_index + 1};
    while (kids.size() < 8) {
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
    BBox boxes[8];
    std::uint32_t children[8];
    for (std::size_t i = 0; i < 8; ++i) children[i] = Bvh8::kEmptyChild;
    for (std::size_t i = 0; i < kids.size(); ++i) {
      const Bvh2Node& k = bvh2_.nodes[kids[i]];
      boxes[i] = k.bounds;
      children[i] = k.is_leaf() ? make_pack(k) : collapse(kids[i], level + 1);  // may grow out_.nodes
    }
    Bvh8Node& node = out_.nodes[index];
    node.bounds = BBox8::pack({boxes, kids.size()});
    std::copy(children, children + 8, node.child);
    order_children(node);
    return index;
  }

 private:
  const Bvh2& bvh2_;
  std::span<const Triangle> triangles_;
  Bvh8Leaves leaves_;
  Bvh8& out_;
};

}  // namespace

Bvh8 collapse_to_bvh8(const Bvh2& bvh2, std::span<const Triangle> triangles, Bvh8Leaves leaves) {
  Bvh8 out;
  Collapser c(bvh2, triangles, leaves, out);
  if (triangles.empty()) return out;  // no nodes: traversal returns at once
  const Bvh2Node& root = bvh2.nodes[0];
  if (root.is_leaf()) {
    // A single leaf: a root node with one child.
    out.nodes.emplace_back();
    const std::uint32_t pack = c.make_pack(root);
    const BBox box = root.bounds;
    out.nodes[0].bounds = BBox8::pack({&box, 1});
    std::fill(out.nodes[0].child, out.nodes[0].child + 8, Bvh8::kEmptyChild);
    out.nodes[0].child[0] = pack;
    order_children(out.nodes[0]);
  } else {
    c.collapse(0, 0);
  }
  return out;
}

double Bvh8::sah_cost() const {
  if (nodes.empty()) return 0.0;
  const auto lane_box = [](const BBox8& b, int lane) {
    BBox box;
    for (int a = 0; a < 3; ++a) {
      box.lower[a] = b.lower[a][lane];
      box.upper[a] = b.upper[a][lane];
    }
    return box;
  };
  BBox root;
  for (int lane = 0; lane < 8; ++lane) root.extend(lane_box(nodes[0].bounds, lane));  // empty lanes add nothing
  const double root_area = root.half_area();
  if (!(root_area > 0.0)) return 0.0;
  double cost = root_area;  // the root is always visited
  for (const Bvh8Node& n : nodes)
    for (int lane = 0; lane < 8; ++lane)
      if (n.child[lane] != kEmptyChild) cost += lane_box(n.bounds, lane).half_area();  // an inner node or a pack
  return cost / root_area;
}

}  // namespace raybench
