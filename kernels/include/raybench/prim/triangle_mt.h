// Möller–Trumbore ray-triangle test, without scale-dependent epsilons.
//
// Source: the Möller–Trumbore seed note (../shared/seeds/002_*.txt, a
// Chinese blog post) derives it by Cramer's rule on
//   b*e1 - t*d + c*e2 = o - v0,  e1 = v1 - v0, e2 = v2 - v0
// (Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
// JGT 1997). The seed rejects |det| < 1e-4, an absolute threshold: with legs
// of 5e-3 units (the Stanford bunny's scale) det falls below it and every
// triangle disappears. Here only det == 0 (the ray lies in the triangle's
// plane, or the triangle is degenerate) is rejected, and every comparison is
// written so that NaN rejects.
//
// Not watertight: a ray through a shared edge may miss both triangles.
#pragma once

#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct MollerTrumbore {
  static constexpr std::string_view name = "mt";
  static constexpr std::string_view description = "Moller-Trumbore (the seed note's algorithm) without absolute epsilons, float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  // The per-triangle data the BVH stores in leaf order: edges precomputed.
  struct Prepared {
    Vec3f v0, e1, e2;
  };
  static Prepared prepare(const Triangle& tri) { return {tri.v0, tri.v1 - tri.v0, tri.v2 - tri.v0}; }

  // Nothing to precompute per ray.
  using RayData = Ray;
  static const Ray& precompute(const Ray& ray) { return ray; }

  // True when the ray hits the triangle at t in (ray.tnear, tmax]; fills out.
  RAYBENCH_INLINE static bool intersect(const Ray& ray, float tmax, const Prepared& tri, TriangleHit& out) {
    const Vec3f p = cross(ray.dir, tri.e2);
    const float det = dot(tri.e1, p);
    if (!(det != 0.0f)) return false;  // parallel ray or zero-area triangle (or NaN)
    const float inv_det = 1.0f / det;
    const Vec3f s = ray.org - tri.v0;
    const float u = dot(s, p) * inv_det;
    if (!(u >= 0.0f && u <= 1.0f)) return false;
    const Vec3f q = cross(s, tri.e1);
    const float v = dot(ray.dir, q) * inv_det;
    if (!(v >= 0.0f && u + v <= 1.0f)) return false;
    const float t = dot(tri.e2, q) * inv_det;
    if (!(t > ray.tnear && t <= tmax)) return false;
    out = {t, u, v};
    return true;
  }
  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(ray, tmax, prepare(tri), out);
  }
};

}  // namespace raybench
