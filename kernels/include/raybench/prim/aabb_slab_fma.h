// The slab test (aabb_slab.h) with each distance one fused multiply-add:
// t = plane * (1/d) - o * (1/d), with o * (1/d) rounded once per ray, as
// Embree's non-robust box test computes it (its BVH node intersectors'
// "nearX * rdir - org_rdir"). One instruction per plane instead of a
// subtraction and a multiplication: wide BVH traversal (bvh8, bvh4) tests
// every child box of a node this way.
//
// Not the same rounding as Slab: (plane - o) * (1/d) rounds the difference
// first, the fused form rounds o * (1/d) first, which loses more where
// plane and o nearly cancel (a box face near the ray's origin, far from the
// coordinate origin). Neither is conservative; both are "fast".
// For a zero direction component 1/d is infinite and o * (1/d) infinite or
// NaN, and the fused form would turn the exact answer for a ray parallel to
// a slab (aabb_slab.h) into NaN: a ray with any zero component is tested as
// Slab tests it (the Fallback). Which form a ray gets is decided once per
// ray (serves()), so a traversal picks its loop once.
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/prim/aabb.h"
#include "raybench/prim/aabb_slab.h"

namespace raybench {

struct SlabFma {
  static constexpr std::string_view name = "slab_fma";
  static constexpr std::string_view description =
      "slab test, each distance one fused multiply-add on precomputed o/d (Embree's non-robust form); "
      "axis-parallel rays as slab, float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  using Precomputed = Slab::Precomputed;
  static Precomputed precompute(const Ray& ray) { return Slab::precompute(ray); }

  // Whether the ray gets the fused form: every 1/d finite. Others get Slab.
  using Fallback = Slab;
  static bool serves(const Precomputed& r) {
    return std::isfinite(r.inv_dir.x) && std::isfinite(r.inv_dir.y) && std::isfinite(r.inv_dir.z);
  }

  RAYBENCH_INLINE static BoxHit clip(const Precomputed& r, const BBox& box, float tmax) {
    if (!serves(r)) return Fallback::clip(r, box, tmax);
    const Vec3f org_over_dir{r.org.x * r.inv_dir.x, r.org.y * r.inv_dir.y, r.org.z * r.inv_dir.z};
    return clip(r, org_over_dir, org_over_dir, box, tmax);
  }
  // As above with what the fused distances subtract given per axis: near
  // planes t = plane * (1/d) - near[axis], far planes - far[axis]. Here both
  // are o * (1/d); SlabFmaRobust moves them apart (aabb_slab_fma_robust.h).
  RAYBENCH_INLINE static BoxHit clip(const Precomputed& r, const Vec3f& near, const Vec3f& far, const BBox& box,
                                     float tmax) {
    float entry = r.tnear, exit = tmax;
    for (int axis = 0; axis < 3; ++axis) {
      const float near_plane = r.negative[axis] ? box.upper[axis] : box.lower[axis];
      const float far_plane = r.negative[axis] ? box.lower[axis] : box.upper[axis];
      const float t_near = std::fma(near_plane, r.inv_dir[axis], -near[axis]);
      const float t_far = std::fma(far_plane, r.inv_dir[axis], -far[axis]);
      // As Slab::clip: a NaN distance (a NaN plane) is ignored, a NaN bound stays NaN.
      entry = t_near > entry ? t_near : entry;
      exit = t_far < exit ? t_far : exit;
    }
    return {entry, exit};
  }

  RAYBENCH_INLINE static bool intersect(const Precomputed& ray, const BBox& box, float tmax, BoxHit& out) {
    return Slab::report(clip(ray, box, tmax), out);
  }
};

}  // namespace raybench
