// The ray-sphere seed note's geometric test (seed 003, a Chinese blog post),
// kept as the note writes it: the
// baseline that shows what the fixed variants fix.
//
// Source: ../shared/seeds/003_*.txt (goteet, "射线与球的相交性检测",
// jianshu.com/p/1b008ed86627). With oc = center - org and a unit direction d:
//   projoc = d.oc                   the centre's projection on the ray; < 0: miss
//   distance2 = oc.oc - projoc^2    Pythagoras: squared distance centre-ray
//   disc = r^2 - distance2          < FLOAT_EPSILON: tangent, t0 = t1 = projoc
//   t0, t1 = projoc -/+ sqrt(disc)  and t0 = t1 when t0 < 0
//
// What it gets wrong (measured in ../shared/EXTREMES.md; each one is pinned by
// a SphereSeed.KnownFailure_* test in kernels/tests/sphere_test.cpp):
// - `projoc < 0` rejects before asking whether the origin is inside, so a ray
//   starting inside misses when the centre is behind its origin.
// - `oc.oc - projoc^2` subtracts two numbers of size |oc|^2 to get one of size
//   r^2: hit/miss is wrong for 1.4 % of rays at distance 1e3 from a unit
//   sphere and ~50 % from 1e4 on.
// - FLOAT_EPSILON is absolute: every sphere with r^2 < FLT_EPSILON, i.e.
//   r < 3.45e-4, collapses to one point at the centre's projection (t0 = t1).
// - It assumes |d| = 1 (the note says so): any other length gives wrong roots
//   and turns misses into hits.
// - Every rejection is written `x < ...` / `x > ...`, which NaN fails: a ray
//   with NaN in it hits, with t = NaN.
//
// The one adaptation: the note has no interval. raybench's (tnear, tmax] is
// applied to the two roots it reports, written as rejections in the note's
// style so that NaN still passes, as it does in the note.
#pragma once

#include <cmath>
#include <limits>
#include <string_view>

#include "raybench/math/ray.h"
#include "raybench/prim/sphere.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct SphereSeed {
  static constexpr std::string_view name = "sphere_seed";
  static constexpr std::string_view description =
      "the ray-sphere seed note's geometric test as written (projoc < 0 rejects, FLT_EPSILON tangent test), float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kEpsilon;

  // The note's FLOAT_EPSILON: FLT_EPSILON = 2^-23, the spacing of floats at 1,
  // used as an absolute threshold on r^2 - distance^2 (as the note uses it).
  static constexpr float kFloatEpsilon = std::numeric_limits<float>::epsilon();

  // The note's semantics, where they differ from the other sphere tests: dir
  // must be unit length; a hit needs the centre's projection ahead of the
  // origin (projoc >= 0); a ray from inside (centre ahead) reports
  // t_near = t_far = the exit; a near-tangent ray reports t_near = t_far.
  static bool intersect(const Ray& ray, float tmax, const Sphere& s, SphereHit& out) {
    const float radius2 = s.radius * s.radius;  // the note's GetRadiusSquare()
    const Vec3f oc = s.center - ray.org;
    const float projoc = dot(ray.dir, oc);
    if (projoc < 0) return false;
    const float oc2 = dot(oc, oc);
    const float distance2 = oc2 - projoc * projoc;
    if (distance2 > radius2) return false;
    float discriminant = radius2 - distance2;
    float t0, t1;
    if (discriminant < kFloatEpsilon) {
      t0 = t1 = projoc;  // "only one intersection: the ray is tangent"
    } else {
      discriminant = std::sqrt(discriminant);
      t0 = projoc - discriminant;
      t1 = projoc + discriminant;
      if (t0 < 0) t0 = t1;
    }
    // Adaptation (see above): a root in (tnear, tmax], NaN passing as in the note.
    const bool outside0 = t0 <= ray.tnear || t0 > tmax;
    const bool outside1 = t1 <= ray.tnear || t1 > tmax;
    if (outside0 && outside1) return false;
    out = {t0, t1};
    return true;
  }
};

}  // namespace raybench
