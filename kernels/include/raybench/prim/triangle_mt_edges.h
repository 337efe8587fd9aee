// Möller–Trumbore in the stored-normal form of triangle_mt_normal.h, with
// the normal recomputed at every test from the stored edges instead of
// stored: 9 floats per triangle (v0 and two edges) instead of 12, for wide
// BVH leaves a quarter less memory (simd/wide_triangle.h, TriangleEdgePack;
// the backends' :mt_edges option).
// Why: on a scene whose tree does not fit in the caches (the
// million-triangle terrain: bvh8 51 MB instead of 64) a ray's time goes
// mostly to waiting for leaf lines, and fewer lines per leaf pay for the
// extra cross product; on scenes whose trees fit in the last-level cache
// the stored normal is faster.
// The normal is e1 x e2 in float with one fused multiply-add per component
// (the SIMD form's arithmetic exactly), not in double as mt_normal rounds
// it; everything after it is mt_normal's test.
// Guarantee: mt_normal's, except on collinear triangles: the double normal
// is exactly zero there and every ray misses, while the float one keeps a
// rounding residue, so a few rays hit it (results/accuracy-kernels.csv).
// measured: docs/notes/kernels-triangle-tests.md
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"
#include "raybench/prim/triangle_mt_normal.h"

namespace raybench {

struct MollerTrumboreEdges {
  static constexpr std::string_view name = "mt_edges";
  static constexpr std::string_view description =
      "Moller-Trumbore in the stored-normal form, the normal recomputed from two stored edges per test "
      "(9 floats per triangle instead of 12), float";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  struct Prepared {
    Vec3f v0;
    Vec3f e1;  // v0 - v1, as MollerTrumboreNormal's
    Vec3f e2;  // v2 - v0
  };
  static Prepared prepare(const Triangle& tri) { return {tri.v0, tri.v0 - tri.v1, tri.v2 - tri.v0}; }

  // e1 x e2, each component one fused multiply-add: a*b - round(c*d).
  RAYBENCH_INLINE static Vec3f normal(const Vec3f& e1, const Vec3f& e2) {
    return {std::fma(e1.y, e2.z, -(e1.z * e2.y)), std::fma(e1.z, e2.x, -(e1.x * e2.z)),
            std::fma(e1.x, e2.y, -(e1.y * e2.x))};
  }

  using RayData = Ray;
  static const Ray& precompute(const Ray& ray) { return ray; }

  // True when the ray hits the triangle at t in (ray.tnear, tmax]; fills out.
  RAYBENCH_INLINE static bool intersect(const Ray& ray, float tmax, const Prepared& tri, TriangleHit& out) {
    return MollerTrumboreNormal::intersect(ray, tmax, {tri.v0, tri.e1, tri.e2, normal(tri.e1, tri.e2)}, out);
  }
  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(ray, tmax, prepare(tri), out);
  }
};

}  // namespace raybench
