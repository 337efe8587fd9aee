// One ray against W triangles at once (W = 8 or 4): Möller–Trumbore (as
// prim/triangle_mt.h, same arithmetic in the same order, so each lane answers
// exactly as the scalar test) over triangles stored structure-of-arrays, as
// wide BVH leaves store them (issue 4). AVX2 (8 lanes) or SSE (4 lanes) when
// the compiler targets AVX2, else a scalar loop with the same interface.
// Unused lanes hold NaN and miss.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"
#include "raybench/prim/triangle_mt.h"
#include "raybench/simd/lanes.h"

namespace raybench {

inline constexpr bool kHaveAvx2 =
#if defined(__AVX2__)
    true;
#else
    false;
#endif

template <int W>
struct alignas(4 * W) TrianglePack {
  static constexpr int kWidth = W;
  float v0[3][W], e1[3][W], e2[3][W];

  // Packs up to W triangles; missing lanes get NaN and never hit.
  static TrianglePack pack(std::span<const Triangle> tris) {
    TrianglePack p;
    for (int lane = 0; lane < W; ++lane) {
      const bool used = lane < static_cast<int>(tris.size());
      const Vec3f v0 = used ? tris[lane].v0 : Vec3f{};
      const Vec3f e1 = used ? tris[lane].v1 - tris[lane].v0 : Vec3f{};
      const Vec3f e2 = used ? tris[lane].v2 - tris[lane].v0 : Vec3f{};
      for (int a = 0; a < 3; ++a) {
        const float nan = std::numeric_limits<float>::quiet_NaN();
        p.v0[a][lane] = used ? v0[a] : nan;
        p.e1[a][lane] = used ? e1[a] : nan;
        p.e2[a][lane] = used ? e2[a] : nan;
      }
    }
    return p;
  }
};
using Triangle8 = TrianglePack<8>;
using Triangle4 = TrianglePack<4>;

// The scalar form: lane by lane with the scalar kernel. Returns the lane of
// the closest hit in (tnear, tmax], or -1. On equal t the last such lane
// wins: tmax is inclusive, so a later lane at the same t replaces the hit.
template <int W>
inline int intersect_pack_scalar(const Ray& ray, float tmax, const TrianglePack<W>& t, TriangleHit& out) {
  int best = -1;
  for (int lane = 0; lane < W; ++lane) {
    const MollerTrumbore::Prepared p{{t.v0[0][lane], t.v0[1][lane], t.v0[2][lane]},
                                     {t.e1[0][lane], t.e1[1][lane], t.e1[2][lane]},
                                     {t.e2[0][lane], t.e2[1][lane], t.e2[2][lane]}};
    TriangleHit h;
    if (MollerTrumbore::intersect(ray, tmax, p, h)) {
      tmax = h.t;
      out = h;
      best = lane;
    }
  }
  return best;
}

#if defined(__AVX2__)
template <int W>
inline int intersect_pack_simd(const Ray& ray, float tmax, const TrianglePack<W>& t, TriangleHit& out) {
  using F = simd::FloatLanes<W>;
  const F dx = F::set1(ray.dir.x), dy = F::set1(ray.dir.y), dz = F::set1(ray.dir.z);
  const F e1x = F::load(t.e1[0]), e1y = F::load(t.e1[1]), e1z = F::load(t.e1[2]);
  const F e2x = F::load(t.e2[0]), e2y = F::load(t.e2[1]), e2z = F::load(t.e2[2]);
  // p = d x e2, det = e1 . p   (mul/sub kept separate: no FMA, as the scalar)
  const F px = dy * e2z - dz * e2y;
  const F py = dz * e2x - dx * e2z;
  const F pz = dx * e2y - dy * e2x;
  const F det = e1x * px + e1y * py + e1z * pz;
  const F inv_det = F::set1(1.0f) / det;
  const F sx = F::set1(ray.org.x) - F::load(t.v0[0]);
  const F sy = F::set1(ray.org.y) - F::load(t.v0[1]);
  const F sz = F::set1(ray.org.z) - F::load(t.v0[2]);
  const F u = (sx * px + sy * py + sz * pz) * inv_det;
  const F qx = sy * e1z - sz * e1y;
  const F qy = sz * e1x - sx * e1z;
  const F qz = sx * e1y - sy * e1x;
  const F v = (dx * qx + dy * qy + dz * qz) * inv_det;
  const F tt = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
  // Ordered, non-signalling comparisons: false for NaN, as the scalar's.
  const F zero = F::set1(0.0f), one = F::set1(1.0f);
  const F ok = (det != zero) & (u >= zero) & (u <= one) & (v >= zero) & (u + v <= one) & (tt > F::set1(ray.tnear)) &
               (tt <= F::set1(tmax));
  unsigned mask = ok.mask();
  if (!mask) return -1;
  alignas(32) float ts[W], us[W], vs[W];
  tt.storeu(ts);
  u.storeu(us);
  v.storeu(vs);
  int best = -1;
  for (; mask; mask &= mask - 1) {
    const int lane = __builtin_ctz(mask);
    if (best < 0 || ts[lane] <= ts[best]) best = lane;  // the scalar loop's tie rule
  }
  out = {ts[best], us[best], vs[best]};
  return best;
}
#endif

// The batched test the build can run: SIMD where available.
template <int W>
inline int intersect_pack(const Ray& ray, float tmax, const TrianglePack<W>& t, TriangleHit& out) {
#if defined(__AVX2__)
  return intersect_pack_simd(ray, tmax, t, out);
#else
  return intersect_pack_scalar(ray, tmax, t, out);
#endif
}

}  // namespace raybench
