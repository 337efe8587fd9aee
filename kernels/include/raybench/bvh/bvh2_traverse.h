// Single-ray traversal of a Bvh2, closest hit and any hit, with the triangle
// test as a template parameter (traversal x primitive composition, as in
// Embree's BVHNIntersector1 and madmann91/bvh's leaf callbacks).
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "raybench/bvh/bvh2.h"
#include "raybench/math/ray.h"

namespace raybench {

// Reciprocal direction, its signs and the ray interval, computed once per ray.
struct RayBoxPrecomputed {
  Vec3f org, inv_dir;
  bool negative[3];
  float tnear, tfar;

  explicit RayBoxPrecomputed(const Ray& r)
      : org(r.org),
        inv_dir{1.0f / r.dir.x, 1.0f / r.dir.y, 1.0f / r.dir.z},
        negative{std::signbit(inv_dir.x), std::signbit(inv_dir.y), std::signbit(inv_dir.z)},
        tnear(r.tnear),
        tfar(r.tfar) {}
};

// Slab test of seed 000 in branchless form (Kay & Kajiya 1986), choosing each
// axis's entry and exit plane by the direction's sign (Williams et al. 2005,
// as in pbrt-v4's Bounds3::IntersectP) rather than by comparing the two
// distances. That choice makes the NaN case safe: a zero direction component
// has an infinite reciprocal, and an origin exactly on that slab's plane gives
// 0 * inf = NaN; the comparisons below keep the previous bound when a
// distance is NaN, so the slab does not constrain a ray lying in the plane of
// a closed box face. An empty box (lower = +inf, upper = -inf) is missed.
// Not conservative: rounding may miss a box the exact ray grazes.
// Returns the entry distance, or +inf when the box is missed within [tnear, tmax].
inline float enter_box(const RayBoxPrecomputed& r, const BBox& b, float tmax) {
  float entry = r.tnear, exit = tmax;
  for (int axis = 0; axis < 3; ++axis) {
    const float near_plane = r.negative[axis] ? b.upper[axis] : b.lower[axis];
    const float far_plane = r.negative[axis] ? b.lower[axis] : b.upper[axis];
    const float t_near = (near_plane - r.org[axis]) * r.inv_dir[axis];
    const float t_far = (far_plane - r.org[axis]) * r.inv_dir[axis];
    entry = t_near > entry ? t_near : entry;
    exit = t_far < exit ? t_far : exit;
  }
  return entry <= exit ? entry : std::numeric_limits<float>::infinity();
}

// The builder bounds the depth (Bvh2BuildOptions::max_sah_depth plus at most
// 32 median halvings), so this stack cannot overflow.
inline constexpr int kBvh2StackSize = 128;

// Visits the tree; `leaf(first, count, tmax)` tests a leaf's primitives and
// returns the new tmax (smaller when it found a closer hit). With AnyHit the
// walk stops as soon as a leaf reports a hit by lowering tmax.
template <bool AnyHit, typename LeafFn>
inline void traverse_bvh2(const Bvh2& bvh, const Ray& ray, LeafFn&& leaf) {
  const RayBoxPrecomputed r(ray);
  float tmax = ray.tfar;
  std::uint32_t stack[kBvh2StackSize];
  int top = 0;
  const Bvh2Node* nodes = bvh.nodes.data();
  if (bvh.prim_ids.empty()) return;  // the root of an empty tree is an empty inner node
  if (enter_box(r, nodes[0].bounds, tmax) == std::numeric_limits<float>::infinity()) return;
  std::uint32_t current = 0;
  for (;;) {
    const Bvh2Node& node = nodes[current];
    if (node.is_leaf()) {
      const float new_tmax = leaf(node.first_index, node.prim_count, tmax);
      if (AnyHit && new_tmax < tmax) return;
      tmax = new_tmax;
    } else {
      const std::uint32_t left = node.first_index, right = left + 1;
      const float t_left = enter_box(r, nodes[left].bounds, tmax);
      const float t_right = enter_box(r, nodes[right].bounds, tmax);
      const bool hit_left = t_left != std::numeric_limits<float>::infinity();
      const bool hit_right = t_right != std::numeric_limits<float>::infinity();
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
template <typename Test>
inline Hit intersect_bvh2(const Bvh2& bvh, std::span<const typename Test::Prepared> prepared, const Ray& ray) {
  Hit hit;
  const auto& ray_data = Test::precompute(ray);
  traverse_bvh2<false>(bvh, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
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
template <typename Test>
inline bool occluded_bvh2(const Bvh2& bvh, std::span<const typename Test::Prepared> prepared, const Ray& ray) {
  bool found = false;
  const auto& ray_data = Test::precompute(ray);
  traverse_bvh2<true>(bvh, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
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
