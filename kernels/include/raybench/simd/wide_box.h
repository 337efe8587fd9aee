// One ray against W axis-aligned boxes at once (W = 8 or 4): the Slab test
// of prim/aabb_slab.h (planes chosen by the direction's sign, a NaN distance
// leaves the bound unchanged, a NaN bound misses) over boxes stored
// structure-of-arrays, as wide BVH nodes store their children (issue 4).
// With BoxTest = SlabRobust the exit is padded by its rounding error as in
// prim/aabb_slab_robust.h (Ize 2013): no box the exact ray touches is missed.
// AVX2 (8 lanes) or SSE (4 lanes) when the compiler targets AVX2, else a
// scalar loop, same answers.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>

#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_robust.h"
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

// Bit i set when box i is entered within [tnear, tmax]; entry[i] its entry
// distance (+inf for a missed box). The scalar form: box by box.
template <typename BoxTest = Slab, int W>
inline unsigned intersect_boxes_scalar(const Slab::Precomputed& r, float tmax, const BBoxWide<W>& b, float entry[W]) {
  unsigned mask = 0;
  for (int lane = 0; lane < W; ++lane) {
    BoxHit h;
    const bool hit = BoxTest::intersect(r, b.lane(lane), tmax, h);
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

template <typename BoxTest = Slab, int W>
inline BoxHits<W> slab_lanes(const Slab::Precomputed& r, float tmax, const BBoxWide<W>& b) {
  using F = simd::FloatLanes<W>;
  F t_entry = F::set1(r.tnear), t_exit = F::set1(tmax);
  for (int a = 0; a < 3; ++a) {
    const float* near_plane = r.negative[a] ? b.upper[a] : b.lower[a];
    const float* far_plane = r.negative[a] ? b.lower[a] : b.upper[a];
    const F org = F::set1(r.org[a]), inv = F::set1(r.inv_dir[a]);
    // max/min return their second operand when either is NaN: a NaN
    // distance keeps the bound and a NaN bound stays NaN, exactly as
    // Slab::clip's comparisons do.
    t_entry = max((F::load(near_plane) - org) * inv, t_entry);
    t_exit = min((F::load(far_plane) - org) * inv, t_exit);
  }
  // exit + |exit| * 8u, as SlabRobust::intersect.
  if constexpr (std::is_same_v<BoxTest, SlabRobust>) t_exit = t_exit + t_exit.abs() * F::set1(SlabRobust::kPad);
  // Slab::overlaps: entry <= exit, and an entry at +inf is never reached.
  return {(t_entry <= t_exit) & (t_entry < F::set1(std::numeric_limits<float>::infinity())), t_entry};
}

template <typename BoxTest = Slab, int W>
inline unsigned intersect_boxes_simd(const Slab::Precomputed& r, float tmax, const BBoxWide<W>& b, float entry[W]) {
  const BoxHits<W> h = slab_lanes<BoxTest>(r, tmax, b);
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
