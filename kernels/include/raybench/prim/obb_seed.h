// The ray-OBB seed note's slab test (seed 004, a Chinese blog post), kept as
// the note writes it: the baseline that
// shows what obb_eigen.h fixes.
//
// Source: ../shared/seeds/004_*.txt ("OBB与Ray求交", 2022): for each box axis
// n with half size h, e = n.(C - P) and f = n.d; if |f| > 1e-20 the slab is
// entered and left at t = (e +/- h) / f, and the running interval
// [minT, maxT] is narrowed; otherwise the ray is parallel to the slab and
// misses unless its origin lies between the two planes.
//
// What it gets wrong (../shared/EXTREMES.md; each pinned by an
// ObbSeed.KnownFailure_* test in kernels/tests/obb_test.cpp):
// - `double minT = DBL_MIN` is the smallest *positive* double, not -DBL_MAX.
//   It acts as "t > 0": after `minT > maxT` has passed, maxT >= minT > 0, so
//   the `maxT < 0` check never fires; and a ray whose origin lies on a face,
//   pointing outward, has exit = 0 < DBL_MIN and misses the closed box it
//   touches (the ray-AABB seed note, seed 000, hits it).
// - `|f| > 1e-20` is absolute: a ray with |d| <= 1e-20 is "parallel" to every
//   slab and misses every box its origin is not in, though hit/miss must not
//   depend on |d| (EXTREMES.md G16).
// - Every rejection is written `x > ...` / `x < ...`, which NaN fails: a ray
//   with a NaN origin passes all three slabs and hits every box.
//
// Types as in the note: e, f, t1, t2 float (glm::vec3 dot products), the
// (e +/- m_size/2.0) / f arithmetic in double, minT and maxT double. The note
// stores a box's full size m_size; m_size / 2.0 is half_extent exactly.
// The one adaptation: the note has no interval and returns only a bool.
// raybench's [tnear, tmax] is applied at the end as two more rejections in
// the note's style (NaN still passes), and out gets the note's {minT, maxT},
// not clipped to [tnear, tmax] as aabb.h's BoxHit contract asks: for an
// origin inside, the entry is the note's DBL_MIN, which rounds to 0.0f.
#pragma once

#include <cfloat>
#include <cmath>
#include <string_view>
#include <utility>

#include "raybench/math/ray.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct ObbSeed {
  static constexpr std::string_view name = "obb_seed";
  static constexpr std::string_view description =
      "the ray-OBB seed note's slab test as written (minT = DBL_MIN, |f| > 1e-20 parallel test)";
  static constexpr AccuracyClass accuracy = AccuracyClass::kEpsilon;

  // The note's parallel threshold on f = n.d: absolute, so it
  // depends on |d|.
  static constexpr double kParallelEpsilon = 1e-20;

  static bool intersect(const Ray& ray, float tmax, const OrientedBox& box, BoxHit& out) {
    const Vec3f delta = box.center - ray.org;  // C - P
    float t1, t2;                               // where the ray meets the current slab's planes
    double minT = DBL_MIN, maxT = DBL_MAX;
    for (int i = 0; i < 3; ++i) {  // the note writes this block out for u, v and w
      const double half_size = box.half_extent[i];  // obb.m_size.x / 2.0
      const float e = dot(delta, box.axis[i]);
      const float f = dot(ray.dir, box.axis[i]);
      if (std::abs(f) > kParallelEpsilon) {  // not parallel to this slab
        t1 = static_cast<float>((e + half_size) / f);
        t2 = static_cast<float>((e - half_size) / f);
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > minT) minT = t1;
        if (t2 < maxT) maxT = t2;
        if (minT > maxT) return false;  // the slab intervals do not overlap
        if (maxT < 0) return false;     // "box behind the ray": never true, see above
      } else if (-e - half_size > 0 || -e + half_size < 0) {
        return false;  // parallel and outside the slab
      }
    }
    // Adaptation (see above): raybench's interval, NaN passing as in the note.
    if (minT > tmax) return false;
    if (maxT < ray.tnear) return false;
    out = {static_cast<float>(minT), static_cast<float>(maxT)};
    return true;
  }
};

}  // namespace raybench
