// One ray against W triangles at once (W = 8 or 4): Möller–Trumbore in its
// stored-normal form (prim/triangle_mt_normal.h, Embree's Triangle4 form:
// one cross product, fused multiply-adds, no division until a lane passes),
// same arithmetic in the same order, so each lane answers exactly as the
// scalar test, over triangles stored structure-of-arrays, as wide BVH leaves
// store them. AVX2 (8 lanes) or SSE with FMA (4 lanes) when the
// compiler targets AVX2 (with AVX-512VL its comparisons go into mask
// registers, same answers), else a scalar loop with the same interface.
// Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
// JGT 2(1), 1997.
// Guarantee: each lane answers as the scalar test (not watertight: a ray
// through a shared edge can miss both triangles); unused lanes hold NaN and
// miss. The stored normal costs 33 % more leaf memory (12 floats per
// triangle instead of 9) for a few per cent of speed; TriangleEdgePack
// stores the 9 (prim/triangle_mt_edges.h) and recomputes the normal per
// test, for scenes whose leaves do not fit in the caches.
// measured: docs/notes/kernels-triangle-tests.md
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>

#include "raybench/math/inline.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"
#include "raybench/prim/triangle_mt_edges.h"
#include "raybench/prim/triangle_mt_normal.h"
#include "raybench/simd/lanes.h"

namespace raybench {

inline constexpr bool kHaveAvx2 =
#if defined(__AVX2__)
    true;
#else
    false;
#endif

// Whether a pack stores its triangles' normals (TrianglePack) or leaves
// them to the test (TriangleEdgePack).
template <typename Pack>
concept StoresNormals = requires(const Pack& p) { p.normal; };

// Fills a pack's lanes with Pack::Kernel::prepare of up to W triangles;
// missing lanes get NaN and never hit.
template <typename Pack>
Pack pack_triangle_lanes(std::span<const Triangle> tris) {
  using Prepared = typename Pack::Kernel::Prepared;
  constexpr int W = Pack::kWidth;
  Pack p;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int lane = 0; lane < W; ++lane) {
    const bool used = lane < static_cast<int>(tris.size());
    const Prepared t = used ? Pack::Kernel::prepare(tris[lane]) : Prepared{};
    const auto put = [&](float (&x)[3][W], const Vec3f& v) {
      for (int a = 0; a < 3; ++a) x[a][lane] = used ? v[a] : nan;
    };
    put(p.v0, t.v0);
    put(p.e1, t.e1);
    put(p.e2, t.e2);
    if constexpr (StoresNormals<Pack>) put(p.normal, t.normal);
  }
  return p;
}

// Lane i of a pack as its scalar kernel's Prepared triangle.
template <typename Pack>
typename Pack::Kernel::Prepared triangle_lane(const Pack& p, int i) {
  constexpr int W = Pack::kWidth;
  const auto at = [&](const float (&x)[3][W]) { return Vec3f{x[0][i], x[1][i], x[2][i]}; };
  if constexpr (StoresNormals<Pack>) return {at(p.v0), at(p.e1), at(p.e2), at(p.normal)};
  else return {at(p.v0), at(p.e1), at(p.e2)};
}

template <int W>
struct alignas(4 * W) TrianglePack {
  static constexpr int kWidth = W;
  using Kernel = MollerTrumboreNormal;
  // MollerTrumboreNormal::Prepared, lane by lane.
  float v0[3][W], e1[3][W], e2[3][W], normal[3][W];

  // Packs up to W triangles; missing lanes get NaN and never hit.
  static TrianglePack pack(std::span<const Triangle> tris) { return pack_triangle_lanes<TrianglePack>(tris); }
  Kernel::Prepared lane(int i) const { return triangle_lane(*this, i); }
};
using Triangle8 = TrianglePack<8>;
using Triangle4 = TrianglePack<4>;

// The same test with the normal recomputed from the edges per test
// (prim/triangle_mt_edges.h): 9 floats per triangle instead of 12.
template <int W>
struct alignas(4 * W) TriangleEdgePack {
  static constexpr int kWidth = W;
  using Kernel = MollerTrumboreEdges;
  float v0[3][W], e1[3][W], e2[3][W];

  static TriangleEdgePack pack(std::span<const Triangle> tris) { return pack_triangle_lanes<TriangleEdgePack>(tris); }
  Kernel::Prepared lane(int i) const { return triangle_lane(*this, i); }
};

// The scalar form: lane by lane with the scalar kernel. Returns the lane of
// the closest hit in (tnear, tmax], or -1. On equal t the last such lane
// wins: tmax is inclusive, so a later lane at the same t replaces the hit.
template <typename Pack>
inline int intersect_pack_scalar(const Ray& ray, float tmax, const Pack& t, TriangleHit& out) {
  int best = -1;
  for (int lane = 0; lane < Pack::kWidth; ++lane) {
    TriangleHit h;
    if (Pack::Kernel::intersect(ray, tmax, t.lane(lane), h)) {
      tmax = h.t;
      out = h;
      best = lane;
    }
  }
  return best;
}

#if defined(__AVX2__)
template <typename Pack>
RAYBENCH_INLINE int intersect_pack_simd(const Ray& ray, float tmax, const Pack& t, TriangleHit& out) {
  constexpr int W = Pack::kWidth;
  using F = simd::FloatLanes<W>;
  const auto load3 = [](const float (&x)[3][W]) { return std::array<F, 3>{F::load(x[0]), F::load(x[1]), F::load(x[2])}; };
  const auto dot = [](const std::array<F, 3>& a, const std::array<F, 3>& b) {  // MollerTrumboreNormal::dot_fma
    return fmadd(a[0], b[0], fmadd(a[1], b[1], a[2] * b[2]));
  };
  const std::array<F, 3> d{F::set1(ray.dir.x), F::set1(ray.dir.y), F::set1(ray.dir.z)};
  // Stored, or MollerTrumboreEdges::normal lane by lane.
  const std::array<F, 3> normal = [&] {
    if constexpr (StoresNormals<Pack>) {
      return load3(t.normal);
    } else {
      const std::array<F, 3> e1 = load3(t.e1), e2 = load3(t.e2);
      return std::array<F, 3>{fmsub(e1[1], e2[2], e1[2] * e2[1]), fmsub(e1[2], e2[0], e1[0] * e2[2]),
                              fmsub(e1[0], e2[1], e1[1] * e2[0])};
    }
  }();
  const std::array<F, 3> c{F::load(t.v0[0]) - F::set1(ray.org.x), F::load(t.v0[1]) - F::set1(ray.org.y),
                           F::load(t.v0[2]) - F::set1(ray.org.z)};
  const std::array<F, 3> r{fmsub(d[1], c[2], d[2] * c[1]), fmsub(d[2], c[0], d[0] * c[2]), fmsub(d[0], c[1], d[1] * c[0])};
  const F det = dot(normal, d);
  const F abs_det = det.abs(), det_sign = det.sign();
  const F u_scaled = dot(r, load3(t.e2)) ^ det_sign;
  const F v_scaled = dot(r, load3(t.e1)) ^ det_sign;
  const F t_scaled = dot(normal, c) ^ det_sign;
  // Ordered, non-signalling comparisons: false for NaN, as the scalar's.
  const F zero = F::set1(0.0f);
  const F tnear = F::set1(ray.tnear);
#if defined(RAYBENCH_AVX512)
  // The same five comparisons chained under masks: each ands the last.
  const unsigned ok = gt_mask(t_scaled, abs_det * tnear,
                              le_mask(u_scaled + v_scaled, abs_det,
                                      ge_mask(v_scaled, zero, ge_mask(u_scaled, zero, ne_mask(det, zero)))));
  if (!ok) return -1;  // most packs: no division
  const F inv_det = F::set1(1.0f) / abs_det;
  const F tt = t_scaled * inv_det;
  unsigned mask = le_mask(tt, F::set1(tmax), gt_mask(tt, tnear, ok));
#else
  const F ok = (det != zero) & (u_scaled >= zero) & (v_scaled >= zero) & (u_scaled + v_scaled <= abs_det) &
               (t_scaled > abs_det * tnear);
  if (!ok.mask()) return -1;  // most packs: no division
  const F inv_det = F::set1(1.0f) / abs_det;
  const F tt = t_scaled * inv_det;
  unsigned mask = (ok & (tt > tnear) & (tt <= F::set1(tmax))).mask();
#endif
  if (!mask) return -1;
  alignas(32) float ts[W], us[W], vs[W];
  tt.storeu(ts);
  (u_scaled * inv_det).storeu(us);
  (v_scaled * inv_det).storeu(vs);
  int best = -1;
  for (; mask; mask &= mask - 1) {
    const int lane = __builtin_ctz(mask);
    if (best < 0 || ts[lane] <= ts[best]) best = lane;  // the scalar loop's tie rule
  }
  out = {ts[best], us[best], vs[best]};
  return best;
}
#endif

// The batched test the build can run: SIMD where available. Inlined into
// the traversal loop: called, it would spill and reload the ray's SIMD
// registers around every leaf (all of them are caller-saved)
// (measured: docs/notes/kernels-triangle-tests.md).
template <typename Pack>
RAYBENCH_INLINE int intersect_pack(const Ray& ray, float tmax, const Pack& t, TriangleHit& out) {
#if defined(__AVX2__)
  return intersect_pack_simd(ray, tmax, t, out);
#else
  return intersect_pack_scalar(ray, tmax, t, out);
#endif
}

}  // namespace raybench
