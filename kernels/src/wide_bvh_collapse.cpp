// The collapse of a Bvh2 into a WideBvh<W> (W = 8 or 4), collapse_bvh2 in
// raybench/bvh/wide_bvh.h: the wide tree of least SAH cost among all whose
// nodes are cuts of the BVH2, by the dynamic programme of Ylitie, Karras &
// Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
// BVHs", HPG 2017 (section 4.1); each node's per-octant child orders and
// any-hit lane order; the triangle packs its leaf test needs.
// Guarantee: every triangle of the BVH2 is in exactly one pack; the result
// is the same bytes for any thread count (each task writes only its own
// slots); NaN or infinite boxes and costs (a broken mesh, coordinates past
// about 3.7e18) still give a valid tree, never a leaf of more than
// max_leaf_packs packs of W.
// measured (optimal against greedy, costs tried, build time):
// docs/notes/kernels-collapse.md
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "raybench/bvh/wide_bvh.h"
#include "raybench/simd/lanes.h"
#include "fault_in_parallel.h"

namespace raybench {
namespace {

// The indices 0 .. count - 1 ordered by decreasing key, ties in index order:
// a stable insertion sort, count being at most a node's width. The callers
// map the keys of NaN boxes to an infinity, keeping the order strict weak.
template <int W>
void order_by_decreasing(const float (&key)[W], int count, int (&order)[W]) {
  for (int i = 0; i < count; ++i) {
    int at = i;
    for (; at > 0 && key[order[at - 1]] < key[i]; --at) order[at] = order[at - 1];
    order[at] = i;
  }
}

// WideNode::far_to_near: for each octant, the lanes sorted by how far their
// box centre lies along the octant's diagonal (+x+y+z for octant 0, -x for
// bit 0 ...), farthest first; empty lanes go first, as no ray enters them
// (so do NaN boxes of a broken mesh, which no ray enters either).
// Ties keep lane order, so the result depends only on the boxes.
template <int W>
void order_children(WideNode<W>& node) {
#if defined(__AVX2__)
  // The same keys and order, W lanes at a time: each lane's rank in the
  // order (keys greater, then equal keys in earlier lanes) is a popcount of
  // two lane comparisons. The insertion sort's data-dependent branches
  // mispredicted (measured: docs/notes/kernels-collapse.md).
  using Lanes = simd::FloatLanes<W>;
  const Lanes inf = Lanes::set1(std::numeric_limits<float>::infinity());
  Lanes centre2[3];
  for (int a = 0; a < 3; ++a) centre2[a] = Lanes::load(node.bounds.lower[a]) + Lanes::load(node.bounds.upper[a]);
  unsigned empty = 0;
  for (int lane = 0; lane < W; ++lane) empty |= (node.child[lane] == WideBvh<W>::kEmptyChild ? 1u : 0u) << lane;
  for (int octant = 0; octant < 8; ++octant) {
    Lanes along = Lanes::set1(0.0f);
    for (int a = 0; a < 3; ++a) along = along + (centre2[a] ^ Lanes::set1((octant >> a & 1) ? -0.0f : 0.0f));
    alignas(4 * W) float key[W];
    along.storeu(key);
    const unsigned not_nan = (along <= inf).mask();
    for (int lane = 0; lane < W; ++lane)
      if ((empty >> lane & 1) || !(not_nan >> lane & 1)) key[lane] = std::numeric_limits<float>::infinity();
    const Lanes keys = Lanes::load(key);
    std::uint32_t order = 0;
    for (int lane = 0; lane < W; ++lane) {
      const Lanes k = Lanes::set1(key[lane]);
      const unsigned greater = (keys > k).mask();
      const unsigned equal_before = ((keys >= k) & (keys <= k)).mask() & ((1u << lane) - 1u);
      order |= static_cast<std::uint32_t>(lane) << (WideNode<W>::kOrderBits * std::popcount(greater | equal_before));
    }
    node.far_to_near[octant] = static_cast<typename WideNode<W>::Order>(order);
  }
#else
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
        if (std::isnan(along[lane])) along[lane] = std::numeric_limits<float>::infinity();
      }
    }
    order_by_decreasing(along, W, lanes);
    std::uint32_t order = 0;
    for (int rank = 0; rank < W; ++rank)
      order |= static_cast<std::uint32_t>(lanes[rank]) << (WideNode<W>::kOrderBits * rank);
    node.far_to_near[octant] = static_cast<typename WideNode<W>::Order>(order);
  }
#endif
}

// The collapse in two passes. The first decides the wide tree's shape from
// the BVH2 alone: which BVH2 nodes become each wide node's children, which of
// those are packs (the costs below, in parallel tasks), and the index of
// every wide node and pack, in depth-first order (serial, cheap). The second
// fills nodes and packs, which costs most (boxes, child orders, triangle
// packs), in parallel: each writes only its own slot, so the result is the
// same for any thread count.
//
// The shape is the one of least SAH cost (WideBvh::sah_cost: a node visit
// and a pack test cost 1 each, weighted by the area of the box leading to
// them) among all wide trees whose nodes are cuts of the BVH2: the dynamic
// programme of Ylitie, Karras & Laine (HPG 2017, section 4.1). Bottom-up, for
// every BVH2 node n and slot count k = 1..W, the cheapest way to hold n's
// subtree in at most k child slots of a wide node: one slot (n as a leaf of
// ceil(triangles / W) packs, if at most max_leaf_packs, or as a wide node of
// its own), or n's two children sharing the k slots. Any BVH2 subtree small
// enough may become a leaf, so the BVH2 is best built with small leaves (the
// backends' quality builds use leaf_granularity 1) and the collapse gathers
// them. A leaf of several packs pays where its children's boxes would
// overlap most (large triangles: architectural interiors). It
// fills nodes fuller than the greedy collapse (open the largest child until
// W; Wald et al., RT 2008). measured, with the costs tried and dropped:
// docs/notes/kernels-collapse.md
template <int W>
class Collapser {
 public:
  Collapser(const Bvh2& bvh2, std::span<const Triangle> triangles, WideLeaves leaves, WideLaneOrder lane_order,
            int max_leaf_packs, WideBvh<W>& out)
      : bvh2_(bvh2),
        triangles_(triangles),
        leaves_(leaves),
        lane_order_(lane_order),
        max_leaf_triangles_(static_cast<std::uint32_t>(max_leaf_packs) * W),
        out_(out) {}

  void run() {
    const Bvh2Node& root = bvh2_.nodes[0];
    if (root.is_leaf()) {
      // A single leaf: a root node with one child.
      expect_fits_a_pack(root);
      plans_.push_back({});
      plans_[0].kids[0] = 0;
      plans_[0].child[0] = add_leaf(0, root.prim_count);
      plans_[0].count = 1;
    } else {
      choose_slots();
      // Room for the most there can be, so plan(), serial, never moves them:
      // every wide node is a distinct inner BVH2 node, every pack holds at
      // least one BVH2 leaf (measured: docs/notes/kernels-collapse.md).
      plans_.reserve(bvh2_.nodes.size() / 2);
      pack_roots_.reserve(bvh2_.nodes.size() / 2 + 1);
      plan(0, 0);
    }
    if (pack_roots_.size() > WideBvh<W>::kMaxPacks)
      throw std::length_error("collapse_bvh2: more than " + std::to_string(WideBvh<W>::kMaxPacks) + " packs");
    out_.nodes.resize(plans_.size());
    out_.pack_prims.resize(pack_roots_.size() * W);
    switch (leaves_) {
      case WideLeaves::kMollerTrumbore: out_.packs.resize(pack_roots_.size()); break;
      case WideLeaves::kMollerTrumboreEdges: out_.edge_packs.resize(pack_roots_.size()); break;
      case WideLeaves::kVertices: out_.vertex_packs.resize(pack_roots_.size()); break;
    }
    bvh2_build::fault_in_parallel(std::span(out_.nodes));
    bvh2_build::fault_in_parallel(std::span(out_.pack_prims));
    bvh2_build::fault_in_parallel(std::span(out_.packs));
    bvh2_build::fault_in_parallel(std::span(out_.edge_packs));
    bvh2_build::fault_in_parallel(std::span(out_.vertex_packs));
    // Small grains: a small mesh's hundred nodes and few hundred packs are
    // filled on both threads too (measured: docs/notes/kernels-collapse.md).
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, plans_.size(), 64), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) fill_node(i);
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pack_roots_.size(), 128), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) fill_pack(i);
    });
  }

 private:
  struct Plan {
    std::uint32_t kids[W];   // BVH2 nodes
    std::uint32_t child[W];  // what WideNode::child will hold for each
    int count = 0;
  };
  // A pack: the BVH2 subtree of its leaf, and which W of the subtree's
  // triangles (in the BVH2's order) it holds.
  struct PackRoot {
    std::uint32_t bvh2_node;
    std::uint32_t chunk;
  };

  static void expect_fits_a_pack(const Bvh2Node& leaf) {
    if (leaf.prim_count > W)
      throw std::logic_error("collapse_bvh2: a BVH2 leaf holds more than " + std::to_string(W) + " triangles");
  }

  // The slot choices of the dynamic programme for one BVH2 node.
  struct Slots {
    std::int8_t left[W];    // left[k - 1]: slots of the left child when the subtree has k; 0: one slot, itself
    std::int8_t as_node_left = 0;  // as a wide node of its own: slots of its left child
    bool as_leaf = false;   // in one slot: a leaf of packs (or else a wide node)
    std::uint32_t triangles = 0;  // in the subtree
  };

  void choose_slots() {
    slots_.resize(bvh2_.nodes.size());
    cost_ = std::make_unique_for_overwrite<float[]>(bvh2_.nodes.size() * W);
    if (lane_order_ == WideLaneOrder::kOcclusion) hit_chance_ = std::make_unique_for_overwrite<float[]>(bvh2_.nodes.size());
    choose_slots_below(0, 0);
  }

  // Fills slots_ and cost_ for the BVH2 subtree at `n`, children before
  // their parent; returns the subtree's triangle count. The top levels'
  // subtrees are evaluated as parallel tasks: each node writes only its own
  // entries, so the result is the same for any thread count.
  std::uint32_t choose_slots_below(std::uint32_t n, int depth) {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    const Bvh2Node& node = bvh2_.nodes[n];
    const float area = node.bounds.half_area();
    float* g = &cost_[n * W];  // g[k - 1]: the subtree in at most k slots
    Slots& s = slots_[n];
    std::fill(s.left, s.left + W, std::int8_t{0});
    if (node.is_leaf()) {
      expect_fits_a_pack(node);
      s.as_leaf = true;
      s.triangles = node.prim_count;
      std::fill(g, g + W, area);
      if (hit_chance_) hit_chance_[n] = leaf_hit_chance(node);
      return node.prim_count;
    }
    const std::uint32_t l = node.first_index, r = l + 1;
    std::uint32_t left_triangles = 0, right_triangles = 0;
    const auto left = [&] { left_triangles = choose_slots_below(l, depth + 1); };
    const auto right = [&] { right_triangles = choose_slots_below(r, depth + 1); };
    if (depth < parallel_depth_) {
      tbb::parallel_invoke(left, right);
    } else {
      left();
      right();
    }
    const std::uint32_t triangles = left_triangles + right_triangles;
    if (hit_chance_) {
      // A ray entering this box enters a child's with the ratio of their
      // areas (Cauchy, for convex boxes); the children's chances taken as
      // independent.
      const auto through = [&](std::uint32_t child) {
        return area > 0.0f ? std::min(1.0f, bvh2_.nodes[child].bounds.half_area() / area) * hit_chance_[child] : 0.0f;
      };
      hit_chance_[n] = 1.0f - (1.0f - through(l)) * (1.0f - through(r));
    }
    const float* gl = &cost_[l * W];
    const float* gr = &cost_[r * W];
    // split[k - 1]: the cheapest sharing of k >= 2 slots between the children.
    // Every sharing gives each child at least one slot: one slot to the left
    // is taken first, so that when every cost is infinite or NaN (box areas
    // overflow float for coordinates beyond about 3.7e18, or are NaN for
    // extents inf * 0), the choice is still a valid one: with no valid
    // choice the plan indexed left[-1] and packed too many triangles.
    float split[W];
    std::int8_t split_left[W] = {};
    for (int k = 2; k <= W; ++k) {
      split[k - 1] = gl[0] + gr[k - 2];
      split_left[k - 1] = 1;
      for (int i = 2; i < k; ++i) {
        const float c = gl[i - 1] + gr[k - i - 1];
        if (c < split[k - 1]) {
          split[k - 1] = c;
          split_left[k - 1] = static_cast<std::int8_t>(i);
        }
      }
    }
    const float as_node = area + split[W - 1];
    // A leaf of ceil(triangles / W) packs, each a test.
    const bool fits = triangles <= max_leaf_triangles_;
    const float as_leaf = fits ? area * static_cast<float>((triangles + W - 1) / W) : kInf;
    // A leaf unless a wide node costs less: the same choice as
    // as_leaf <= as_node for finite costs, but never a leaf of more than
    // max_leaf_packs packs, even when both costs are infinite or NaN.
    s.as_leaf = fits && !(as_node < as_leaf);
    s.triangles = triangles;
    s.as_node_left = split_left[W - 1];
    const float one_slot = std::min(as_leaf, as_node);
    g[0] = one_slot;
    for (int k = 2; k <= W; ++k) {
      g[k - 1] = one_slot;
      if (split[k - 1] < one_slot) {
        g[k - 1] = split[k - 1];
        s.left[k - 1] = split_left[k - 1];
      }
    }
    return triangles;
  }

  // The chance that a ray entering a BVH2 leaf's box hits one of its
  // triangles: a random line meeting a convex box meets a convex body inside
  // it with the ratio of their surface areas (Cauchy), for a triangle twice
  // its area over the box's, so area / half_area. Summed over the triangles
  // (an overestimate where they overlap as seen along the ray) and capped.
  float leaf_hit_chance(const Bvh2Node& leaf) const {
    const float box = leaf.bounds.half_area();
    float covered = 0.0f;
    for (std::uint32_t k = 0; k < leaf.prim_count; ++k) {
      const Triangle& t = triangles_[bvh2_.prim_ids[leaf.first_index + k]];
      covered += 0.5f * length(cross(t.v1 - t.v0, t.v2 - t.v0));
    }
    return box > 0.0f ? std::min(1.0f, covered / box) : 0.0f;
  }

  // Appends the children chosen for the BVH2 subtree at `n` given `k` slots.
  void add_kids(Plan& p, std::uint32_t n, int k) const {
    const int left = slots_[n].left[k - 1];
    if (left == 0) {
      p.kids[p.count++] = n;
      return;
    }
    add_kids(p, bvh2_.nodes[n].first_index, left);
    add_kids(p, bvh2_.nodes[n].first_index + 1, k - left);
  }

  // The leaf of the BVH2 subtree at `bvh2_node`, of `triangles` triangles:
  // its packs, consecutive.
  std::uint32_t add_leaf(std::uint32_t bvh2_node, std::uint32_t triangles) {
    const auto first = static_cast<std::uint32_t>(pack_roots_.size());
    const std::uint32_t packs = std::max<std::uint32_t>(1, (triangles + W - 1) / W);
    for (std::uint32_t chunk = 0; chunk < packs; ++chunk) pack_roots_.push_back({bvh2_node, chunk});
    return WideBvh<W>::leaf_ref(first & (WideBvh<W>::kMaxPacks - 1), packs);  // run() throws past kMaxPacks
  }

  // Plans the wide node for the BVH2 subtree at `n2` (an inner node), then
  // its subtrees; returns its index.
  std::uint32_t plan(std::uint32_t n2, std::size_t level) {
    out_.depth = std::max(out_.depth, level);
    const auto index = static_cast<std::uint32_t>(plans_.size());
    Plan p;
    const int left = slots_[n2].as_node_left;
    add_kids(p, bvh2_.nodes[n2].first_index, left);
    add_kids(p, bvh2_.nodes[n2].first_index + 1, W - left);
    plans_.push_back(p);
    for (int i = 0; i < p.count; ++i) {
      const std::uint32_t kid = p.kids[i];
      const std::uint32_t child = slots_[kid].as_leaf ? add_leaf(kid, slots_[kid].triangles) : plan(kid, level + 1);  // grows plans_
      plans_[index].child[i] = child;
    }
    return index;
  }

  // Any-hit traversal visits the highest lane entered first. With
  // WideLaneOrder::kByArea the node's lanes hold its children by decreasing
  // box area (ties in the plan's order, the BVH2's), so the smallest box is
  // visited first (wide_bvh_traverse.h says why). With kOcclusion, by
  // increasing hit chance per cost: given that a ray enters children A and
  // B, visiting A first costs C_A + (1 - P_A) C_B, so A goes first when
  // P_A / C_A > P_B / C_B (Ize & Hansen 2011), with P the subtree's hit
  // chance and C its SAH cost per ray entering its box (the dynamic
  // programme's cost of it in one slot).
  void fill_node(std::size_t i) {
    const Plan& p = plans_[i];
    int order[W];  // order[lane]: the plan's child in that lane
    for (int k = 0; k < p.count; ++k) order[k] = k;
    if (lane_order_ == WideLaneOrder::kByArea) {
      float area[W];
      for (int k = 0; k < p.count; ++k) {
        area[k] = bvh2_.nodes[p.kids[k]].bounds.half_area();
        if (std::isnan(area[k])) area[k] = -std::numeric_limits<float>::infinity();
      }
      order_by_decreasing(area, p.count, order);
    } else if (lane_order_ == WideLaneOrder::kOcclusion && hit_chance_) {  // none for a single-leaf tree
      float lowest_first[W];  // minus the chance per cost: decreasing puts the lowest chance in lane 0
      for (int k = 0; k < p.count; ++k) {
        const std::uint32_t kid = p.kids[k];
        const float area = bvh2_.nodes[kid].bounds.half_area();
        const float cost = area > 0.0f ? cost_[kid * W] / area : 1.0f;
        lowest_first[k] = -(hit_chance_[kid] / cost);
        if (std::isnan(lowest_first[k])) lowest_first[k] = std::numeric_limits<float>::infinity();
      }
      order_by_decreasing(lowest_first, p.count, order);
    }
    BBox boxes[W];
    std::uint32_t child[W];
    for (int lane = 0; lane < p.count; ++lane) {
      boxes[lane] = bvh2_.nodes[p.kids[order[lane]]].bounds;
      child[lane] = p.child[order[lane]];
    }
    // Value-initialised first: its padding (W = 4) is zeroed, so equal trees
    // are equal bytes (the nodes array is allocated unwritten).
    WideNode<W>& node = *std::construct_at(&out_.nodes[i]);
    node.bounds = BBoxWide<W>::pack({boxes, static_cast<std::size_t>(p.count)});
    std::fill(node.child, node.child + W, WideBvh<W>::kEmptyChild);
    std::copy(child, child + p.count, node.child);
    order_children(node);
  }

  // Pack i: the triangles chunk * W .. chunk * W + W - 1 of its leaf's BVH2
  // subtree (at most max_leaf_packs * W triangles), in the BVH2's order.
  void fill_pack(std::size_t i) {
    const PackRoot root = pack_roots_[i];
    std::uint32_t ids[W];
    std::uint32_t count = 0, seen = 0;
    const std::uint32_t first = root.chunk * W;
    // A subtree of at most kMaxLeafPacks * W triangles has fewer leaves, so
    // the stack holds at most that many nodes.
    std::uint32_t todo[WideBvh<W>::kMaxLeafPacks * W];
    int top = 0;
    todo[top++] = root.bvh2_node;
    while (top > 0 && count < W) {
      const Bvh2Node& n = bvh2_.nodes[todo[--top]];
      if (n.is_leaf()) {
        for (std::uint32_t k = 0; k < n.prim_count; ++k, ++seen)
          if (seen >= first && count < W) ids[count++] = bvh2_.prim_ids[n.first_index + k];
      } else {
        todo[top++] = n.first_index + 1;
        todo[top++] = n.first_index;
      }
    }
    Triangle tris[W];
    for (std::uint32_t k = 0; k < count; ++k) tris[k] = triangles_[ids[k]];
    const std::span<const Triangle> used(tris, count);
    switch (leaves_) {
      case WideLeaves::kMollerTrumbore: out_.packs[i] = TrianglePack<W>::pack(used); break;
      case WideLeaves::kMollerTrumboreEdges: out_.edge_packs[i] = TriangleEdgePack<W>::pack(used); break;
      case WideLeaves::kVertices:
        if constexpr (W == 8) out_.vertex_packs[i] = TriangleVertices8::pack(used);
        break;
    }
    for (std::uint32_t k = 0; k < W; ++k)
      out_.pack_prims[i * W + k] = k < count ? static_cast<std::int32_t>(ids[k]) : -1;
  }

  const Bvh2& bvh2_;
  std::span<const Triangle> triangles_;
  WideLeaves leaves_;
  WideLaneOrder lane_order_;
  std::uint32_t max_leaf_triangles_;
  WideBvh<W>& out_;
  std::vector<Plan> plans_;
  // BVH2 levels above parallel_depth_ are evaluated as parallel tasks: at
  // most 2^7 of them, in a balanced tree of kTaskNodes / 2 to kTaskNodes
  // nodes each (or larger, past 2^7); trees of fewer than kTaskNodes nodes
  // stay serial; 256 lets a small mesh use both threads, with the builder's
  // smaller grain (bvh2_builder.cpp; measured: docs/notes/kernels-collapse.md).
  static constexpr std::size_t kTaskNodes = 256;
  const int parallel_depth_ =
      std::min(7, static_cast<int>(std::bit_width(bvh2_.nodes.size() / kTaskNodes)));
  std::vector<Slots> slots_;                // per BVH2 node
  std::unique_ptr<float[]> cost_;           // per BVH2 node, W entries: its subtree in at most 1..W slots
  std::unique_ptr<float[]> hit_chance_;     // per BVH2 node, for kOcclusion only: leaf_hit_chance, combined above
  std::vector<PackRoot> pack_roots_;
};

}  // namespace

template <int W>
WideBvh<W> collapse_bvh2(const Bvh2& bvh2, std::span<const Triangle> triangles, WideLeaves leaves,
                         WideLaneOrder lane_order, int max_leaf_packs) {
  if (W != 8 && leaves == WideLeaves::kVertices)
    throw std::invalid_argument("collapse_bvh2: vertex leaves (the watertight test) are 8 wide only");
  if (max_leaf_packs == 0) max_leaf_packs = default_leaf_packs<W>(leaves);
  if (max_leaf_packs < 1 || max_leaf_packs > static_cast<int>(WideBvh<W>::kMaxLeafPacks))
    throw std::invalid_argument("collapse_bvh2: max_leaf_packs " + std::to_string(max_leaf_packs) + " is not in 1.." +
                                std::to_string(WideBvh<W>::kMaxLeafPacks));
  // The watertight traversal tests one pack per leaf (wide_bvh_traverse.h).
  if (leaves == WideLeaves::kVertices && max_leaf_packs != 1)
    throw std::invalid_argument("collapse_bvh2: vertex leaves (the watertight test) hold one pack each");
  WideBvh<W> out;
  if (triangles.empty()) return out;  // no nodes: traversal returns at once
  Collapser<W>(bvh2, triangles, leaves, lane_order, max_leaf_packs, out).run();
  out.bounds = out.nodes[0].bounds.bounds();
  return out;
}

template <int W>
double WideBvh<W>::sah_cost() const {
  if (nodes.empty()) return 0.0;
  const double root_area = bounds.half_area();
  if (!(root_area > 0.0)) return 0.0;
  double cost = root_area;  // the root is always visited
  for (const WideNode<W>& n : nodes)
    for (int lane = 0; lane < W; ++lane) {
      const std::uint32_t child = n.child[lane];
      if (child == kEmptyChild) continue;
      const double tests = (child & kLeafBit) ? pack_count(child) : 1;  // a leaf's packs, or an inner node
      cost += tests * n.bounds.lane(lane).half_area();
    }
  return cost / root_area;
}

template struct WideBvh<4>;
template struct WideBvh<8>;
template WideBvh<4> collapse_bvh2<4>(const Bvh2&, std::span<const Triangle>, WideLeaves, WideLaneOrder, int);
template WideBvh<8> collapse_bvh2<8>(const Bvh2&, std::span<const Triangle>, WideLeaves, WideLaneOrder, int);

}  // namespace raybench
