// Single-ray traversal of a Bvh8: one 8-wide slab test per node (AVX2, or
// its scalar fallback); the children entered are pushed in the node's stored
// far-to-near order for the ray's octant (Bvh8Node::far_to_near), so the
// nearest is popped next, without sorting distances: with AVX2 one
// permutation orders them and a table-driven compaction pushes them with two
// stores, branch-free. Their entry distances go on the stack too, so a subtree
// farther than the current hit is skipped when popped. Leaves are tested 8
// triangles at once. Any hit returns at the first hit in the interval, and
// pushes leaves above inner nodes so that they are tested first.
// The leaf test and the box test are policies: Bvh8MollerTrumbore or
// Bvh8Watertight (which needs Bvh8Leaves::kVertices), Slab or SlabRobust
// (the conservative test: with the watertight leaves no ray leaks through
// the tree, as bvh2:watertight:robust).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "raybench/bvh/bvh8.h"
#include "raybench/math/inline.h"

namespace raybench {

namespace bvh8_detail {
// Each level pushes at most 7 entries beyond the one popped next; Bvh8::depth
// bounds the levels. The 8-wide pushes store 8 entries whatever their count.
inline constexpr std::size_t kStackPerLevel = 7;
inline constexpr std::size_t kMaxDepth = 128;  // BVH2 depth is bounded by 96 (bvh2_traverse.h)
inline constexpr std::size_t kStackSize = kStackPerLevel * kMaxDepth + 16;

// The traversal stack, structure-of-arrays: node references and the entry
// distance of each.
struct Stack {
  alignas(32) std::uint32_t ref[kStackSize];
  alignas(32) float entry[kStackSize];
  int top = 0;
};

// Pushes the children of `node` in `lanes` (bit i: lane i) in the node's
// far-to-near order for `octant`, lane by lane: the scalar form of the
// compacted AVX2 push below, same order.
inline void push_far_to_near_scalar(Stack& stack, const Bvh8Node& node, int octant, unsigned lanes,
                                    const float entry[8]) {
  for (int rank = 0; rank < 8; ++rank) {
    const int lane = far_to_near_lane(node, octant, rank);
    if (!(lanes >> lane & 1u)) continue;
    stack.ref[stack.top] = node.child[lane];
    stack.entry[stack.top] = entry[lane];
    ++stack.top;
  }
}

#if defined(__AVX2__)
// kCompactLanes[mask]: the set bits of mask in increasing order, 4 bits each,
// lowest first: the permutation that packs the selected lanes to the front.
inline constexpr std::array<std::uint32_t, 256> kCompactLanes = [] {
  std::array<std::uint32_t, 256> table{};
  for (unsigned mask = 0; mask < 256; ++mask) {
    int k = 0;
    for (unsigned lane = 0; lane < 8; ++lane)
      if (mask >> lane & 1u) table[mask] |= lane << (4 * k++);
  }
  return table;
}();

// Unpacks 8 fields of `bits` bits each from `packed` into the 8 lanes.
template <int Bits>
inline __m256i unpack_lanes(std::uint32_t packed) {
  const __m256i shifts = _mm256_setr_epi32(0, Bits, 2 * Bits, 3 * Bits, 4 * Bits, 5 * Bits, 6 * Bits, 7 * Bits);
  return _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(static_cast<int>(packed)), shifts), _mm256_set1_epi32(7));
}

// Pushes the lanes of `refs`/`entry` selected by `lanes`, keeping their order.
inline void push_compacted(Stack& stack, __m256i refs, __m256 entry, unsigned lanes) {
  const __m256i pick = unpack_lanes<4>(kCompactLanes[lanes]);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.ref + stack.top), _mm256_permutevar8x32_epi32(refs, pick));
  _mm256_storeu_ps(stack.entry + stack.top, _mm256_permutevar8x32_ps(entry, pick));
  stack.top += __builtin_popcount(lanes);
}
#endif
}  // namespace bvh8_detail

struct Bvh8MollerTrumbore {
  static constexpr Bvh8Leaves kLeaves = Bvh8Leaves::kMollerTrumbore;  // what collapse_to_bvh8 must store
  using RayData = Ray;
  static RayData precompute(const Ray& ray) { return ray; }
  static int intersect(const RayData& ray, float tmax, const Bvh8& bvh, std::uint32_t pack, TriangleHit& out) {
    return intersect8(ray, tmax, bvh.packs[pack], out);
  }
};

struct Bvh8Watertight {
  static constexpr Bvh8Leaves kLeaves = Bvh8Leaves::kVertices;
  using RayData = WatertightTriangle::RayData;
  static RayData precompute(const Ray& ray) { return WatertightTriangle::precompute(ray); }
  static int intersect(const RayData& ray, float tmax, const Bvh8& bvh, std::uint32_t pack, TriangleHit& out) {
    return intersect8_watertight(ray, tmax, bvh.vertex_packs[pack], out);
  }
};

template <bool AnyHit, typename Leaf = Bvh8MollerTrumbore, typename BoxTest = Slab>
inline Hit traverse_bvh8(const Bvh8& bvh, const Ray& ray) {
  Hit hit;
  if (bvh.nodes.empty()) return hit;
  const Slab::Precomputed r = Slab::precompute(ray);
  const int octant = ray_octant(r);
  const typename Leaf::RayData leaf_ray = Leaf::precompute(ray);
  // A popped subtree farther than the current hit is skipped; the robust
  // test compares with the padded bound, so it never skips what it entered.
  const auto reachable = [](float entry, float tmax) {
    if constexpr (std::is_same_v<BoxTest, SlabRobust>) return entry <= tmax + std::fabs(tmax) * SlabRobust::kPad;
    else return entry <= tmax;
  };
  float tmax = ray.tfar;
  bvh8_detail::Stack stack;
  stack.ref[0] = 0;
  stack.entry[0] = r.tnear;
  stack.top = 1;
  while (stack.top > 0) {
    --stack.top;
    const std::uint32_t ref = stack.ref[stack.top];
    if (!reachable(stack.entry[stack.top], tmax)) continue;  // a hit closer than this subtree was found meanwhile
    if (ref & Bvh8::kLeafBit) {
      const std::uint32_t pack = ref & ~Bvh8::kLeafBit;
      TriangleHit th;
      const int lane = Leaf::intersect(leaf_ray, tmax, bvh, pack, th);
      if (lane >= 0) {
        tmax = th.t;
        hit = {th.t, bvh.pack_prims[8 * pack + static_cast<std::uint32_t>(lane)], th.u, th.v};
        if (AnyHit) return hit;
      }
      continue;
    }
    const Bvh8Node& node = bvh.nodes[ref];
#if defined(__AVX2__)
    // Permute the node's lanes into far-to-near order, then push the entered
    // ones compacted (for any hit: inner nodes first, leaves on top; the leaf
    // bit is the sign bit, so movemask finds them).
    const Box8Hits box = slab8_avx2<BoxTest>(r, tmax, node.bounds);
    const __m256i order = bvh8_detail::unpack_lanes<3>(node.far_to_near[octant]);
    const auto entered = static_cast<unsigned>(_mm256_movemask_ps(_mm256_permutevar8x32_ps(box.hit, order)));
    if (!entered) continue;
    const __m256i refs =
        _mm256_permutevar8x32_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(node.child)), order);
    const __m256 entry = _mm256_permutevar8x32_ps(box.t_entry, order);
    if constexpr (AnyHit) {
      const auto leaves = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(refs)));
      bvh8_detail::push_compacted(stack, refs, entry, entered & ~leaves);
      bvh8_detail::push_compacted(stack, refs, entry, entered & leaves);
    } else {
      bvh8_detail::push_compacted(stack, refs, entry, entered);
    }
#else
    alignas(32) float entry[8];
    const unsigned entered = intersect8<BoxTest>(r, tmax, node.bounds, entry);
    if constexpr (AnyHit) {
      unsigned leaves = 0;
      for (int lane = 0; lane < 8; ++lane) leaves |= static_cast<unsigned>((node.child[lane] & Bvh8::kLeafBit) != 0) << lane;
      bvh8_detail::push_far_to_near_scalar(stack, node, octant, entered & ~leaves, entry);
      bvh8_detail::push_far_to_near_scalar(stack, node, octant, entered & leaves, entry);
    } else {
      bvh8_detail::push_far_to_near_scalar(stack, node, octant, entered, entry);
    }
#endif
  }
  return hit;
}

template <typename Leaf = Bvh8MollerTrumbore, typename BoxTest = Slab>
inline Hit intersect_bvh8(const Bvh8& bvh, const Ray& ray) {
  return traverse_bvh8<false, Leaf, BoxTest>(bvh, ray);
}
template <typename Leaf = Bvh8MollerTrumbore, typename BoxTest = Slab>
inline bool occluded_bvh8(const Bvh8& bvh, const Ray& ray) {
  return traverse_bvh8<true, Leaf, BoxTest>(bvh, ray).hit();
}

}  // namespace raybench
