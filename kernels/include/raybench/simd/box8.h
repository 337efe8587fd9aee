// One ray against 8 axis-aligned boxes at once: the Slab test of
// prim/aabb_slab.h (planes chosen by the direction's sign, a NaN distance
// leaves the bound unchanged, a NaN bound misses) over boxes stored
// structure-of-arrays, as BVH8 nodes store their children (issue 4).
// With BoxTest = SlabRobust the exit is padded by its rounding error as in
// prim/aabb_slab_robust.h (Ize 2013): no box the exact ray touches is missed.
// AVX2 when the compiler targets it, else a scalar loop, same answers.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>

#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/simd/triangle8.h"  // kHaveAvx2 and <immintrin.h>

namespace raybench {

struct alignas(32) BBox8 {
  float lower[3][8], upper[3][8];

  // Packs up to 8 boxes; missing lanes are empty boxes, which every ray misses.
  static BBox8 pack(std::span<const BBox> boxes) {
    BBox8 p;
    for (int lane = 0; lane < 8; ++lane) {
      const BBox b = lane < static_cast<int>(boxes.size()) ? boxes[lane] : BBox{};
      for (int a = 0; a < 3; ++a) {
        p.lower[a][lane] = b.lower[a];
        p.upper[a][lane] = b.upper[a];
      }
    }
    return p;
  }
};

// Bit i set when box i is entered within [tnear, tmax]; entry[i] its entry
// distance (+inf for a missed box).
template <typename BoxTest = Slab>
inline unsigned intersect8_scalar(const Slab::Precomputed& r, float tmax, const BBox8& b, float entry[8]) {
  unsigned mask = 0;
  for (int lane = 0; lane < 8; ++lane) {
    BBox box;
    for (int a = 0; a < 3; ++a) {
      box.lower[a] = b.lower[a][lane];
      box.upper[a] = b.upper[a][lane];
    }
    BoxHit h;
    const bool hit = BoxTest::intersect(r, box, tmax, h);
    entry[lane] = hit ? h.t_entry : std::numeric_limits<float>::infinity();
    mask |= static_cast<unsigned>(hit) << lane;
  }
  return mask;
}

#if defined(__AVX2__)
// The AVX2 test with its answers left in registers for the traversal to
// permute: `hit` all ones in the lanes entered, `t_entry` their entry
// distances (meaningless in the other lanes).
struct Box8Hits {
  __m256 hit, t_entry;
};

template <typename BoxTest = Slab>
inline Box8Hits slab8_avx2(const Slab::Precomputed& r, float tmax, const BBox8& b) {
  __m256 t_entry = _mm256_set1_ps(r.tnear), t_exit = _mm256_set1_ps(tmax);
  for (int a = 0; a < 3; ++a) {
    const float* near_plane = r.negative[a] ? b.upper[a] : b.lower[a];
    const float* far_plane = r.negative[a] ? b.lower[a] : b.upper[a];
    const __m256 org = _mm256_set1_ps(r.org[a]), inv = _mm256_set1_ps(r.inv_dir[a]);
    const __m256 t_near = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(near_plane), org), inv);
    const __m256 t_far = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(far_plane), org), inv);
    // max_ps/min_ps return their second operand when either is NaN: a NaN
    // distance keeps the bound and a NaN bound stays NaN, exactly as
    // Slab::clip's comparisons do.
    t_entry = _mm256_max_ps(t_near, t_entry);
    t_exit = _mm256_min_ps(t_far, t_exit);
  }
  if constexpr (std::is_same_v<BoxTest, SlabRobust>) {
    // exit + |exit| * 8u, as SlabRobust::intersect (andnot clears the sign bit).
    const __m256 magnitude = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), t_exit);
    t_exit = _mm256_add_ps(t_exit, _mm256_mul_ps(magnitude, _mm256_set1_ps(SlabRobust::kPad)));
  }
  // Slab::overlaps: entry <= exit, and an entry at +inf is never reached.
  const __m256 hit = _mm256_and_ps(_mm256_cmp_ps(t_entry, t_exit, _CMP_LE_OQ),
                                   _mm256_cmp_ps(t_entry, _mm256_set1_ps(std::numeric_limits<float>::infinity()), _CMP_LT_OQ));
  return {hit, t_entry};
}

template <typename BoxTest = Slab>
inline unsigned intersect8_avx2(const Slab::Precomputed& r, float tmax, const BBox8& b, float entry[8]) {
  const Box8Hits h = slab8_avx2<BoxTest>(r, tmax, b);
  _mm256_store_ps(entry, _mm256_blendv_ps(_mm256_set1_ps(std::numeric_limits<float>::infinity()), h.t_entry, h.hit));
  return static_cast<unsigned>(_mm256_movemask_ps(h.hit));
}
#endif

template <typename BoxTest = Slab>
inline unsigned intersect8(const Slab::Precomputed& r, float tmax, const BBox8& b, float entry[8]) {
#if defined(__AVX2__)
  return intersect8_avx2<BoxTest>(r, tmax, b, entry);
#else
  return intersect8_scalar<BoxTest>(r, tmax, b, entry);
#endif
}

}  // namespace raybench
