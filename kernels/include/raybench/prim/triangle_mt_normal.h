// Möller–Trumbore with a stored normal: the form Embree's Triangle4
// intersector uses (its MoellerTrumboreIntersector1), and the form our wide
// BVH leaves test (simd/wide_triangle.h) 4 or 8 at once.
//
// The same Cramer's rule as the Möller–Trumbore seed note (triangle_mt.h) on
//   u e1 + v e2 - t d = o - v0,
// with the triple products regrouped around the normal: storing
// e1' = v0 - v1, e2 = v2 - v0 and n = e1' x e2 per triangle, and with
// c = v0 - o, r = d x c,
//   det = n . d,  u = (r . e2) / det,  v = (r . e1') / det,  t = (n . c) / det.
// One cross product per ray and triangle instead of two, each dot product
// two fused multiply-adds, and no division until a triangle passes: the
// tests compare the undivided numerators, made positive by det's sign, with
// |det| (u >= 0, v >= 0, u + v <= 1 and t > tnear, scaled by |det|).
// Only then is t divided out and checked against (tnear, tmax] exactly, so
// rounding never puts a hit outside the ray's interval, and whether a
// triangle is hit does not depend on how far tmax has shrunk by rounding:
// the closest hit is the same in any order of testing, as with
// triangle_mt.h (a scaled test against tmax, as Embree's, would make it
// depend on which of two triangles an ulp apart was tested first).
// Like triangle_mt.h: only det == 0 is rejected, NaN rejects, not watertight.
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct MollerTrumboreNormal {
  static constexpr std::string_view name = "mt_normal";
  static constexpr std::string_view description =
      "Moller-Trumbore with a stored normal, fused multiply-adds, division deferred (Embree's Triangle4 form), float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  struct Prepared {
    Vec3f v0;
    Vec3f e1;      // v0 - v1: the sign that makes every numerator a plain dot product
    Vec3f e2;      // v2 - v0
    Vec3f normal;  // e1 x e2, computed in double and rounded once
  };
  static Prepared prepare(const Triangle& tri) {
    const Vec3f e1 = tri.v0 - tri.v1, e2 = tri.v2 - tri.v0;
    const double n[3] = {double(e1.y) * e2.z - double(e1.z) * e2.y, double(e1.z) * e2.x - double(e1.x) * e2.z,
                         double(e1.x) * e2.y - double(e1.y) * e2.x};
    return {tri.v0, e1, e2, {static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2])}};
  }

  using RayData = Ray;
  static const Ray& precompute(const Ray& ray) { return ray; }

  // a . b as the SIMD form computes it: fma(ax, bx, fma(ay, by, az * bz)).
  RAYBENCH_INLINE static float dot_fma(const Vec3f& a, const Vec3f& b) {
    return std::fma(a.x, b.x, std::fma(a.y, b.y, a.z * b.z));
  }

  // True when the ray hits the triangle at t in (ray.tnear, tmax]; fills out.
  RAYBENCH_INLINE static bool intersect(const Ray& ray, float tmax, const Prepared& tri, TriangleHit& out) {
    const Vec3f& d = ray.dir;
    const Vec3f c = tri.v0 - ray.org;
    const Vec3f r{std::fma(d.y, c.z, -(d.z * c.y)), std::fma(d.z, c.x, -(d.x * c.z)), std::fma(d.x, c.y, -(d.y * c.x))};
    const float det = dot_fma(tri.normal, d);
    const float abs_det = std::fabs(det);
    // Flipping the numerators' signs by det's (an exact operation) makes
    // every test a comparison with |det|.
    const auto signed_by_det = [&](float x) { return std::signbit(det) ? -x : x; };
    const float u_scaled = signed_by_det(dot_fma(r, tri.e2));
    const float v_scaled = signed_by_det(dot_fma(r, tri.e1));
    const float t_scaled = signed_by_det(dot_fma(tri.normal, c));
    if (!(det != 0.0f && u_scaled >= 0.0f && v_scaled >= 0.0f && u_scaled + v_scaled <= abs_det &&
          t_scaled > abs_det * ray.tnear))
      return false;
    const float inv_det = 1.0f / abs_det;
    const float t = t_scaled * inv_det;
    if (!(t > ray.tnear && t <= tmax)) return false;
    out = {t, u_scaled * inv_det, v_scaled * inv_det};
    return true;
  }
  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(ray, tmax, prepare(tri), out);
  }
};

}  // namespace raybench
