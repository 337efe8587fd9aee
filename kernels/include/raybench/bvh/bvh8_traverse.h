// Single-ray traversal of a Bvh8: one 8-wide slab test per node (AVX2, or
// its scalar fallback), children visited nearest first (closest hit) with
// their entry distances kept on the stack so that a subtree farther than the
// current hit is skipped when popped; leaves are tested 8 triangles at once.
// Any hit returns at the first hit in the interval.
// The leaf test and the box test are policies: Bvh8MollerTrumbore or
// Bvh8Watertight (which needs Bvh8Leaves::kVertices), Slab or SlabRobust
// (the conservative test: with the watertight leaves no ray leaks through
// the tree, as bvh2:watertight:robust).
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>

#include "raybench/bvh/bvh8.h"
#include "raybench/math/inline.h"

namespace raybench {

namespace bvh8_detail {
struct StackEntry {
  std::uint32_t ref;
  float entry;
};
// Each level pushes at most 7 entries; Bvh8::depth bounds the levels.
inline constexpr std::size_t kStackPerLevel = 7;
inline constexpr std::size_t kMaxDepth = 128;  // BVH2 depth is bounded by 96 (bvh2_traverse.h)
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
  using bvh8_detail::StackEntry;
  Hit hit;
  if (bvh.nodes.empty()) return hit;
  const Slab::Precomputed r = Slab::precompute(ray);
  const typename Leaf::RayData leaf_ray = Leaf::precompute(ray);
  // A popped subtree farther than the current hit is skipped; the robust
  // test compares with the padded bound, so it never skips what it entered.
  const auto reachable = [](float entry, float tmax) {
    if constexpr (std::is_same_v<BoxTest, SlabRobust>) return entry <= tmax + std::fabs(tmax) * SlabRobust::kPad;
    else return entry <= tmax;
  };
  float tmax = ray.tfar;
  StackEntry stack[bvh8_detail::kStackPerLevel * bvh8_detail::kMaxDepth + 8];
  int top = 0;
  stack[top++] = {0, r.tnear};
  while (top > 0) {
    const StackEntry e = stack[--top];
    if (!reachable(e.entry, tmax)) continue;  // a hit closer than this subtree was found meanwhile
    if (e.ref & Bvh8::kLeafBit) {
      const std::uint32_t pack = e.ref & ~Bvh8::kLeafBit;
      TriangleHit th;
      const int lane = Leaf::intersect(leaf_ray, tmax, bvh, pack, th);
      if (lane >= 0) {
        tmax = th.t;
        hit = {th.t, bvh.pack_prims[8 * pack + static_cast<std::uint32_t>(lane)], th.u, th.v};
        if (AnyHit) return hit;
      }
      continue;
    }
    const Bvh8Node& node = bvh.nodes[e.ref];
    alignas(32) float entry[8];
    unsigned mask = intersect8<BoxTest>(r, tmax, node.bounds, entry);
    if constexpr (AnyHit) {
      // Any hit will do: no ordering by distance, but leaves go on top, so
      // they are tested before any inner node is opened (a hit ends the walk).
      for (unsigned inner = mask; inner; inner &= inner - 1) {
        const int lane = __builtin_ctz(inner);
        if (!(node.child[lane] & Bvh8::kLeafBit)) stack[top++] = {node.child[lane], entry[lane]};
      }
      for (unsigned leaves = mask; leaves; leaves &= leaves - 1) {
        const int lane = __builtin_ctz(leaves);
        if (node.child[lane] & Bvh8::kLeafBit) stack[top++] = {node.child[lane], entry[lane]};
      }
      continue;
    }
    // Push the hit children farthest first, so the nearest is popped next
    // (insertion into a small sorted run on top of the stack).
    const int base = top;
    for (; mask; mask &= mask - 1) {
      const int lane = __builtin_ctz(mask);
      const StackEntry child{node.child[lane], entry[lane]};
      int i = top++;
      while (i > base && stack[i - 1].entry < child.entry) {
        stack[i] = stack[i - 1];
        --i;
      }
      stack[i] = child;
    }
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
