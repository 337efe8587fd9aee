// A binary BVH over every primitive of a scene with analytic ones (issue 31):
// triangles, spheres, boxes and oriented boxes in one tree, built by the
// binned SAH builder over their boxes (PrimitiveSpans::bounds), traversed by
// traverse_bvh2 as the triangle-only tree is. A leaf slot holds a reference
// (mixed_leaf.h): a triangle, prepared for the backend's triangle test in
// leaf order as the triangle-only tree stores it, or an analytic primitive
// judged by its surface test (SpherePrecise, Slab, Obb, or the seed-faithful
// ones: AnalyticTestChoice).
// Cost against the triangle-only tree: 4 bytes of reference per leaf slot
// and one branch on the primitive's kind per test.
// Guarantee: with a conservative box test (SlabRobust) the answers are those
// of the same tests over every primitive whose box the ray touches: the
// closest hit has the least t any of them reports (the last one tested on
// equal t), occlusion is whether any reports a hit. Hits keep global prim ids
// (PrimitiveSpans: triangles, spheres, boxes, oriented boxes); analytic hits
// have u = v = 0.
// Only the binned SAH builder takes primitive boxes; a tree may then be
// optimised by reinsertion, which moves nodes, not primitives.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "raybench/bvh/bvh2.h"
#include "raybench/bvh/bvh2_reinsertion.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "raybench/bvh/mixed_leaf.h"

namespace raybench {

template <typename Test>
struct MixedBvh2 {
  Bvh2 bvh;                                        // over every primitive's box; prim_ids are global ids
  std::vector<std::uint32_t> refs;                 // leaf order: each slot's mixed_ref
  std::vector<typename Test::Prepared> triangles;  // the triangles in leaf order, prepared for Test
  AnalyticLeafPrims analytic;                      // the analytic primitives in leaf order, and their tests

  std::size_t memory_bytes() const {
    return bvh.memory_bytes() + refs.size() * sizeof(std::uint32_t) + triangles.size() * sizeof(typename Test::Prepared) +
           analytic.memory_bytes();
  }
};

// The tree over every primitive of `prims` (binned SAH over their boxes,
// then options.reinsertion's reinsertion), its leaves judged by Test
// and the analytic tests `tests`. Throws std::length_error for more than
// kMaxMixedPrimsPerKind primitives of one kind.
template <typename Test>
MixedBvh2<Test> build_mixed_bvh2(const PrimitiveSpans& prims, const Bvh2BuildOptions& options = {},
                                 AnalyticTestChoice tests = {}) {
  for (std::size_t n : {prims.triangles.size(), prims.spheres.size(), prims.boxes.size(), prims.obbs.size()})
    if (n > kMaxMixedPrimsPerKind) throw std::length_error("build_mixed_bvh2: too many primitives of one kind");
  MixedBvh2<Test> m;
  m.bvh = build_bvh2_binned_sah(std::span<const BBox>(primitive_bounds(prims)), options);
  optimize_bvh2_after_build(m.bvh, options);
  m.analytic.tests = tests;
  m.refs.reserve(m.bvh.prim_ids.size());
  m.triangles.reserve(prims.triangles.size());
  for (std::uint32_t id : m.bvh.prim_ids) {
    if (prims.kind(id) == PrimitiveKind::kTriangle) {
      m.refs.push_back(mixed_ref(PrimitiveKind::kTriangle, m.triangles.size()));
      m.triangles.push_back(Test::prepare(prims.triangles[id]));
    } else {
      m.refs.push_back(m.analytic.add(prims, id));
    }
  }
  return m;
}

// Tests the leaf slots [first, first + count) for a hit in (tnear, tmax];
// on_hit(slot, t, u, v) is told of each hit closer than the last and
// returns false to stop. Returns the last hit's t, or tmax.
template <typename Test, typename OnHit>
inline float intersect_mixed_slots(const MixedBvh2<Test>& m, const auto& triangle_ray, const AnalyticRay& analytic_ray,
                                   std::uint32_t first, std::uint32_t count, float tmax, OnHit&& on_hit) {
  for (std::uint32_t i = first; i < first + count; ++i) {
    const std::uint32_t ref = m.refs[i];
    if (mixed_ref_kind(ref) == PrimitiveKind::kTriangle) {
      TriangleHit th;
      if (!Test::intersect(triangle_ray, tmax, m.triangles[mixed_ref_index(ref)], th)) continue;
      tmax = th.t;
      if (!on_hit(i, th.t, th.u, th.v)) return tmax;
    } else {
      float t;
      if (!m.analytic.intersect(analytic_ray, tmax, ref, t)) continue;
      tmax = t;
      if (!on_hit(i, t, 0.0f, 0.0f)) return tmax;
    }
  }
  return tmax;
}

// Closest hit over every primitive.
template <typename Test, typename BoxTest = Slab>
inline Hit intersect_mixed_bvh2(const MixedBvh2<Test>& m, const Ray& ray) {
  Hit hit;
  const auto& triangle_ray = Test::precompute(ray);
  const AnalyticRay analytic_ray = AnalyticRay::precompute(ray);
  traverse_bvh2<false, BoxTest>(m.bvh, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
    return intersect_mixed_slots(m, triangle_ray, analytic_ray, first, count, tmax,
                                 [&](std::uint32_t slot, float t, float u, float v) {
                                   hit = {t, static_cast<std::int32_t>(m.bvh.prim_ids[slot]), u, v};
                                   return true;
                                 });
  });
  return hit;
}

// Any hit in the ray's interval.
template <typename Test, typename BoxTest = Slab>
inline bool occluded_mixed_bvh2(const MixedBvh2<Test>& m, const Ray& ray) {
  bool found = false;
  const auto& triangle_ray = Test::precompute(ray);
  const AnalyticRay analytic_ray = AnalyticRay::precompute(ray);
  traverse_bvh2<true, BoxTest>(m.bvh, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
    intersect_mixed_slots(m, triangle_ray, analytic_ray, first, count, tmax, [&](std::uint32_t, float, float, float) {
      found = true;
      return false;
    });
    return found ? -std::numeric_limits<float>::infinity() : tmax;
  });
  return found;
}

}  // namespace raybench
