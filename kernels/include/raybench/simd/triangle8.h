// One ray against 8 triangles at once: Möller–Trumbore (as prim/triangle_mt.h,
// same arithmetic in the same order, so each lane answers exactly as the
// scalar test) over triangles stored structure-of-arrays. AVX2 when the
// compiler targets it, else a scalar loop with the same interface.
// The layout BVH8 leaves will use (issue 4); unused lanes hold NaN and miss.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"
#include "raybench/prim/triangle_mt.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace raybench {

struct alignas(32) Triangle8 {
  float v0[3][8], e1[3][8], e2[3][8];

  // Packs up to 8 triangles; missing lanes get NaN and never hit.
  static Triangle8 pack(std::span<const Triangle> tris) {
    Triangle8 p;
    for (int lane = 0; lane < 8; ++lane) {
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

// The scalar form: lane by lane with the scalar kernel. Returns the lane of
// the closest hit in (tnear, tmax], or -1. On equal t the last such lane
// wins: tmax is inclusive, so a later lane at the same t replaces the hit.
inline int intersect8_scalar(const Ray& ray, float tmax, const Triangle8& t, TriangleHit& out) {
  int best = -1;
  for (int lane = 0; lane < 8; ++lane) {
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
inline int intersect8_avx2(const Ray& ray, float tmax, const Triangle8& t, TriangleHit& out) {
  const auto load = [](const float* p) { return _mm256_load_ps(p); };
  const __m256 dx = _mm256_set1_ps(ray.dir.x), dy = _mm256_set1_ps(ray.dir.y), dz = _mm256_set1_ps(ray.dir.z);
  const __m256 e1x = load(t.e1[0]), e1y = load(t.e1[1]), e1z = load(t.e1[2]);
  const __m256 e2x = load(t.e2[0]), e2y = load(t.e2[1]), e2z = load(t.e2[2]);
  // p = d x e2, det = e1 . p   (mul/sub kept separate: no FMA, as the scalar)
  const __m256 px = _mm256_sub_ps(_mm256_mul_ps(dy, e2z), _mm256_mul_ps(dz, e2y));
  const __m256 py = _mm256_sub_ps(_mm256_mul_ps(dz, e2x), _mm256_mul_ps(dx, e2z));
  const __m256 pz = _mm256_sub_ps(_mm256_mul_ps(dx, e2y), _mm256_mul_ps(dy, e2x));
  const auto dot3 = [](__m256 ax, __m256 ay, __m256 az, __m256 bx, __m256 by, __m256 bz) {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ax, bx), _mm256_mul_ps(ay, by)), _mm256_mul_ps(az, bz));
  };
  const __m256 det = dot3(e1x, e1y, e1z, px, py, pz);
  const __m256 inv_det = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
  const __m256 sx = _mm256_sub_ps(_mm256_set1_ps(ray.org.x), load(t.v0[0]));
  const __m256 sy = _mm256_sub_ps(_mm256_set1_ps(ray.org.y), load(t.v0[1]));
  const __m256 sz = _mm256_sub_ps(_mm256_set1_ps(ray.org.z), load(t.v0[2]));
  const __m256 u = _mm256_mul_ps(dot3(sx, sy, sz, px, py, pz), inv_det);
  const __m256 qx = _mm256_sub_ps(_mm256_mul_ps(sy, e1z), _mm256_mul_ps(sz, e1y));
  const __m256 qy = _mm256_sub_ps(_mm256_mul_ps(sz, e1x), _mm256_mul_ps(sx, e1z));
  const __m256 qz = _mm256_sub_ps(_mm256_mul_ps(sx, e1y), _mm256_mul_ps(sy, e1x));
  const __m256 v = _mm256_mul_ps(dot3(dx, dy, dz, qx, qy, qz), inv_det);
  const __m256 tt = _mm256_mul_ps(dot3(e2x, e2y, e2z, qx, qy, qz), inv_det);
  // Ordered, non-signalling comparisons: false for NaN, as the scalar's.
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  __m256 ok = _mm256_cmp_ps(det, zero, _CMP_NEQ_OQ);
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(u, zero, _CMP_GE_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(u, one, _CMP_LE_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(v, zero, _CMP_GE_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_add_ps(u, v), one, _CMP_LE_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(tt, _mm256_set1_ps(ray.tnear), _CMP_GT_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(tt, _mm256_set1_ps(tmax), _CMP_LE_OQ));
  int mask = _mm256_movemask_ps(ok);
  if (!mask) return -1;
  alignas(32) float ts[8], us[8], vs[8];
  _mm256_store_ps(ts, tt);
  _mm256_store_ps(us, u);
  _mm256_store_ps(vs, v);
  int best = -1;
  for (; mask; mask &= mask - 1) {
    const int lane = __builtin_ctz(static_cast<unsigned>(mask));
    if (best < 0 || ts[lane] <= ts[best]) best = lane;  // the scalar loop's tie rule
  }
  out = {ts[best], us[best], vs[best]};
  return best;
}
#endif

// The batched test the build can run: AVX2 where available.
inline int intersect8(const Ray& ray, float tmax, const Triangle8& t, TriangleHit& out) {
#if defined(__AVX2__)
  return intersect8_avx2(ray, tmax, t, out);
#else
  return intersect8_scalar(ray, tmax, t, out);
#endif
}

inline constexpr bool kHaveAvx2 =
#if defined(__AVX2__)
    true;
#else
    false;
#endif

}  // namespace raybench
