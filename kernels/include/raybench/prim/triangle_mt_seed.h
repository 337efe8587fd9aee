// Möller–Trumbore exactly as its seed note writes it (a Chinese blog post
// deriving it by Cramer's rule, ../shared/seeds/002_*.txt;
// "IntersectTriangle", D3DX style, float), kept so that raybench can show
// where it fails. What it gets wrong (../shared/EXTREMES.md, measured):
//  - `det < 0.0001f` is an absolute threshold: det scales with the square of
//    the triangle's size and with |dir|, so triangles with legs <= ~5e-3
//    (the Stanford bunny's), unnormalised directions, and rays grazing under
//    ~1e-4 rad are rejected.
//  - it never checks t >= 0: a triangle behind the origin hits with t < 0.
//  - every rejection is `x < ...` / `x > ...`; NaN fails both, so a NaN ray
//    "hits" with t = NaN.
// The note returns any t; its caller keeps the nearest. raybench adds only
// that bookkeeping (t <= tmax, so a BVH can find the closest hit), not the
// missing t > tnear test.
#pragma once

#include <string_view>

#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct MollerTrumboreSeed {
  static constexpr std::string_view name = "mt_seed";
  static constexpr std::string_view description = "Moller-Trumbore as the seed note writes it: det < 1e-4 rejection, no t >= 0 test";
  static constexpr AccuracyClass accuracy = AccuracyClass::kEpsilon;

  using Prepared = Triangle;  // the note computes the edges per call
  static Prepared prepare(const Triangle& tri) { return tri; }
  using RayData = Ray;
  static const Ray& precompute(const Ray& ray) { return ray; }

  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    const Vec3f edge1 = tri.v1 - tri.v0;
    const Vec3f edge2 = tri.v2 - tri.v0;
    const Vec3f pvec = cross(ray.dir, edge2);
    float det = dot(edge1, pvec);
    Vec3f tvec;
    if (det > 0) {
      tvec = ray.org - tri.v0;
    } else {
      tvec = tri.v0 - ray.org;
      det = -det;
    }
    if (det < 0.0001f) return false;  // the note's absolute epsilon
    float u = dot(tvec, pvec);
    if (u < 0.0f || u > det) return false;
    const Vec3f qvec = cross(tvec, edge1);
    float v = dot(ray.dir, qvec);
    if (v < 0.0f || u + v > det) return false;
    float t = dot(edge2, qvec);
    const float inv_det = 1.0f / det;
    t *= inv_det;
    u *= inv_det;
    v *= inv_det;
    if (t > tmax) return false;  // raybench's nearest-hit bookkeeping (not in the note)
    out = {t, u, v};
    return true;
  }
};

}  // namespace raybench
