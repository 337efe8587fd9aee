// Ray-triangle intersection by coordinate transformation: Baldwin & Weber,
// "Fast Ray-Triangle Intersections by Coordinate Transformation", JCGT 5(3),
// 2016.
//
// Per triangle, precompute the affine map M that sends v0 -> origin,
// e1 = v1 - v0 -> x, e2 = v2 - v0 -> y, and a "free" vector f -> z, with f
// the unit axis of the normal's largest component (the paper's choice, which
// keeps M well conditioned). With n = e1 x e2 and Cramer's rule on
// p - v0 = a e1 + b e2 + c f:
//   a = (e2 x f) . (p - v0) / (n . f),  b = (f x e1) . (p - v0) / (n . f),
//   c = n . (p - v0) / (n . f).
// Per ray: the plane c = 0 gives t = -c(o) / c'(d), then (a, b) at the hit
// point are the barycentrics. The map is computed in double and stored as a
// full 3x4 float matrix (12 floats; the paper's compact form stores 9).
// Not watertight. Degenerate triangles get a NaN map and always miss.
#pragma once

#include <cmath>
#include <limits>
#include <string_view>

#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct BaldwinWeber {
  static constexpr std::string_view name = "baldwin_weber";
  static constexpr std::string_view description = "Baldwin & Weber 2016 (JCGT): precomputed per-triangle affine transform";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  struct Prepared {
    float row[3][4];  // a, b, c rows: coefficient x, y, z, constant
  };

  static Prepared prepare(const Triangle& tri) {
    const double v0[3] = {tri.v0.x, tri.v0.y, tri.v0.z};
    const double e1[3] = {double(tri.v1.x) - v0[0], double(tri.v1.y) - v0[1], double(tri.v1.z) - v0[2]};
    const double e2[3] = {double(tri.v2.x) - v0[0], double(tri.v2.y) - v0[1], double(tri.v2.z) - v0[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const int k = (std::fabs(n[0]) >= std::fabs(n[1]) && std::fabs(n[0]) >= std::fabs(n[2])) ? 0
                  : (std::fabs(n[1]) >= std::fabs(n[2]))                                   ? 1
                                                                                            : 2;
    Prepared p;
    if (!(n[k] != 0.0)) {  // zero area: no plane to transform to
      for (auto& r : p.row)
        for (float& x : r) x = std::numeric_limits<float>::quiet_NaN();
      return p;
    }
    double f[3] = {0, 0, 0};
    f[k] = 1.0;
    const auto crossd = [](const double* a, const double* b, double* out) {
      out[0] = a[1] * b[2] - a[2] * b[1];
      out[1] = a[2] * b[0] - a[0] * b[2];
      out[2] = a[0] * b[1] - a[1] * b[0];
    };
    double rows[3][3];
    crossd(e2, f, rows[0]);
    crossd(f, e1, rows[1]);
    for (int i = 0; i < 3; ++i) rows[2][i] = n[i];
    for (int r = 0; r < 3; ++r) {
      double constant = 0.0;
      for (int i = 0; i < 3; ++i) {
        const double coefficient = rows[r][i] / n[k];
        p.row[r][i] = static_cast<float>(coefficient);
        constant -= coefficient * v0[i];
      }
      p.row[r][3] = static_cast<float>(constant);
    }
    return p;
  }

  using RayData = Ray;
  static const Ray& precompute(const Ray& ray) { return ray; }

  static bool intersect(const Ray& ray, float tmax, const Prepared& m, TriangleHit& out) {
    const auto apply = [&](int r, Vec3f p, float w) {
      return m.row[r][0] * p.x + m.row[r][1] * p.y + m.row[r][2] * p.z + m.row[r][3] * w;
    };
    const float origin_c = apply(2, ray.org, 1.0f);
    const float dir_c = apply(2, ray.dir, 0.0f);
    const float t = -origin_c / dir_c;
    if (!(t > ray.tnear && t <= tmax)) return false;  // also rejects NaN (parallel ray, degenerate map)
    const Vec3f hit = ray.org + ray.dir * t;
    const float u = apply(0, hit, 1.0f);
    if (!(u >= 0.0f && u <= 1.0f)) return false;
    const float v = apply(1, hit, 1.0f);
    if (!(v >= 0.0f && u + v <= 1.0f)) return false;
    out = {t, u, v};
    return true;
  }
  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(ray, tmax, prepare(tri), out);
  }
};

}  // namespace raybench
