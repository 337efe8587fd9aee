// The textbook ray-sphere test: the quadratic formula with b^2 - 4ac, float.
//
// Source: the ray-sphere seed note (../shared/seeds/003_*.txt, a Chinese
// blog post), second half, which derives
//   |o + t d - c|^2 = r^2  =>  a t^2 + b t + c' = 0,
//   a = d.d, b = 2 d.(o - c), c' = (o - c).(o - c) - r^2,  t = (-b -/+ sqrt(b^2 - 4ac')) / 2a
// and quotes chai3d's cIntersectionSegmentSphere, which is the same algebra.
// Kept from them: the formula, its float rounding, and `a == 0` as the only
// guard. Not kept: chai3d's segment rule that drops the exit point of a
// segment starting inside (EXTREMES.md G10 counts it as a failure); here a ray
// starting inside hits the far side, as for the other sphere tests.
//
// Known weaknesses (EXTREMES.md, pinned by SphereQuadratic.KnownFailure_*
// tests): b^2 and 4ac' are both ~4|o - c|^2|d|^2 and their difference ~4r^2|d|^2,
// so far from a small sphere the cancellation loses hit/miss; and c' drops
// r^2 entirely once r^2 is below half an ulp of |o - c|^2, so a small sphere
// seen from a distance collapses to a tangent point. sphere_precise.h fixes both.
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/math/ray.h"
#include "raybench/prim/sphere.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct SphereQuadratic {
  static constexpr std::string_view name = "sphere_quadratic";
  static constexpr std::string_view description =
      "textbook quadratic b^2-4ac ray-sphere test (the form the ray-sphere seed note cites, chai3d), float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  // True when a root lies in (ray.tnear, tmax]; out gets both roots. Every
  // test is written so that NaN rejects.
  static bool intersect(const Ray& ray, float tmax, const Sphere& s, SphereHit& out) {
    const Vec3f ca = ray.org - s.center;
    const float a = dot(ray.dir, ray.dir);
    if (!(a > 0.0f)) return false;  // zero (or NaN) direction: no ray
    const float b = 2.0f * dot(ray.dir, ca);
    const float c = dot(ca, ca) - s.radius * s.radius;
    const float discriminant = b * b - 4.0f * a * c;
    if (!(discriminant >= 0.0f)) return false;
    const float root = std::sqrt(discriminant);
    const float t0 = (-b - root) / (2.0f * a);  // root >= 0 and a > 0: t0 <= t1
    const float t1 = (-b + root) / (2.0f * a);
    return report_sphere_roots(ray, tmax, t0, t1, out);
  }
};

}  // namespace raybench
