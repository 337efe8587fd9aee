// Conservative ray-AABB slab test with its padding folded into the ray: as
// SlabRobust (aabb_slab_robust.h), never misses a box that the exact ray
// touches within [tnear, tmax], but at no cost per box.
//
// Source: Ize, "Robust BVH Ray Traversal", JCGT 2(2) 2013, which scales the
// far planes' reciprocal direction once per ray instead of padding every
// exit. SlabRobust pads each box's exit (exit + |exit| * 8u): three more
// operations on the box test's critical path, measured at about 10 % of
// bvh8:watertight. Here the far planes' distances use
// fl(fl(1/d) * (1 + 8u)), computed once per ray, and tmax is padded as
// SlabRobust pads an exit (once per node in a traversal, off the box
// test's path).
//
// Error bound, for tnear >= 0 (u = 2^-24, gamma(n) as in aabb_slab_robust.h).
// If the exact ray touches the box, its exact entry a = max(tnear, y_j) and
// exit b = min(tmax, x_i) satisfy 0 <= a <= b, so every far distance x_i
// and tmax are >= b >= 0. A near distance is computed <= y_j (1 + gamma(3))
// when y_j >= 0 and < 0 <= tnear otherwise, so the computed entry is
// <= a (1 + gamma(3)) <= b (1 + gamma(3)). A far distance x_i >= 0 has
// (plane - o) and 1/d of one sign, and four roundings (1/d, the scaling,
// the subtraction, the product) leave it
//   >= x_i (1 + 8u) (1 - u)^4 >= x_i (1 + 4u - 32u^2) >= x_i (1 + gamma(3)),
// and the padded tmax >= tmax (1 + 8u) (1 - u)^2 >= tmax (1 + gamma(3)).
// So the computed exit >= b (1 + gamma(3)) >= the computed entry. With
// tnear < 0 a far distance may be negative and the scaling would shorten
// it, so such rays take SlabRobust's exit padding instead (every backend
// raises tnear to 0, as Embree's box tests do: with_nonnegative_tnear). The
// same conditions on overflow and underflow hold as for SlabRobust.
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/prim/aabb.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_robust.h"

namespace raybench {

struct SlabRobustRay {
  static constexpr std::string_view name = "slab_robust_ray";
  static constexpr std::string_view description =
      "slab test made conservative per ray: far planes scaled by 1/d rounded outward, tmax padded (Ize 2013), "
      "never misses, float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kConservative;

  // 1 + 8u, exactly a float: the far planes' reciprocal scale.
  static constexpr float kFarScale = 1.0f + SlabRobust::kPad;

  using Precomputed = Slab::Precomputed;
  static Precomputed precompute(const Ray& ray) { return Slab::precompute(ray); }

  // Whether the folded padding holds for this ray (tnear >= 0; false for an
  // invalid ray's NaN, which SlabRobust misses as well). Others get SlabRobust.
  using Fallback = SlabRobust;
  static bool serves(const Precomputed& ray) { return ray.tnear >= 0.0f; }
  static float far_inv_dir(float inv_dir) { return inv_dir * kFarScale; }

  // On a hit, t_entry is as computed and t_exit may exceed the exact exit
  // by a few ulps. A traversal computes the scaled reciprocals once per ray
  // (RayLanes); here they are recomputed per box.
  RAYBENCH_INLINE static bool intersect(const Precomputed& ray, const BBox& box, float tmax, BoxHit& out) {
    if (!serves(ray)) return Fallback::intersect(ray, box, tmax, out);
    const Vec3f far{far_inv_dir(ray.inv_dir.x), far_inv_dir(ray.inv_dir.y), far_inv_dir(ray.inv_dir.z)};
    return Slab::report(Slab::clip(ray, far, box, SlabRobust::padded(tmax)), out);
  }
};

}  // namespace raybench
