// Branchless ray-AABB slab test with a precomputed reciprocal direction,
// exact for zero direction components of either sign, NaN-safe.
//
// Source: the ray-AABB seed note (../shared/seeds/000_*.txt, i_dovelemon's
// Chinese blog post, after Ericson) describes the slabs method
// (Kay & Kajiya, "Ray Tracing Complex Scenes", SIGGRAPH 1986): per axis the
// ray is inside the slab lower <= o + t d <= upper for t between
// (lower - o) / d and (upper - o) / d, and it meets the box where the three
// intervals and the ray's own [tnear, tmax] overlap. Here, unlike the seed:
// - No parallel threshold. 1/d is computed once per ray; for d = +0 or -0 it
//   is +inf or -inf, and the distances become -inf/+inf (origin strictly
//   inside the slab: no constraint) or +inf/-inf (outside: empty), which is
//   the exact answer for a ray parallel to the slab. Hit/miss no longer
//   depends on |d|.
// - Each axis's entry plane is chosen by the sign bit of 1/d (Williams et
//   al., "An Efficient and Robust Ray-Box Intersection Algorithm", JGT 2005;
//   pbrt-v4's Bounds3::IntersectP) instead of by comparing the two
//   distances, so -0 selects like a negative direction and never needs a
//   swap.
// - An origin exactly on a slab plane with a zero component gives
//   0 * inf = NaN. The updates `entry = t > entry ? t : entry` keep the old
//   bound when t is NaN, so that slab does not constrain: the closed box
//   contains the ray. The same updates keep a NaN *bound* (entry or exit)
//   NaN, and `entry <= exit` then fails: precompute() turns a ray with NaN
//   or Inf in its origin or direction into tnear = NaN, and a NaN tnear or
//   tmax misses every box at no cost per box.
// - The ray's tnear is honoured; the interval is closed at both ends.
// - An entry at +inf is a miss: the ray never gets there (a zero component
//   with the origin outside that slab, when every other bound is infinite).
// The empty box (lower = +inf, upper = -inf) is missed. A NaN box coordinate
// gives a NaN distance, ignored like the others: that side is unbounded.
//
// Not conservative: every distance is rounded (three roundings, see
// aabb_slab_robust.h), so a box the exact ray only grazes may be missed.
// Inside a BVH that loses hits (EXTREMES.md: 1.7-6.6 % of rays aimed at
// edges and vertices); aabb_slab_robust.h pads the exit and loses none.
#pragma once

#include <cmath>
#include <limits>
#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/prim/aabb.h"

namespace raybench {

struct Slab {
  static constexpr std::string_view name = "slab";
  static constexpr std::string_view description =
      "branchless slab test, precomputed 1/d, planes chosen by sign (Kay-Kajiya 1986, Williams et al. 2005), NaN misses, float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  struct Precomputed {
    Vec3f org;
    Vec3f inv_dir;     // 1/d per axis: +-inf for a +-0 component
    bool negative[3];  // sign bit of 1/d (true for -0): the entry plane is `upper`
    float tnear;       // the ray's tnear, or NaN for a ray with NaN/Inf in org or dir
  };

  RAYBENCH_INLINE static Precomputed precompute(const Ray& ray) {
    Precomputed p;
    p.org = ray.org;
    p.inv_dir = {1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z};
    for (int axis = 0; axis < 3; ++axis) p.negative[axis] = std::signbit(p.inv_dir[axis]);
    // An infinite origin or direction is no ray (docs/raysets.md: such rays count as
    // misses); a NaN tnear propagates through every test below as a miss.
    const bool valid = is_finite(ray.org) && is_finite(ray.dir);
    p.tnear = valid ? ray.tnear : std::numeric_limits<float>::quiet_NaN();
    return p;
  }

  // The overlap of [tnear, tmax] with the three slab intervals, as computed:
  // empty when !(t_entry <= t_exit). Shared with SlabRobust, which pads it.
  RAYBENCH_INLINE static BoxHit clip(const Precomputed& r, const BBox& box, float tmax) {
    return clip(r, r.inv_dir, box, tmax);
  }
  // As above with the far planes' distances scaled by far_inv_dir instead of
  // 1/d (SlabRobustRay's reciprocals rounded outward).
  RAYBENCH_INLINE static BoxHit clip(const Precomputed& r, const Vec3f& far_inv_dir, const BBox& box, float tmax) {
    float entry = r.tnear, exit = tmax;
    for (int axis = 0; axis < 3; ++axis) {
      const float near_plane = r.negative[axis] ? box.upper[axis] : box.lower[axis];
      const float far_plane = r.negative[axis] ? box.lower[axis] : box.upper[axis];
      const float t_near = (near_plane - r.org[axis]) * r.inv_dir[axis];
      const float t_far = (far_plane - r.org[axis]) * far_inv_dir[axis];
      // Written so that a NaN distance (origin on the plane, zero component)
      // is ignored and a NaN bound (invalid ray, NaN tmax) stays NaN.
      entry = t_near > entry ? t_near : entry;
      exit = t_far < exit ? t_far : exit;
    }
    return {entry, exit};
  }

  static bool overlaps(const BoxHit& h) {
    return h.t_entry <= h.t_exit && h.t_entry < std::numeric_limits<float>::infinity();
  }

  // Every box test's answer from its clipped interval: a hit, written to
  // `out`, when the interval overlaps; `out` untouched otherwise.
  RAYBENCH_INLINE static bool report(const BoxHit& h, BoxHit& out) {
    if (!overlaps(h)) return false;
    out = h;
    return true;
  }

  RAYBENCH_INLINE static bool intersect(const Precomputed& ray, const BBox& box, float tmax, BoxHit& out) {
    return report(clip(ray, box, tmax), out);
  }
};

}  // namespace raybench
