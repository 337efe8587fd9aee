// An 8-wide BVH collapsed from a Bvh2: each node holds its 8 children's
// bounds structure-of-arrays (BBox8), so one AVX2 slab test visits all of
// them; leaves are Triangle8 packs of up to 8 triangles, tested at once.
// The collapse is the usual greedy one (Wald et al., "Getting Rid of Packets",
// RT 2008; Embree's BVH8 from BVH2): open the child with the largest surface
// area until 8 children or only leaves remain.
// Each node also stores, for each of the 8 direction octants, an order of its
// children from far to near along that octant's diagonal (by box centre), so
// traversal orders the children it enters with one permutation instead of
// sorting their distances: the octant ordering of wide BVHs (Ylitie, Karras,
// Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
// BVHs", HPG 2017; tinybvh's BVH8_CPU does the same on the CPU).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raybench/bvh/bvh2.h"
#include "raybench/simd/box8.h"
#include "raybench/simd/triangle8.h"
#include "raybench/simd/triangle8_watertight.h"

namespace raybench {

// 256 bytes: exactly four cache lines.
struct alignas(64) Bvh8Node {
  BBox8 bounds;             // empty boxes in unused lanes: no ray enters them
  std::uint32_t child[8];   // kEmptyChild, an inner node index, or kLeafBit | pack index
  // far_to_near[octant]: the 8 lanes, 3 bits each, lowest bits first, from the
  // child farthest along the octant's diagonal to the nearest. The octant of a
  // direction is bit a set when its slab test enters axis a by the upper
  // plane (ray_octant).
  std::uint32_t far_to_near[8];
};
static_assert(sizeof(Bvh8Node) == 256);

// A ray's octant: bit a set when the slab test enters axis a by the upper
// plane (a negative direction component, or -0: the sign of 1/d).
inline int ray_octant(const Slab::Precomputed& r) {
  return static_cast<int>(r.negative[0]) | static_cast<int>(r.negative[1]) << 1 | static_cast<int>(r.negative[2]) << 2;
}

// Lane `rank` (0 = farthest) of a node's far-to-near order for `octant`.
inline int far_to_near_lane(const Bvh8Node& node, int octant, int rank) {
  return static_cast<int>(node.far_to_near[octant] >> (3 * rank) & 7u);
}

// What a leaf pack stores: Möller–Trumbore's v0, e1, e2 (Triangle8), or the
// triangles' own vertices for the watertight test (TriangleVertices8: the
// edges must not be rounded, or shared edges would no longer match).
enum class Bvh8Leaves { kMollerTrumbore, kVertices };

struct Bvh8 {
  static constexpr std::uint32_t kLeafBit = 0x80000000u;
  static constexpr std::uint32_t kEmptyChild = 0xffffffffu;

  std::vector<Bvh8Node> nodes;          // nodes[0] is the root
  std::vector<Triangle8> packs;                 // Bvh8Leaves::kMollerTrumbore: up to 8 triangles each
  std::vector<TriangleVertices8> vertex_packs;  // Bvh8Leaves::kVertices: the same packs as vertices
  std::vector<std::int32_t> pack_prims;  // 8 per pack: input triangle index, -1 in unused lanes
  std::size_t depth = 0;                 // levels below the root; bounds the traversal stack

  std::size_t memory_bytes() const {
    return nodes.size() * sizeof(Bvh8Node) + packs.size() * sizeof(Triangle8) +
           vertex_packs.size() * sizeof(TriangleVertices8) + pack_prims.size() * sizeof(std::int32_t);
  }
  // Surface-area-heuristic cost of the 8-wide tree, relative to the root's
  // area: visiting a node (one 8-box test) and testing a pack (one 8-triangle
  // test) cost 1 each, weighted by the area of the box that leads to them.
  // Not comparable with Bvh2::sah_cost, whose units are single tests.
  double sah_cost() const;
};

// Collapses `bvh2` (whose leaves hold at most 8 triangles, as every
// builder of bvh2_builders.h makes them with max_leaf_size 8) over `triangles`.
Bvh8 collapse_to_bvh8(const Bvh2& bvh2, std::span<const Triangle> triangles,
                      Bvh8Leaves leaves = Bvh8Leaves::kMollerTrumbore);

}  // namespace raybench
