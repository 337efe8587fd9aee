// Conservative ray-AABB slab test in the fused form: each distance one fused
// multiply-add, as SlabFma (aabb_slab_fma.h), and yet, as SlabRobust
// (aabb_slab_robust.h), it never misses a box that the exact ray (the float
// inputs taken as exact reals) touches within [tnear, tmax]. All its padding
// is in two offsets per axis, computed once per ray, so a box costs what
// SlabFma's costs. The wide BVH traversal takes it as its box-test policy
// (wide_bvh_traverse.h), but the backends' :robust option keeps
// SlabRobustRay, which measured faster in the whole traversal: the per-ray
// offsets and three more constants held through the traversal cost more
// than the subtraction per plane they save
// (measured: docs/notes/kernels-box-tests.md).
//
// Why it is conservative, and its error bound: above struct SlabFmaRobust.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "raybench/math/bbox.h"
#include "raybench/math/inline.h"
#include "raybench/prim/aabb.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_fma.h"
#include "raybench/prim/aabb_slab_robust.h"

namespace raybench {

// Why SlabFma is not conservative: its distance plane * r - p, r = fl(1/d),
// carries the rounding of p = fl(o * r), an error absolute in t (u |o / d|,
// u = 2^-24), and the rounding of r, relative to the distance. Both are
// bounded once the planes are: every plane the ray is tested against lies
// within `extent` (a BVH's root bounds), so |plane| <= E per axis (finite
// planes: an empty box's infinite ones give exactly infinite distances), and
//   Q = E |r| + |o r|
// bounds every |plane * r| + |o r|. The offsets move o * r by a margin
// m = fl(fl(E |r|) + |fl(o r)|) * 8u, up for the near planes and down for
// the far planes: the entry can only fall and the exit only rise.
//
// Error bound (u and gamma(n) as in aabb_slab_robust.h). Let x = (plane - o)/d
// exactly, r = (1 + d1)/d with |d1| <= u, so plane r - o r = x (1 + d1) and
// |x| <= Q / (1 - u). Two roundings on each term give m >= 8u (1 - u)^2 Q, and the near
// offset A = fl(fl(o r) + m) satisfies A - o r >= m (1 - u) - (2u + u^2)|o r|
// >= 5.9u Q and |A - o r| <= 10.1u Q. The exact z = plane r - A is then
// <= x + u |x| - 5.9u Q <= x - 4.8u Q, and |z| <= (1 + 10.1u) Q, so the
// one rounding of the fused operation leaves the near distance
// fl(z) <= z + u |z| <= x - 3.7u Q <= x. Likewise every far distance >= x.
// If the exact ray touches the box, its exact entry a = max(tnear, y_j) and
// exit b = min(tmax, x_i) satisfy a <= b, and
//   computed entry <= a <= b <= computed exit,
// whatever the signs (no tnear >= 0 condition, unlike SlabRobustRay). tmax is
// still padded as SlabRobust pads an exit, so that a traversal skips no
// subtree SlabRobust would enter (wide_bvh_traverse.h pads its `reachable`
// test alike). Q = 0 means o = 0 and every plane at 0 on that axis: then all
// is exact. The bound holds when nothing overflows or underflows (1/d, o r,
// E r, the distances and m zero or normal floats); past that the margin may
// be infinite or NaN, and a NaN offset makes every distance NaN, ignored: the
// box is entered, still conservative. A ray with a zero direction component
// (1/d infinite) is tested by SlabRobust, as SlabFma defers to Slab; which
// test a ray gets is decided once per ray (serves()).
//
// As a standalone test (intersect, the microbenchmarks) the box is its own
// extent, and the offsets are computed per box.
struct SlabFmaRobust {
  static constexpr std::string_view name = "slab_fma_robust";
  static constexpr std::string_view description =
      "fused slab test made conservative per ray: o/d moved by its error bound over the tested planes' extent, tmax "
      "padded, never misses, float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kConservative;

  using Precomputed = Slab::Precomputed;
  static Precomputed precompute(const Ray& ray) { return Slab::precompute(ray); }

  // Rays with every 1/d finite; the others get SlabRobust.
  using Fallback = SlabRobust;
  static bool serves(const Precomputed& r) { return SlabFma::serves(r); }

  // What the fused distances subtract, per axis: t = plane * (1/d) - near
  // for the near planes, - far for the far planes. Valid for planes within
  // the extent they were computed over.
  struct Offsets {
    Vec3f near, far;
  };
  RAYBENCH_INLINE static Offsets offsets(const Precomputed& r, const BBox& extent) {
    Offsets o;
    for (int axis = 0; axis < 3; ++axis) {
      const float inv_dir = r.inv_dir[axis];
      const float largest_plane = std::max(finite_or_zero(std::fabs(extent.lower[axis])),
                                           finite_or_zero(std::fabs(extent.upper[axis])));
      const float org_over_dir = r.org[axis] * inv_dir;
      const float margin = (largest_plane * std::fabs(inv_dir) + std::fabs(org_over_dir)) * SlabRobust::kPad;
      o.near[axis] = org_over_dir + margin;
      o.far[axis] = org_over_dir - margin;
    }
    return o;
  }

  // Infinite planes (an empty box's, or an empty extent's) need no margin:
  // their distances are exactly infinite. NaN ones are ignored by clip.
  static float finite_or_zero(float magnitude) { return magnitude < std::numeric_limits<float>::infinity() ? magnitude : 0.0f; }

  // On a hit, t_entry and t_exit are as computed: the entry may lie below
  // the exact entry and the exit above the exact exit by the margin.
  RAYBENCH_INLINE static BoxHit clip(const Precomputed& r, const Offsets& o, const BBox& box, float tmax) {
    return SlabFma::clip(r, o.near, o.far, box, SlabRobust::padded(tmax));
  }

  RAYBENCH_INLINE static bool intersect(const Precomputed& ray, const BBox& box, float tmax, BoxHit& out) {
    if (!serves(ray)) return Fallback::intersect(ray, box, tmax, out);
    return intersect(ray, offsets(ray, box), box, tmax, out);
  }
  // With offsets set over an extent that contains the box, for a ray it serves.
  RAYBENCH_INLINE static bool intersect(const Precomputed& ray, const Offsets& o, const BBox& box, float tmax,
                                        BoxHit& out) {
    return Slab::report(clip(ray, o, box, tmax), out);
  }
};

// Box tests whose per-ray setup needs the extent of the planes tested.
template <typename BoxTest>
concept UsesExtent = requires { typename BoxTest::Offsets; };

}  // namespace raybench
