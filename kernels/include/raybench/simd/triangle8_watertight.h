// One ray against 8 triangles at once with the watertight test of Woop,
// Benthin & Wald (JCGT 2013), prim/triangle_watertight.h: the same float
// operations in the same order per lane, so each lane answers exactly as the
// scalar test, cracks-free on shared edges. A lane whose scaled barycentrics
// hit exactly 0 in float (a ray through an edge or vertex) is recomputed by
// the scalar test, which decides it in double as the paper prescribes.
// The triangles' own vertices are stored (v1 = v0 + e1 would be rounded,
// and neighbours must see bit-identical shared vertices), structure-of-arrays,
// and their normals, for the hit's distance (the plane's, not the paper's).
// AVX2 when the compiler targets it (its comparisons into mask registers with
// AVX-512VL), else a scalar loop, same answers.
// Guarantee: each lane's answer is the scalar test's (watertight, both
// faces, degenerate and NaN lanes miss); unused lanes hold NaN and never
// hit; on equal t the last lane wins.
// measured (addressing, where to divide, exact lanes):
// docs/notes/kernels-triangle-tests.md
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "raybench/prim/triangle_watertight.h"
#include "raybench/simd/wide_triangle.h"  // kHaveAvx2 and <immintrin.h>

namespace raybench {

struct alignas(64) TriangleVertices8 {
  // [vertex][axis][lane], then each lane's normal, WatertightTriangle::normal,
  // as v[kNormal][axis][lane], for the hit's distance
  // (WatertightTriangle::plane_distance). In one array with the vertices,
  // the test reaches the normal at a constant offset from a vertex row.
  static constexpr int kNormal = 3;
  float v[4][3][8];

  // Packs up to 8 triangles; missing lanes get NaN and never hit.
  static TriangleVertices8 pack(std::span<const Triangle> tris) {
    TriangleVertices8 p;
    for (int lane = 0; lane < 8; ++lane) {
      const bool used = lane < static_cast<int>(tris.size());
      const Vec3f normal = used ? WatertightTriangle::normal(tris[lane]) : Vec3f{};
      for (int a = 0; a < 3; ++a) {
        const float nan = std::numeric_limits<float>::quiet_NaN();
        p.v[0][a][lane] = used ? tris[lane].v0[a] : nan;
        p.v[1][a][lane] = used ? tris[lane].v1[a] : nan;
        p.v[2][a][lane] = used ? tris[lane].v2[a] : nan;
        p.v[kNormal][a][lane] = used ? normal[a] : nan;
      }
    }
    return p;
  }

  Triangle lane(int i) const {
    return {{v[0][0][i], v[0][1][i], v[0][2][i]}, {v[1][0][i], v[1][1][i], v[1][2][i]}, {v[2][0][i], v[2][1][i], v[2][2][i]}};
  }
};

// Lane by lane with the scalar test, every lane against the same tmax.
// Returns the lane of the closest hit in (tnear, tmax], or -1; on equal t the
// last such lane wins (as intersect_pack). With AnyLane, the first lane that
// hits, without looking for the closest; `out` is then not necessarily set.
template <bool AnyLane = false>
inline int intersect8_watertight_scalar(const WatertightTriangle::RayData& ray, float tmax, const TriangleVertices8& t,
                                        TriangleHit& out) {
  int best = -1;
  float best_t = 0.0f;
  for (int lane = 0; lane < 8; ++lane) {
    TriangleHit h{};
    if (WatertightTriangle::intersect(ray, tmax, t.lane(lane), h) && (best < 0 || h.t <= best_t)) {
      if constexpr (AnyLane) return lane;
      out = h;
      best_t = h.t;
      best = lane;
    }
  }
  return best;
}

#if defined(__AVX2__)
template <bool AnyLane = false>
RAYBENCH_INLINE int intersect8_watertight_simd(const WatertightTriangle::RayData& r, float tmax, const TriangleVertices8& t,
                                      TriangleHit& out) {
  // Axis kx of vertex k lies at px + kVertex * k: one base per axis and
  // constant offsets. Indexed as t.v[k][r.kx], the compiler kept nine
  // offsets, spilled them, and reloaded each before its vertex load. The
  // gain is fragile: the same bases taken from reinterpret_cast compiled
  // differently (measured: docs/notes/kernels-triangle-tests.md).
  constexpr int kVertex = 3 * 8;  // floats from one vertex's axis to the next vertex's
  static_assert(sizeof(TriangleVertices8::v[0]) == kVertex * sizeof(float));
  const float* px = t.v[0][r.kx];
  const float* py = t.v[0][r.ky];
  const float* pz = t.v[0][r.kz];
  const __m256 sx = _mm256_set1_ps(r.sx), sy = _mm256_set1_ps(r.sy);
  const __m256 ox = _mm256_set1_ps(r.ox), oy = _mm256_set1_ps(r.oy), oz = _mm256_set1_ps(r.oz);
  // Vertex k relative to the origin, (ax, ay, az) for the first one, and
  // sheared: (x, y) in the ray's frame.
  __m256 x[3], y[3], ax, ay, az;
  for (int k = 0; k < 3; ++k) {
    const __m256 rx = _mm256_sub_ps(_mm256_load_ps(px + kVertex * k), ox);
    const __m256 ry = _mm256_sub_ps(_mm256_load_ps(py + kVertex * k), oy);
    const __m256 rz = _mm256_sub_ps(_mm256_load_ps(pz + kVertex * k), oz);
    x[k] = _mm256_fnmadd_ps(sx, rz, rx);
    y[k] = _mm256_fnmadd_ps(sy, rz, ry);
    if (k == 0) ax = rx, ay = ry, az = rz;
  }
  const __m256 u = _mm256_sub_ps(_mm256_mul_ps(x[2], y[1]), _mm256_mul_ps(y[2], x[1]));
  const __m256 v = _mm256_sub_ps(_mm256_mul_ps(x[0], y[2]), _mm256_mul_ps(y[0], x[2]));
  const __m256 w = _mm256_sub_ps(_mm256_mul_ps(x[1], y[0]), _mm256_mul_ps(y[1], x[0]));
  const __m256 zero = _mm256_setzero_ps();
  // Strictly inside: all three of one sign, none zero, so the smallest
  // positive or the largest negative. On an edge in float: a zero among
  // them and no two of opposite signs, so the smallest or the largest is
  // zero (the scalar test's outside() fails, and it decides in double).
  // min/max return one of their operands, so these say what the scalar
  // test says on the lanes without NaN, and a lane whose u, v and w are all
  // NaN (an unused one) is neither. A NaN that hides a sign from them
  // leaves det NaN: no distance passes the interval, and the scalar test
  // misses it.
  const __m256 smallest = _mm256_min_ps(_mm256_min_ps(u, v), w), largest = _mm256_max_ps(_mm256_max_ps(u, v), w);
#if defined(RAYBENCH_AVX512)
  const __mmask8 inside = _mm256_cmp_ps_mask(smallest, zero, _CMP_GT_OQ) | _mm256_cmp_ps_mask(largest, zero, _CMP_LT_OQ);
  const int exact = _mm256_cmp_ps_mask(smallest, zero, _CMP_EQ_OQ) | _mm256_cmp_ps_mask(largest, zero, _CMP_EQ_OQ);
#else
  const __m256 inside = _mm256_or_ps(_mm256_cmp_ps(smallest, zero, _CMP_GT_OQ), _mm256_cmp_ps(largest, zero, _CMP_LT_OQ));
  const int exact = _mm256_movemask_ps(_mm256_or_ps(_mm256_cmp_ps(smallest, zero, _CMP_EQ_OQ), _mm256_cmp_ps(largest, zero, _CMP_EQ_OQ)));
#endif
  const __m256 det = _mm256_add_ps(_mm256_add_ps(u, v), w);
  // The distance to each triangle's plane, as WatertightTriangle::plane_distance.
  constexpr int kToNormal = kVertex * TriangleVertices8::kNormal;  // floats from a vertex-0 row to its normal row
  const __m256 nx = _mm256_load_ps(px + kToNormal), ny = _mm256_load_ps(py + kToNormal), nz = _mm256_load_ps(pz + kToNormal);
  const __m256 along_normal = _mm256_fmadd_ps(nx, ax, _mm256_fmadd_ps(ny, ay, _mm256_mul_ps(nz, az)));
  const __m256 speed_along_normal =
      _mm256_fmadd_ps(nx, _mm256_set1_ps(r.dx), _mm256_fmadd_ps(ny, _mm256_set1_ps(r.dy), _mm256_mul_ps(nz, _mm256_set1_ps(r.dz))));
  // Divided for every pack: an early return before the division (no lane
  // inside or exact, or on the paper's scaled distance) mispredicts and
  // measured slower, and so did dividing before the edge test
  // (measured: docs/notes/kernels-triangle-tests.md).
  const __m256 tt = _mm256_div_ps(along_normal, speed_along_normal);
  // A lane strictly inside has det != 0 (three nonzero values of one sign
  // do not sum to 0) and is never one of the exact lanes: no more tests
  // (measured: docs/notes/kernels-triangle-tests.md).
#if defined(RAYBENCH_AVX512)
  int mask = _mm256_mask_cmp_ps_mask(_mm256_mask_cmp_ps_mask(inside, tt, _mm256_set1_ps(r.tnear), _CMP_GT_OQ),
                                     tt, _mm256_set1_ps(WatertightTriangle::finite_tmax(tmax)), _CMP_LE_OQ);
#else
  const __m256 ok = _mm256_and_ps(inside, _mm256_and_ps(_mm256_cmp_ps(tt, _mm256_set1_ps(r.tnear), _CMP_GT_OQ),
                                                        _mm256_cmp_ps(tt, _mm256_set1_ps(WatertightTriangle::finite_tmax(tmax)), _CMP_LE_OQ)));
  int mask = _mm256_movemask_ps(ok);
#endif
  if (!mask && !exact) return -1;
  if constexpr (AnyLane)
    if (mask) return __builtin_ctz(static_cast<unsigned>(mask));  // a lane strictly inside hits
  // The barycentrics are divided for the closest lane only.
  alignas(32) float ts[8], vs[8], ws[8], dets[8];
  _mm256_store_ps(ts, tt);
  _mm256_store_ps(vs, v);
  _mm256_store_ps(ws, w);
  _mm256_store_ps(dets, det);
  int exact_hits = 0;
  TriangleHit exact_hit[8];
  for (int lanes = exact; lanes; lanes &= lanes - 1) {
    const int lane = __builtin_ctz(static_cast<unsigned>(lanes));
    if (WatertightTriangle::intersect(r, tmax, t.lane(lane), exact_hit[lane])) {
      if constexpr (AnyLane) return lane;
      ts[lane] = exact_hit[lane].t;
      mask |= 1 << lane, exact_hits |= 1 << lane;
    }
  }
  int best = -1;
  for (; mask; mask &= mask - 1) {
    const int lane = __builtin_ctz(static_cast<unsigned>(mask));
    if (best < 0 || ts[lane] <= ts[best]) best = lane;  // the scalar loop's tie rule
  }
  if (best < 0) return -1;
  if (exact_hits >> best & 1) {
    out = exact_hit[best];
  } else {
    const float inv_det = 1.0f / dets[best];  // as the scalar test
    out = {ts[best], vs[best] * inv_det, ws[best] * inv_det};
  }
  return best;
}
#endif

template <bool AnyLane = false>
RAYBENCH_INLINE int intersect8_watertight(const WatertightTriangle::RayData& ray, float tmax, const TriangleVertices8& t,
                                 TriangleHit& out) {
#if defined(__AVX2__)
  return intersect8_watertight_simd<AnyLane>(ray, tmax, t, out);
#else
  return intersect8_watertight_scalar<AnyLane>(ray, tmax, t, out);
#endif
}

}  // namespace raybench
