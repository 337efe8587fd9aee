// Conservative ray-AABB slab test: never misses a box that the exact ray
// (the float inputs taken as exact reals) touches within [tnear, tmax].
//
// Sources: Williams et al., "An Efficient and Robust Ray-Box Intersection
// Algorithm", JGT 2005 (sign-chosen planes, as in aabb_slab.h); Ize, "Robust
// BVH Ray Traversal", JCGT 2(2) 2013 (pad the exit by the rounding error);
// pbrt-v4's Bounds3::IntersectP (`tFar *= 1 + 2 * gamma(3)`). Same
// arithmetic as Slab (aabb_slab.h), then the exit is padded once.
//
// Error bound. Let u = 2^-24 (float unit roundoff) and
// gamma(n) = n u / (1 - n u) (Higham; pbrt-v4's gamma). Each distance
// t = (plane - o) * fl(1/d) is three roundings away from the exact
// (plane - o) / d, so t = x (1 + theta) with |theta| <= gamma(3):
//   computed near <= x + gamma(3) |x|,   computed far >= x - gamma(3) |x|.
// Both maps are increasing, so they carry over to entry = max(tnear, near_i)
// and exit = min(tmax, far_i) (tnear and tmax are exact). If the exact ray
// touches the box, exact entry a <= exact exit b, and the padded exit
//   exit' = fl(exit + |exit| * 2^-21)     (2^-21 = 8u)
// satisfies exit' >= computed entry:
//   b >= 0: exit' >= b (1 - gamma(3)) (1 + 8u) (1 - u) >= b (1 + gamma(3)) >= entry
//   b <  0: exit' >= b (1 + gamma(3)) (1 - 8u) (1 + u) >= b (1 - gamma(3)) >= entry
// (the first products are 1 + 4u - O(u^2) >= 1 + 3u + O(u^2), and
// 1 - 4u + O(u^2) <= 1 - 3u - O(u^2)). pbrt-v4 multiplies by
// 1 + 2 gamma(3) ~ 1 + 6u, which covers the six roundings on both sides but
// not the rounding of that product itself (worst case ~ 1 + 7u needed), and
// which tightens a negative exit (pbrt's t's are >= 0; here tnear is as
// given and may be negative). 8u = 2 gamma(4) rounded to float.
//
// The bound holds when nothing overflows or underflows: every nonzero
// direction component with 2^-126 <= |d| <= 2^126 (1/d a normal float) and
// distances that are neither subnormal nor beyond FLT_MAX (a box only
// reachable at t > FLT_MAX is missed). A zero component involves no
// rounding: its distances are exactly +-inf, or NaN (origin on the plane),
// which is ignored. NaN/Inf rays miss, as in Slab.
//
// The cost over Slab: three operations per box (fabs, multiply, add).
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/prim/aabb.h"
#include "raybench/prim/aabb_slab.h"

namespace raybench {

struct SlabRobust {
  static constexpr std::string_view name = "slab_robust";
  static constexpr std::string_view description =
      "slab test with the exit padded by its rounding error (Williams 2005, Ize 2013, pbrt-v4), never misses, float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kConservative;

  // 8u = 2^-21: see the error bound above (2 gamma(4) rounded to float).
  static constexpr float kPad = 0x1p-21f;

  using Precomputed = Slab::Precomputed;
  static Precomputed precompute(const Ray& ray) { return Slab::precompute(ray); }

  // An exit (or tmax) padded by 8u. Sign-safe: moves a negative value up
  // too. +inf stays +inf, NaN stays NaN (a miss), -inf becomes NaN (a miss,
  // as it was).
  static float padded(float t_exit) { return t_exit + std::fabs(t_exit) * kPad; }

  // On a hit, t_entry is as computed (for ordering children) and t_exit is
  // padded: it may exceed the exact exit by a few ulps.
  static bool intersect(const Precomputed& ray, const BBox& box, float tmax, BoxHit& out) {
    BoxHit h = Slab::clip(ray, box, tmax);
    h.t_exit = padded(h.t_exit);
    return Slab::report(h, out);
  }
};

}  // namespace raybench
