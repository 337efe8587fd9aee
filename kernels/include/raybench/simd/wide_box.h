// One ray against W axis-aligned boxes at once (W = 8 or 4): the Slab test
// of prim/aabb_slab.h (planes chosen by the direction's sign, a NaN distance
// leaves the bound unchanged, a NaN bound misses) over boxes stored
// structure-of-arrays, as wide BVH nodes store their children.
// With BoxTest = SlabRobust the exit is padded by its rounding error as in
// prim/aabb_slab_robust.h (Ize 2013): no box the exact ray touches is missed;
// with SlabRobustRay the same guarantee comes from reciprocals scaled once
// per ray (prim/aabb_slab_robust_ray.h), no padding per box; with SlabFma
// each distance is one fused multiply-add (prim/aabb_slab_fma.h), and with
// SlabFmaRobust so too, conservative by offsets set once per ray
// (prim/aabb_slab_fma_robust.h).
// AVX2 (8 lanes) or SSE (4 lanes) when the compiler targets AVX2, else a
// scalar loop, same answers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>

#include "raybench/math/inline.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_fma.h"
#include "raybench/prim/aabb_slab_fma_robust.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/prim/aabb_slab_robust_ray.h"
#include "raybench/simd/lanes.h"
#include "raybench/simd/wide_triangle.h"  // kHaveAvx2

namespace raybench {

template <int W>
struct alignas(4 * W) BBoxWide {
  static constexpr int kWidth = W;
  float lower[3][W], upper[3][W];

  // Packs up to W boxes; missing lanes are empty boxes, which every ray misses.
  static BBoxWide pack(std::span<const BBox> boxes) {
    BBoxWide p;
    for (int lane = 0; lane < W; ++lane) {
      const BBox b = lane < static_cast<int>(boxes.size()) ? boxes[lane] : BBox{};
      for (int a = 0; a < 3; ++a) {
        p.lower[a][lane] = b.lower[a];
        p.upper[a][lane] = b.upper[a];
      }
    }
    return p;
  }

  // The union of the W boxes (empty lanes add nothing).
  BBox bounds() const {
    BBox all;
    for (int i = 0; i < W; ++i) all.extend(lane(i));
    return all;
  }

  BBox lane(int i) const {
    BBox box;
    for (int a = 0; a < 3; ++a) {
      box.lower[a] = lower[a][i];
      box.upper[a] = upper[a][i];
    }
    return box;
  }
};
using BBox8 = BBoxWide<8>;
using BBox4 = BBoxWide<4>;

// A box test that serves only some rays (SlabFma, SlabFmaRobust: no zero
// direction component; SlabRobustRay: tnear >= 0) names the test the others get:
// BoxTest::Fallback when !BoxTest::serves(r). Callers pick it once per ray.
template <typename BoxTest>
concept HasFallback = requires { typename BoxTest::Fallback; };

// Bit i set when box i is entered within [tnear, tmax]; entry[i] its entry
// distance (+inf for a missed box). The scalar form: box by box. A test
// that needs the extent of the planes (SlabFmaRobust) gets the W boxes' union.
template <typename BoxTest = Slab, int W>
inline unsigned intersect_boxes_scalar(const Slab::Precomputed& r, float tmax, const BBoxWide<W>& b, float entry[W]) {
  if constexpr (HasFallback<BoxTest>)
    if (!BoxTest::serves(r)) return intersect_boxes_scalar<typename BoxTest::Fallback>(r, tmax, b, entry);
  unsigned mask = 0;
  [[maybe_unused]] SlabFmaRobust::Offsets offsets;
  if constexpr (UsesExtent<BoxTest>) offsets = BoxTest::offsets(r, b.bounds());
  for (int lane = 0; lane < W; ++lane) {
    BoxHit h;
    bool hit;
    if constexpr (UsesExtent<BoxTest>) hit = BoxTest::intersect(r, offsets, b.lane(lane), tmax, h);
    else hit = BoxTest::intersect(r, b.lane(lane), tmax, h);
    entry[lane] = hit ? h.t_entry : std::numeric_limits<float>::infinity();
    mask |= static_cast<unsigned>(hit) << lane;
  }
  return mask;
}

#if defined(__AVX2__)
// The SIMD test with its answers left in registers for the traversal to
// permute: `hit` all ones in the lanes entered, `t_entry` their entry
// distances (meaningless in the other lanes).
template <int W>
struct BoxHits {
  simd::FloatLanes<W> hit, t_entry;
};

// A ray as the SIMD test reads it, set up once per ray: its origin, 1/d and
// o/d broadcast to every lane, and where each axis's entry planes lie in a
// BBoxWide (lower, or upper for a negative 1/d), so a node's test is loads
// and arithmetic only. far_inv_dir is what the far planes' distances are
// scaled by: 1/d, or SlabRobustRay's 1/d rounded outward; fused_near and
// fused_far what the fused distances subtract: o/d, or SlabFmaRobust's
// offsets, which need the extent of every plane the ray will be tested
// against (a BVH's root bounds).
template <int W>
struct RayLanes {
  simd::FloatLanes<W> org[3], inv_dir[3], far_inv_dir[3], fused_near[3], fused_far[3];
  int near_offset[3];  // from b.lower[a] to axis a's entry planes: 0 (lower) or 3W (upper)
  float tnear;

  template <typename BoxTest = Slab>
  RAYBENCH_INLINE static RayLanes from(const Slab::Precomputed& r, [[maybe_unused]] const BBox& extent) {
    using F = simd::FloatLanes<W>;
    RayLanes lanes;
    [[maybe_unused]] SlabFmaRobust::Offsets offsets;
    if constexpr (UsesExtent<BoxTest>) offsets = BoxTest::offsets(r, extent);
    for (int a = 0; a < 3; ++a) {
      lanes.org[a] = F::set1(r.org[a]);
      lanes.inv_dir[a] = F::set1(r.inv_dir[a]);
      if constexpr (std::is_same_v<BoxTest, SlabRobustRay>)
        lanes.far_inv_dir[a] = F::set1(SlabRobustRay::far_inv_dir(r.inv_dir[a]));
      else
        lanes.far_inv_dir[a] = lanes.inv_dir[a];
      if constexpr (UsesExtent<BoxTest>) {
        lanes.fused_near[a] = F::set1(offsets.near[a]);
        lanes.fused_far[a] = F::set1(offsets.far[a]);
      } else {
        lanes.fused_near[a] = lanes.fused_far[a] = F::set1(r.org[a] * r.inv_dir[a]);
      }
      lanes.near_offset[a] = r.negative[a] ? 3 * W : 0;
    }
    lanes.tnear = r.tnear;
    return lanes;
  }
};

// What a node's exits are clamped to for a ray whose closest hit so far is
// at tmax. Slab::overlaps asks entry <= exit and entry < +inf (an entry at
// +inf is never reached). With the exit clamped to the largest float,
// entry <= exit says both: one comparison per node instead of two and an
// and. The clamp goes on tmax (std::min keeps a NaN tmax NaN, a miss), or,
// for SlabRobust, on the padded exit, which may round up to +inf.
// SlabRobustRay and SlabFmaRobust pad tmax (a NaN tmax stays NaN through
// std::min, a miss); their far distances come padded from far_inv_dir or
// fused_far. A traversal computes it when tmax changes, not per node: the
// padding is five scalar operations.
template <typename BoxTest = Slab>
RAYBENCH_INLINE float box_exit_bound(float tmax) {
  constexpr bool kPadsTmax = std::is_same_v<BoxTest, SlabRobustRay> || std::is_same_v<BoxTest, SlabFmaRobust>;
  constexpr float kLargest = std::numeric_limits<float>::max();
  if constexpr (kPadsTmax) return std::min(SlabRobust::padded(tmax), kLargest);
  else if constexpr (std::is_same_v<BoxTest, SlabRobust>) return tmax;
  else return std::min(tmax, kLargest);
}

// With BoxTest = SlabFma or SlabFmaRobust each distance is one fused
// multiply-add; the caller has checked BoxTest::serves(r) (every 1/d
// finite), as intersect_boxes_simd and traverse_wide do once per ray.
// exit_bound is box_exit_bound<BoxTest>(tmax).
template <typename BoxTest = Slab, int W>
RAYBENCH_INLINE BoxHits<W> slab_lanes(const RayLanes<W>& r, float exit_bound, const BBoxWide<W>& b) {
  using F = simd::FloatLanes<W>;
  constexpr bool kRobust = std::is_same_v<BoxTest, SlabRobust>;
  constexpr bool kFused = std::is_same_v<BoxTest, SlabFma> || std::is_same_v<BoxTest, SlabFmaRobust>;
  constexpr float kLargest = std::numeric_limits<float>::max();
  F t_entry = F::set1(r.tnear), t_exit = F::set1(exit_bound);
  // The box's 6W floats as one array: lower[a] at a * W, upper[a] at (3 + a) * W.
  static_assert(offsetof(BBoxWide<W>, upper) == 3 * W * sizeof(float) && sizeof(BBoxWide<W>) == 6 * W * sizeof(float));
  const float* planes = reinterpret_cast<const float*>(&b);
  for (int a = 0; a < 3; ++a) {
    const F near_plane = F::load(planes + a * W + r.near_offset[a]);
    const F far_plane = F::load(planes + a * W + (3 * W - r.near_offset[a]));
    // max/min return their second operand when either is NaN: a NaN
    // distance keeps the bound and a NaN bound stays NaN, exactly as
    // Slab::clip's comparisons do.
    if constexpr (kFused) {
      t_entry = max(fmsub(near_plane, r.inv_dir[a], r.fused_near[a]), t_entry);
      t_exit = min(fmsub(far_plane, r.inv_dir[a], r.fused_far[a]), t_exit);
    } else {
      t_entry = max((near_plane - r.org[a]) * r.inv_dir[a], t_entry);
      t_exit = min((far_plane - r.org[a]) * r.far_inv_dir[a], t_exit);
    }
  }
  if constexpr (kRobust) {
    // exit + |exit| * 8u, as SlabRobust::intersect, then the clamp (min
    // returns its second operand, the padded exit, when that is NaN).
    t_exit = min(F::set1(kLargest), t_exit + t_exit.abs() * F::set1(SlabRobust::kPad));
  }
  return {t_entry <= t_exit, t_entry};
}

template <typename BoxTest = Slab, int W>
inline unsigned intersect_boxes_simd(const Slab::Precomputed& r, float tmax, const BBoxWide<W>& b, float entry[W]) {
  if constexpr (HasFallback<BoxTest>)
    if (!BoxTest::serves(r)) return intersect_boxes_simd<typename BoxTest::Fallback>(r, tmax, b, entry);
  const BoxHits<W> h =
      slab_lanes<BoxTest>(RayLanes<W>::template from<BoxTest>(r, b.bounds()), box_exit_bound<BoxTest>(tmax), b);
  alignas(32) float t[W];
  h.t_entry.storeu(t);
  const unsigned mask = h.hit.mask();
  for (int lane = 0; lane < W; ++lane) entry[lane] = mask >> lane & 1u ? t[lane] : std::numeric_limits<float>::infinity();
  return mask;
}
#endif

template <typename BoxTest = Slab, int W>
inline unsigned intersect_boxes(const Slab::Precomputed& r, float tmax, const BBoxWide<W>& b, float entry[W]) {
#if defined(__AVX2__)
  return intersect_boxes_simd<BoxTest>(r, tmax, b, entry);
#else
  return intersect_boxes_scalar<BoxTest>(r, tmax, b, entry);
#endif
}

}  // namespace raybench
