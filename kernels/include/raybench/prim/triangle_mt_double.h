// Möller–Trumbore in double precision: a reference to judge the float
// variants by, not an exact one (EXTREMES.md: double still disagrees with
// exact arithmetic on edge- and vertex-aimed rays). Inputs are the float
// vertices and ray, widened exactly; only the results are rounded to float.
#pragma once

#include <string_view>

#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct MollerTrumboreDouble {
  static constexpr std::string_view name = "mt_double";
  static constexpr std::string_view description = "Moller-Trumbore in double precision (reference, not exact)";
  static constexpr AccuracyClass accuracy = AccuracyClass::kReference;

  struct Vec3d {
    double x, y, z;
  };
  struct Prepared {
    Vec3d v0, e1, e2;
  };
  static Vec3d widen(Vec3f v) { return {v.x, v.y, v.z}; }
  static Vec3d sub(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static double dotd(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
  static Vec3d crossd(Vec3d a, Vec3d b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

  static Prepared prepare(const Triangle& tri) {
    const Vec3d v0 = widen(tri.v0);
    return {v0, sub(widen(tri.v1), v0), sub(widen(tri.v2), v0)};
  }
  using RayData = Ray;
  static const Ray& precompute(const Ray& ray) { return ray; }

  static bool intersect(const Ray& ray, float tmax, const Prepared& tri, TriangleHit& out) {
    const Vec3d d = widen(ray.dir);
    const Vec3d p = crossd(d, tri.e2);
    const double det = dotd(tri.e1, p);
    if (!(det != 0.0)) return false;
    const Vec3d s = sub(widen(ray.org), tri.v0);
    const double u = dotd(s, p) / det;
    if (!(u >= 0.0 && u <= 1.0)) return false;
    const Vec3d q = crossd(s, tri.e1);
    const double v = dotd(d, q) / det;
    if (!(v >= 0.0 && u + v <= 1.0)) return false;
    const double t = dotd(tri.e2, q) / det;
    if (!(t > ray.tnear && t <= tmax)) return false;
    out = {static_cast<float>(t), static_cast<float>(u), static_cast<float>(v)};
    return true;
  }
  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(ray, tmax, prepare(tri), out);
  }
};

}  // namespace raybench
