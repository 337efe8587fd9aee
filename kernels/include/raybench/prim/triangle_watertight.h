// Watertight ray-triangle intersection: Woop, Benthin & Wald, "Watertight
// Ray/Triangle Intersection", JCGT 2(1), 2013.
//
// The ray is made the +z axis of a sheared frame (per ray: the dominant
// direction axis kz, the two others kx, ky, swapped when dir[kz] < 0 to keep
// the winding, and the shear Sx, Sy). In that frame the test is a 2-D
// point-in-triangle test at the origin with the scaled barycentrics
// U, V, W computed as 2x2 determinants. Neighbouring triangles evaluate the
// same determinant for a shared edge (with opposite sign), so a ray through
// a shared edge or vertex hits at least one of them: no cracks. When a
// determinant is exactly 0 in float it is recomputed in double (the paper's
// fallback), so the edge decision is exact for these inputs.
// Three departures from the paper. Two are outside the edge test, so
// neither opens a crack: the shear x - Sx*z is one fused multiply-add (a
// vertex still gets the same sheared coordinates in every triangle that has
// it; the 2x2 determinants are not fused, which would break their
// antisymmetry), and the distance interval is checked once, on the divided
// t, not first on the scaled t as well (an early reject for scalar code; the
// 8-wide test divides every lane anyway).
// The third is the hit's t. The paper interpolates it from the vertices'
// sheared depths along the ray, T = U*Az + V*Bz + W*Cz over U+V+W, so its
// error scales with the triangle's extent, not with t: a ray leaving a large
// triangle hit it again just in front of its origin (Conference's floor,
// 2,600 units across: t = +1.5e-5 where the exact distance is -4.4e-5; 0.8 %
// of Conference's diffuse and shadow rays through bvh8:watertight,
// 0.09 % of Sponza's). Here t is the plane's distance from a vertex,
// n . (v0 - org) / n . dir with n from the stored vertices' edges, as
// Embree's Pluecker test and Moller-Trumbore compute it; it is exact for an
// axis-aligned floor, whose normal has two zero components. The hit decision
// (U, V, W) is the paper's, so the test stays watertight; only the distance
// of a hit changes. Before it, pbrt-v4's remedy was built and reverted: a
// hit only where the paper's t exceeds its error bound (Triangle::Intersect,
// "ensure that computed triangle t is conservatively greater than zero").
// It removed the self-hits (0.74 %, 0.79 % and 0.089 % to 0-0.006 %), but
// the bound, which grows with the square of the depth over the triangle's
// size, dropped true hits: far-origin rays 0.3 -> 3.1 % wrong on
// Conference, 1.1 -> 15.5 % on Lucy, 12.6 -> 45 % on Sibenik; grazing
// 0.02-0.3 -> 0.7-2.6 %; reintersection 0-0.09 -> 0.4-1.4 %; tiny
// triangles 2.3 -> 6.3 %; and it cost 7 % speed.
// Not culled: both faces hit. Degenerate triangles (U+V+W == 0) miss.
#pragma once

#include <cmath>
#include <limits>
#include <string_view>

#include "raybench/math/inline.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct WatertightTriangle {
  static constexpr std::string_view name = "watertight";
  static constexpr std::string_view description = "Woop, Benthin & Wald 2013 (JCGT): sheared frame, no cracks on shared edges; t from the plane";
  static constexpr AccuracyClass accuracy = AccuracyClass::kWatertight;

  using Prepared = Triangle;
  static Prepared prepare(const Triangle& tri) { return tri; }

  struct RayData {
    Vec3f org;
    float tnear;
    int kx, ky, kz;
    float sx, sy;
    // org[kx], org[ky], org[kz], set once per ray: indexed in the 8-wide
    // leaf, org[r.kx] compiled to two compares and branches per axis on the
    // origin GCC held in registers, about 20 instructions per leaf.
    float ox, oy, oz;
    // dir[kx], dir[ky], dir[kz], for the hit's distance (plane_distance).
    float dx, dy, dz;
  };
  // The axis choice and the swap are branches on the direction, which an
  // incoherent ray set mispredicts: a probe put this setup at 2-8 % of
  // bvh8's time on the bunny's diffuse rays (two leaf tests per ray). A
  // branch-free form (kz by arithmetic, kx and ky from a table, dir and
  // org indexed in local arrays) measured, bvh8:watertight, six
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
    r.ox = ray.org[r.kx], r.oy = ray.org[r.ky], r.oz = ray.org[r.kz];
    r.dx = ray.dir[r.kx], r.dy = ray.dir[r.ky], r.dz = ray.dir[r.kz];
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
    // Degenerate, or NaN (an infinite origin: the 8-wide test's lanes are
    // neither inside nor on an edge then).
    if (!(std::fabs(det) > 0.0f)) return false;
    const float inv_det = 1.0f / det;
    out = {plane_distance(r, normal(tri), a), v * inv_det, w * inv_det};
    return out.t > r.tnear && out.t <= finite_tmax(tmax);
  }

  // A ray inside the triangle by the edge test but parallel to its plane in
  // float has an infinite distance: no hit, even for tmax = inf. A NaN tmax
  // stays NaN (std::fmin would return the largest float), so nothing hits.
  RAYBENCH_INLINE static float finite_tmax(float tmax) {
    constexpr float kLargest = std::numeric_limits<float>::max();
    return tmax > kLargest ? kLargest : tmax;
  }

  // The triangle's normal, (v1 - v0) x (v2 - v0) from its stored vertices:
  // the 8-wide packs store it as computed here, so both forms get the same
  // distance bit for bit.
  static Vec3f normal(const Triangle& tri) { return cross(tri.v1 - tri.v0, tri.v2 - tri.v0); }

  // The hit's t: the distance along the ray to the triangle's plane,
  // n . (v0 - org) / n . dir, as Embree's Pluecker test and Moller-Trumbore
  // compute it, with n = normal(tri), summed in the frame's axis order (kx,
  // ky, kz). Not the paper's t, which is interpolated from the vertices'
  // sheared depths along the ray: its error scales with the triangle's
  // extent, not with t (see the header comment). n . dir is summed too, not
  // taken from the determinants (n . dir = -det * |dir[kz]| in exact
  // arithmetic): det carries the shear's rounding, relative to the
  // triangle's distance over its size, and the quotient of the precise
  // numerator and that denominator measured 500-1,500 ulp wrong at the 99th
  // percentile on primary rays (2 ulp before) and far-origin rays picked the
  // wrong triangle up to 13 times as often (the accuracy suite).
  RAYBENCH_INLINE static float plane_distance(const RayData& r, const Vec3f& n, const Vec3f& a) {
    const float along_normal = std::fma(n[r.kx], a[r.kx], std::fma(n[r.ky], a[r.ky], n[r.kz] * a[r.kz]));
    const float speed_along_normal = std::fma(n[r.kx], r.dx, std::fma(n[r.ky], r.dy, n[r.kz] * r.dz));
    return along_normal / speed_along_normal;
  }

  static bool intersect(const Ray& ray, float tmax, const Triangle& tri, TriangleHit& out) {
    return intersect(precompute(ray), tmax, tri, out);
  }
};

}  // namespace raybench
