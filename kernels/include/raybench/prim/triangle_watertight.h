// Watertight ray-triangle intersection: Woop, Benthin & Wald, "Watertight
// Ray/Triangle Intersection", JCGT 2(1), 2013.
//
// The ray is made the +z axis of a sheared frame (per ray: the dominant
// direction axis kz, the two others kx, ky, swapped when dir[kz] < 0 to keep
// the winding, and the shear Sx, Sy, Sz). In that frame the test is a 2-D
// point-in-triangle test at the origin with the scaled barycentrics
// U, V, W computed as 2x2 determinants. Neighbouring triangles evaluate the
// same determinant for a shared edge (with opposite sign), so a ray through
// a shared edge or vertex hits at least one of them: no cracks. When a
// determinant is exactly 0 in float it is recomputed in double (the paper's
// fallback), so the edge decision is exact for these inputs.
// Two departures from the paper, both outside the edge test, so neither
// opens a crack: the shear x - Sx*z is one fused multiply-add (a vertex still
// gets the same sheared coordinates in every triangle that has it; the 2x2
// determinants are not fused, which would break their antisymmetry), and
// the distance interval is checked once, on the divided t, not first on the
// scaled t as well (an early reject for scalar code; the 8-wide test divides
// every lane anyway).
// Not culled: both faces hit. Degenerate triangles (U+V+W == 0) miss.
//
// Known failure: t is interpolated from the vertices' depths along the ray,
// so its error scales with the triangle's extent, not with t. A ray leaving
// a large triangle may hit it again just in front of its origin
// (KnownFailure_ARayLeavingALargeTriangleHitsItAgain: 0.8 % of Conference's
// diffuse and shadow rays through bvh8:watertight:robust). pbrt-v4's remedy,
// a hit only where t exceeds its error bound (Triangle::Intersect, "ensure
// that computed triangle t is conservatively greater than zero"), was
// built, with its x and y error terms taken from the unscaled depth (pbrt
// adds the scaled one, which rejected every hit of a short direction), and
// measured with the accuracy suite: the self-hits went (Conference 0.74 %
// and 0.79 %, Sponza 0.089 %, to 0-0.006 %), but the bound, which grows with
// the square of the depth over the triangle's size, dropped true hits:
// far-origin rays 0.3 -> 3.1 % wrong on Conference, 1.1 -> 15.5 % on Lucy,
// 12.6 -> 45 % on Sibenik; grazing 0.02-0.3 -> 0.7-2.6 %; reintersection
// 0-0.09 -> 0.4-1.4 %; tiny triangles 2.3 -> 6.3 %. It also cost
// bvh8:watertight:robust 7 % computed for the lanes that hit. Reverted.
#pragma once

#include <cmath>
#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct WatertightTriangle {
  static constexpr std::string_view name = "watertight";
  static constexpr std::string_view description = "Woop, Benthin & Wald 2013 (JCGT): sheared frame, no cracks on shared edges";
  static constexpr AccuracyClass accuracy = AccuracyClass::kWatertight;

  using Prepared = Triangle;
  static Prepared prepare(const Triangle& tri) { return tri; }

  struct RayData {
    Vec3f org;
    float tnear;
    int kx, ky, kz;
    float sx, sy, sz;
    // org[kx], org[ky], org[kz], set once per ray: indexed in the 8-wide
    // leaf, org[r.kx] compiled to two compares and branches per axis on the
    // origin GCC held in registers, about 20 instructions per leaf.
    float ox, oy, oz;
  };
  // The axis choice and the swap are branches on the direction, which an
  // incoherent ray set mispredicts: a probe put this setup at 2-8 % of
  // bvh8's time on the bunny's diffuse rays (two leaf tests per ray). A
  // branch-free form (kz by arithmetic, kx and ky from a table, dir and
  // org indexed in local arrays) measured, bvh8:watertight:robust, six
  // scenes, six interleaved rounds: diffuse rays +2.5 % (geometric mean,
  // five scenes faster), primary rays -4.5 % (the bunny and Lucy -8 %),
  // whose branches predict. With SSE instead (the lanes permuted by a
  // table row, one division for sx, sy and sz), primary rays -5 % and
  // diffuse rays unchanged (four rounds). The branches stay.
  RAYBENCH_INLINE static RayData precompute(const Ray& ray) {
    RayData r;
    r.org = ray.org;
    r.tnear = ray.tnear;
    const float ax = std::fabs(ray.dir.x), ay = std::fabs(ray.dir.y), az = std::fabs(ray.dir.z);
    r.kz = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    r.kx = (r.kz + 1) % 3;
    r.ky = (r.kx + 1) % 3;
    if (ray.dir[r.kz] < 0.0f) std::swap(r.kx, r.ky);  // keep the winding
    r.sx = ray.dir[r.kx] / ray.dir[r.kz];
    r.sy = ray.dir[r.ky] / ray.dir[r.kz];
    r.sz = 1.0f / ray.dir[r.kz];
    r.ox = ray.org[r.kx], r.oy = ray.org[r.ky], r.oz = ray.org[r.kz];
    return r;
  }

  static bool intersect(const RayData& r, float tmax, const Triangle& tri, TriangleHit& out) {
    const Vec3f a = tri.v0 - r.org, b = tri.v1 - r.org, c = tri.v2 - r.org;
    const auto shear = [](float s, float along, float across) { return std::fma(-s, along, across); };
    const float ax = shear(r.sx, a[r.kz], a[r.kx]), ay = shear(r.sy, a[r.kz], a[r.ky]);
    const float bx = shear(r.sx, b[r.kz], b[r.kx]), by = shear(r.sy, b[r.kz], b[r.ky]);
    const float cx = shear(r.sx, c[r.kz], c[r.kx]), cy = shear(r.sy, c[r.kz], c[r.ky]);
    float u = cx * by - cy * bx;  // weight of v0
    float v = ax * cy - ay * cx;  // weight of v1
    float w = bx * ay - by * ax;  // weight of v2
    // A determinant that is not 0 in float has its exact sign (rounding is
    // monotone: p > q gives fl(p) >= fl(q)), so one strictly negative and one
    // strictly positive already say the origin is outside, whatever the
    // others are. Only then are zeros decided, or a triangle with two equal
    // vertices (one determinant always 0) would take the double path on
    // every test.
    const auto outside = [](float u, float v, float w) {
      return (u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f);
    };
    if (outside(u, v, w)) return false;
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
      // On an edge in float: decide in double, where these products are exact.
      u = static_cast<float>(static_cast<double>(cx) * by - static_cast<double>(cy) * bx);
      v = static_cast<float>(static_cast<double>(ax) * cy - static_cast<double>(ay) * cx);
      w = static_cast<float>(static_cast<double>(bx) * ay - static_cast<double>(by) * ax);
      if (outside(u, v, w)) return false;
    }
    const float det = u + v + w;
    if (!(det != 0.0f)) return false;  // degenerate (or NaN)
    const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
    const float t_scaled = std::fma(u, az, std::fma(v, bz, w * cz));
    const float inv_det = 1.0f / det;
    out = {t_scaled * inv_det, v * inv_det, w * inv_det};
    return out.t > r.tnear && out.t <= tmax;
  }
  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(precompute(ray), tmax, tri, out);
  }
};

}  // namespace raybench
