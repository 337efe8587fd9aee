// The ray-AABB seed note's slab test (seed 000, a Chinese blog post), kept
// as the note writes it: the baseline
// that shows what aabb_slab.h and aabb_slab_robust.h fix.
//
// Source: ../shared/seeds/000_*.txt (i_dovelemon, "3D空间中射线与轴向包围盒AABB的
// 交叉检测算法", blog.csdn.net/i_dovelemon/article/details/38342739; it follows
// the slabs method of Ericson's Real-Time Collision Detection, which it
// cites). Per axis, in the order x, y, z:
//   |d| < 0.000001f         "parallel": miss if the origin is outside the slab
//   else t1, t2 = (min - o) * (1/d), (max - o) * (1/d), swapped so t1 <= t2
//        tmin = max(tmin, t1), tmax = min(tmax, t2), miss if tmin > tmax
// starting from tmin = 0, tmax = FLT_MAX; the hit is at tmin.
//
// What it gets wrong (each one is pinned by a SlabSeed.KnownFailure_* test in
// kernels/tests/aabb_test.cpp):
// - Every rejection is written `x < ...` / `x > ...`, which NaN fails, and
//   every update `if (t1 > tmin)`, which NaN skips: a NaN direction component
//   makes that slab no constraint at all. An all-NaN direction hits every box
//   (EXTREMES.md), and so does a NaN origin coordinate (on a parallel axis
//   both `origin < min` and `origin > max` are false; on another the t's are
//   NaN and skipped).
// - The empty box (lower = +inf, upper = -inf, what BBox starts as) is hit
//   by any ray without parallel components: t1 = +inf, t2 = -inf are swapped
//   into the slab (-inf, +inf).
// - `|d| < 1e-6` is an absolute threshold, so hit/miss depends on the length
//   of the direction: a direction scaled below 1e-6 is "parallel" on every
//   axis and only boxes containing the origin are hit; a small slope (5e-7
//   per unit) is ignored, so a box the ray has left long before is hit.
// - tmin starts at 0, whatever the ray's tnear: boxes before tnear are hit.
// - An infinite direction component gives 1/d = 0, so t1 = t2 = 0: that slab
//   is "crossed" at t = 0 even when the origin lies outside it.
// - Not conservative: the t's are rounded, so a box the exact ray grazes may
//   be missed (as with aabb_slab.h; aabb_slab_robust.h pads).
// What it gets right: a zero direction component (+0 or -0) takes the
// parallel branch, and `origin < min || origin > max` keeps an origin on a
// slab plane inside the closed box.
//
// The one adaptation: the note has no far bound; its initial tmax = FLT_MAX
// is the caller's tmax here (pass FLT_MAX for the note's function exactly).
// The note returns the hit point o + tmin d; this returns tmin and tmax.
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/prim/aabb.h"

namespace raybench {

struct SlabSeed {
  static constexpr std::string_view name = "slab_seed";
  static constexpr std::string_view description =
      "the ray-AABB seed note's branchy slab test as written (|d| < 1e-6 is parallel, tmin from 0, NaN passes), float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kEpsilon;

  // The note's parallel threshold, `abs(dir.x) < 0.000001f`: an
  // absolute number compared with a direction of any length.
  static constexpr float kParallel = 0.000001f;

  // The note recomputes 1/d for every box; nothing to precompute but the ray.
  struct Precomputed {
    Ray ray;
  };
  static Precomputed precompute(const Ray& ray) { return {ray}; }

  static bool intersect(const Precomputed& pre, const BBox& box, float tmax_in, BoxHit& out) {
    const Ray& r = pre.ray;
    float tmin = 0.0f;      // the note: tmin = 0.0f; the ray's tnear is never read
    float tmax = tmax_in;   // the note: tmax = FLT_MAX
    if (!slab(r.org.x, r.dir.x, box.lower.x, box.upper.x, tmin, tmax)) return false;
    if (!slab(r.org.y, r.dir.y, box.lower.y, box.upper.y, tmin, tmax)) return false;
    if (!slab(r.org.z, r.dir.z, box.lower.z, box.upper.z, tmin, tmax)) return false;
    out = {tmin, tmax};
    return true;
  }

 private:
  // One of the note's three identical per-axis blocks, comparisons unchanged.
  static bool slab(float origin, float dir, float min, float max, float& tmin, float& tmax) {
    if (std::abs(dir) < kParallel) {  // If the ray parallel to the plane
      if (origin < min || origin > max) return false;
    } else {
      const float ood = 1.0f / dir;
      float t1 = (min - origin) * ood;
      float t2 = (max - origin) * ood;
      if (t1 > t2) {
        const float temp = t1;
        t1 = t2;
        t2 = temp;
      }
      if (t1 > tmin) tmin = t1;
      if (t2 < tmax) tmax = t2;
      if (tmin > tmax) return false;
    }
    return true;
  }
};

}  // namespace raybench
