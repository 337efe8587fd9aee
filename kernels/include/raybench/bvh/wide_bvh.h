// Wide BVHs collapsed from a Bvh2: WideBvh<8> (Bvh8) and WideBvh<4> (Bvh4).
// Each node holds its W children's bounds structure-of-arrays (BBoxWide), so
// one SIMD slab test visits all of them; a leaf is one or more consecutive
// TrianglePack<W>s of up to W triangles each, a pack tested at once.
// The collapse chooses, among all wide trees whose nodes are cuts of the
// BVH2, the one of least SAH cost (sah_cost below), by the dynamic programme
// of Ylitie, Karras & Laine (HPG 2017); any BVH2 subtree of at most W
// triangles may become a pack.
// Each node also stores, for each of the 8 direction octants, an order of its
// children from far to near along that octant's diagonal (by box centre), so
// traversal orders the children it enters with one permutation instead of
// sorting their distances: the octant ordering of wide BVHs (Ylitie, Karras,
// Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
// BVHs", HPG 2017; tinybvh's BVH8_CPU does the same on the CPU).
#pragma once

#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "raybench/bvh/bvh2.h"
#include "raybench/bvh/huge_pages.h"
#include "raybench/simd/triangle8_watertight.h"
#include "raybench/simd/wide_box.h"
#include "raybench/simd/wide_triangle.h"

namespace raybench {

// 256 bytes for W = 8, 128 for W = 4: whole cache lines.
template <int W>
struct alignas(64) WideNode {
  static_assert(W == 4 || W == 8);
  // Bits per lane index in far_to_near.
  static constexpr int kOrderBits = W == 8 ? 3 : 2;
  using Order = std::conditional_t<W == 8, std::uint32_t, std::uint8_t>;

  BBoxWide<W> bounds;       // empty boxes in unused lanes: no ray enters them
  // kEmptyChild, an inner node index, or a leaf (WideBvh::leaf_ref), in the
  // collapse's WideLaneOrder, empty lanes last (the any-hit traversal's order).
  std::uint32_t child[W];
  // far_to_near[octant]: the W lanes, kOrderBits each, lowest bits first, from
  // the child farthest along the octant's diagonal to the nearest. The octant
  // of a direction is bit a set when its slab test enters axis a by the upper
  // plane (ray_octant).
  Order far_to_near[8];
};
static_assert(sizeof(WideNode<8>) == 256 && sizeof(WideNode<4>) == 128);

// A ray's octant: bit a set when the slab test enters axis a by the upper
// plane (a negative direction component, or -0: the sign of 1/d).
inline int ray_octant(const Slab::Precomputed& r) {
  return static_cast<int>(r.negative[0]) | static_cast<int>(r.negative[1]) << 1 | static_cast<int>(r.negative[2]) << 2;
}

// Lane `rank` (0 = farthest) of a node's far-to-near order for `octant`.
template <int W>
inline int far_to_near_lane(const WideNode<W>& node, int octant, int rank) {
  constexpr int bits = WideNode<W>::kOrderBits;
  return static_cast<int>(static_cast<std::uint32_t>(node.far_to_near[octant]) >> (bits * rank) & ((1u << bits) - 1));
}

// What a leaf pack stores: Möller–Trumbore's v0, e1, e2 and normal
// (TrianglePack), the same without the normal, recomputed per test
// (TriangleEdgePack: a quarter less memory), or the triangles' own vertices
// and normals for the watertight test (TriangleVertices8, 8-wide only: the
// edges must not be rounded, or shared edges would no longer match).
enum class WideLeaves { kMollerTrumbore, kMollerTrumboreEdges, kVertices };

// The order of a node's children in its lanes, which is the order any-hit
// traversal visits them in (wide_bvh_traverse.h), the highest lane first:
// - kByArea: by decreasing box area, so the smallest box is visited first;
// - kBvh2: the BVH2's own order (left before right);
// - kOcclusion: by increasing hit chance per cost, so the child most likely
//   to end an occlusion ray for the least work is visited first (the
//   termination order of Ize & Hansen, "RTSAH Traversal Order for Occlusion
//   Rays", EG 2011; wide_bvh_collapse.cpp estimates both per subtree).
enum class WideLaneOrder { kByArea, kBvh2, kOcclusion };

template <int W>
struct WideBvh {
  static constexpr int kWidth = W;
  // A child that is a leaf: kLeafBit | (packs - 1) << kPackCountShift |
  // first pack; its packs are consecutive, tested in order.
  static constexpr std::uint32_t kLeafBit = 0x80000000u;
  static constexpr int kPackCountShift = 28;
  static constexpr std::uint32_t kMaxLeafPacks = 8;                            // what the 3 count bits hold
  static constexpr std::uint32_t kMaxPacks = 1u << kPackCountShift;           // pack indices below it
  static constexpr std::uint32_t kEmptyChild = 0xffffffffu;
  static constexpr std::uint32_t leaf_ref(std::uint32_t first_pack, std::uint32_t packs) {
    return kLeafBit | (packs - 1) << kPackCountShift | first_pack;
  }
  static constexpr std::uint32_t first_pack(std::uint32_t leaf) { return leaf & (kMaxPacks - 1); }
  static constexpr std::uint32_t pack_count(std::uint32_t leaf) { return (leaf >> kPackCountShift & 7u) + 1; }

  HugePageVector<WideNode<W>> nodes;               // nodes[0] is the root
  HugePageVector<TrianglePack<W>> packs;           // WideLeaves::kMollerTrumbore: up to W triangles each
  HugePageVector<TriangleEdgePack<W>> edge_packs;  // WideLeaves::kMollerTrumboreEdges: the same packs without normals
  HugePageVector<TriangleVertices8> vertex_packs;  // WideLeaves::kVertices (W = 8): the same packs as vertices
  HugePageVector<std::int32_t> pack_prims;         // W per pack, at slot(): input triangle index, -1 in unused lanes
                                                   // (vertex packs carry a copy)
  std::size_t depth = 0;                        // levels below the root; bounds the traversal stack
  // The union of the root's child boxes, which contain every box below them:
  // the extent of every plane a ray is tested against (SlabFmaRobust's).
  BBox bounds;

  // Where a pack's lane is in pack_prims (its pack slot).
  static std::uint32_t slot(std::uint32_t pack, int lane) { return W * pack + static_cast<std::uint32_t>(lane); }

  std::size_t memory_bytes() const {
    return nodes.size() * sizeof(WideNode<W>) + packs.size() * sizeof(TrianglePack<W>) +
           edge_packs.size() * sizeof(TriangleEdgePack<W>) + vertex_packs.size() * sizeof(TriangleVertices8) +
           pack_prims.size() * sizeof(std::int32_t);
  }
  // Surface-area-heuristic cost of the wide tree, relative to the root's
  // area: visiting a node (one W-box test) and testing a pack (one W-triangle
  // test) cost 1 each, weighted by the area of the box that leads to them
  // (a leaf's box for each of its packs).
  // Not comparable with Bvh2::sah_cost, whose units are single tests.
  double sah_cost() const;
};
using Bvh8 = WideBvh<8>;
using Bvh4 = WideBvh<4>;

// Leaves of up to this many packs by default: 4 for the 8-wide tree's
// Möller-Trumbore leaves (up to 32 triangles; Embree's BVH8 leaves hold up
// to 28, in blocks of 4); one for the watertight vertex leaves, whose
// traversal the multi-pack leaf step slows by more than their tree gains,
// and for the 4-wide tree (not measured with more). Measured (eight scenes,
// every ray kind): docs/notes/kernels-collapse.md.
template <int W>
constexpr int default_leaf_packs(WideLeaves leaves) {
  return W == 8 && leaves != WideLeaves::kVertices ? 4 : 1;
}

// Collapses `bvh2` (whose leaves hold at most W triangles, as every builder
// of bvh2_builders.h makes them with max_leaf_size W) over `triangles`, into
// the wide tree of least sah_cost() among those whose nodes are cuts of it
// and whose leaves hold at most max_leaf_packs packs (1 to kMaxLeafPacks, 0
// for default_leaf_packs; a BVH2 subtree of n triangles becomes
// ceil(n / W) packs, filled in the BVH2's order). WideLeaves::kVertices
// needs W = 8 and one pack per leaf (std::invalid_argument otherwise, as
// for max_leaf_packs out of range).
template <int W>
WideBvh<W> collapse_bvh2(const Bvh2& bvh2, std::span<const Triangle> triangles,
                         WideLeaves leaves = WideLeaves::kMollerTrumbore,
                         WideLaneOrder lane_order = WideLaneOrder::kByArea, int max_leaf_packs = 0);

}  // namespace raybench
