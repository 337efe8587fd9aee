// Single-ray traversal of a Bvh2, closest hit and any hit, with the triangle
// test and the box test as template parameters (traversal x primitive
// composition, as in Embree's BVHNIntersector1 and madmann91/bvh's leaf
// callbacks). The box test is Slab (prim/aabb_slab.h), or SlabRobust for a
// conservative traversal that never culls a box the exact ray touches.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "raybench/bvh/bvh2.h"
#include "raybench/math/ray.h"
#include "raybench/prim/aabb_slab.h"

namespace raybench {

// The builder bounds the depth (Bvh2BuildOptions::max_sah_depth plus at most
// 32 median halvings), so this stack cannot overflow.
inline constexpr int kBvh2StackSize = 128;

// Visits the tree; `leaf(first, count, tmax)` tests a leaf's primitives and
// returns the new tmax (smaller when it found a closer hit). With AnyHit the
// walk stops as soon as a leaf reports a hit by lowering tmax.
template <bool AnyHit, typename BoxTest = Slab, typename LeafFn>
inline void traverse_bvh2(const Bvh2& bvh, const Ray& ray, LeafFn&& leaf) {
  if (bvh.prim_ids.empty()) return;  // the root of an empty tree is an empty inner node
  const typename BoxTest::Precomputed r = BoxTest::precompute(ray);
  constexpr float kMissed = std::numeric_limits<float>::infinity();
  const auto enter = [&](const BBox& box, float tmax) {
    BoxHit h;
    return BoxTest::intersect(r, box, tmax, h) ? h.t_entry : kMissed;
  };
  float tmax = ray.tfar;
  std::uint32_t stack[kBvh2StackSize];
  int top = 0;
  const Bvh2Node* nodes = bvh.nodes.data();
  if (enter(nodes[0].bounds, tmax) == kMissed) return;
  std::uint32_t current = 0;
  for (;;) {
    const Bvh2Node& node = nodes[current];
    if (node.is_leaf()) {
      const float new_tmax = leaf(node.first_index, node.prim_count, tmax);
      if (AnyHit && new_tmax < tmax) return;
      tmax = new_tmax;
    } else {
      const std::uint32_t left = node.first_index, right = left + 1;
      const float t_left = enter(nodes[left].bounds, tmax);
      const float t_right = enter(nodes[right].bounds, tmax);
      const bool hit_left = t_left != kMissed, hit_right = t_right != kMissed;
      if (hit_left && hit_right) {
        // Nearest child first; the other waits on the stack.
        const bool left_first = t_left <= t_right;
        stack[top++] = left_first ? right : left;
        current = left_first ? left : right;
        continue;
      }
      if (hit_left || hit_right) {
        current = hit_left ? left : right;
        continue;
      }
    }
    if (top == 0) return;
    current = stack[--top];
  }
}

// Closest hit against triangles prepared for Test, stored in leaf order.
template <typename Test, typename BoxTest = Slab>
inline Hit intersect_bvh2(const Bvh2& bvh, std::span<const typename Test::Prepared> prepared, const Ray& ray) {
  Hit hit;
  const auto& ray_data = Test::precompute(ray);
  traverse_bvh2<false, BoxTest>(bvh, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
    for (std::uint32_t i = first; i < first + count; ++i) {
      TriangleHit th;
      if (Test::intersect(ray_data, tmax, prepared[i], th)) {
        tmax = th.t;
        hit = {th.t, static_cast<std::int32_t>(bvh.prim_ids[i]), th.u, th.v};
      }
    }
    return tmax;
  });
  return hit;
}

// Any hit in the ray's interval: the occlusion query of shadow rays.
template <typename Test, typename BoxTest = Slab>
inline bool occluded_bvh2(const Bvh2& bvh, std::span<const typename Test::Prepared> prepared, const Ray& ray) {
  bool found = false;
  const auto& ray_data = Test::precompute(ray);
  traverse_bvh2<true, BoxTest>(bvh, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
    for (std::uint32_t i = first; i < first + count; ++i) {
      TriangleHit th;
      if (Test::intersect(ray_data, tmax, prepared[i], th)) {
        found = true;
        return -std::numeric_limits<float>::infinity();
      }
    }
    return tmax;
  });
  return found;
}

}  // namespace raybench
