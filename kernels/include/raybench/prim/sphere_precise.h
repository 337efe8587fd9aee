// Ray-sphere test with the two precision improvements of Haines, Günther &
// Akenine-Möller, "Precision Improvements for Ray/Sphere Intersection",
// Ray Tracing Gems (2019), ch. 7.
//
// With f = o - c, a = d.d and b = f.d (half the textbook b):
// 1. The discriminant (eq. 7.5). b^2 - ac cancels catastrophically when the
//    origin is far from a small sphere (two terms of size |f|^2|d|^2, their
//    difference of size r^2|d|^2). It equals a (r^2 - |l|^2), where
//    l = f - (b/a) d is the vector from the centre to its projection on the
//    ray: its length is the centre-ray distance, computed by one subtraction
//    of vectors instead of subtracting squares, so the error is ~ulp(|f|) in
//    a length, not ~ulp(|f|^2) in a squared length. Hit/miss is then wrong
//    only within ~ulp(|f|) of tangent: 0.2 % of rays at distance 1e6 from a
//    unit sphere (EXTREMES.md G12), where the textbook form is wrong for about
//    half of them from 1e4 on (sphere_test.cpp has the rays).
// 2. The roots (eq. 7.7): -b -/+ sqrt(D) cancels for one of them; instead
//    q = -b - sign(b) sqrt(D) adds numbers of one sign, and the roots are
//    c/q and q/a (their product is c/a). The near root stays accurate when
//    r is tiny next to the distance, where c = |f|^2 - r^2 loses r^2.
//
// Semantics: a hit is a root in (ray.tnear, tmax]; a ray starting inside hits
// the far side; |d| need not be 1 (t is in units of |d|). Every test is
// written so that NaN rejects; Inf input ends in NaN, hence a miss.
// Range: d.d and f.f are formed in float, so hit/miss is invariant to the
// scale of d for |d| in about [1e-18, 1e18] (below, d.d underflows).
#pragma once

#include <cmath>
#include <string_view>
#include <utility>

#include "raybench/math/ray.h"
#include "raybench/prim/sphere.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct SpherePrecise {
  static constexpr std::string_view name = "sphere_precise";
  static constexpr std::string_view description =
      "ray-sphere with Haines et al.'s stable discriminant and roots (Ray Tracing Gems ch. 7), float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  // True when a root lies in (ray.tnear, tmax]; out gets both roots.
  static bool intersect(const Ray& ray, float tmax, const Sphere& s, SphereHit& out) {
    const Vec3f f = ray.org - s.center;
    const float a = dot(ray.dir, ray.dir);
    if (!(a > 0.0f)) return false;  // zero (or NaN) direction: no ray
    const float b = dot(f, ray.dir);
    const float r2 = s.radius * s.radius;
    const Vec3f l = f - ray.dir * (b / a);  // centre -> closest point of the line
    const float discriminant = r2 - dot(l, l);  // D / a, eq. 7.5
    if (!(discriminant >= 0.0f)) return false;
    const float root = std::sqrt(a * discriminant);
    const float q = -(b + std::copysign(root, b));  // eq. 7.7: never a cancellation
    const float c = dot(f, f) - r2;
    float t0, t1;
    if (q == 0.0f) {
      // b = 0 and D = 0: the origin is the tangent point, a double root at 0
      // (and c/q would be 0/0).
      t0 = t1 = 0.0f;
    } else {
      t0 = c / q;
      t1 = q / a;
      if (t0 > t1) std::swap(t0, t1);
    }
    return report_sphere_roots(ray, tmax, t0, t1, out);
  }
};

}  // namespace raybench
