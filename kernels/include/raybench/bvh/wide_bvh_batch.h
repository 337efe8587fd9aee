// The wide BVH backends' build and batch traversals (bvh8, bvh4), in one
// place: the built-in backends (harness/src/backends/wide_bvh_backend.cpp)
// and the in-tree plugin that wraps bvh8 (plugin/bvh8/bvh8_plugin.cpp) call
// exactly these functions, so both build the same tree and trace the same
// hits with the same code.
#pragma once

#include <cstdint>
#include <span>

#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/wide_bvh_traverse.h"

namespace raybench {

// A BVH2 built by `builder` (then optimised by `reinsertion`), collapsed
// to W-wide nodes with the leaves `Leaf` traverses.
template <int W, typename Leaf>
WideBvh<W> build_wide_bvh(std::span<const Triangle> triangles, Bvh2Builder builder, Bvh2Reinsertion reinsertion) {
  Bvh2BuildOptions options;
  // The quality builds (spatial splits, reinsertion) build the BVH2 with
  // small leaves, scored as scalar tests: the collapse then gathers subtrees
  // of up to W triangles into packs where the wide tree's SAH says so
  // (wide_bvh_collapse.cpp), which fills nodes better. Measured on Sponza:
  // 4-10 % more rays/s, for 1.8x the build time. The default build keeps
  // leaves of up to W triangles (the SAH counts them in packs of W), as
  // fast to build as Embree's medium build (its light reinsertion too).
  const bool quality = builder == Bvh2Builder::kSbvh || reinsertion == Bvh2Reinsertion::kFull;
  options.leaf_granularity = quality ? 1 : W;
  options.max_leaf_size = W;  // a BVH2 leaf fits one pack
  options.reinsertion = reinsertion;
  // Any-hit traversal visits the children in lane order: the smallest box
  // first for the default build, the most likely to end the ray per cost
  // first for the quality builds (WideLaneOrder::kOcclusion).
  // Measured on shadow rays, one thread, interleaved: smallest first made
  // the default build 1.21x faster on Sponza, 1.01x on Conference, but
  // bvh8:reinsert 0.89x and 0.93x, bvh8:sbvh:reinsert 1.01x and 0.97x
  // (against the BVH2's order). The occlusion order against the BVH2's,
  // the quality builds with and without watertight leaves, 11 scenes (44
  // rows): geometric mean +2.9 %, 38 rows faster, Sponza-Dabrovic +5 to
  // +18 %, Sponza +3 to +10 %, Conference +4 to +7 %, but Lucy -9 to
  // -13 %. On the default build it was -18 % on Sponza (+15 % on
  // Sponza-Dabrovic, the mean unchanged): smallest first stays there.
  const WideLaneOrder lanes = quality ? WideLaneOrder::kOcclusion : WideLaneOrder::kByArea;
  return collapse_bvh2<W>(build_bvh2(triangles, builder, options), triangles, Leaf::kLeaves, lanes);
}

// Closest hit of every ray, traced as given: the caller has screened them
// (finite, tnear >= 0: the harness's rays/screening.h, once per ray set and
// outside timing), so the timed loop does the same per-ray work as Embree's.
template <typename Leaf, typename BoxTest, int W>
inline void intersect_wide_batch(const WideBvh<W>& bvh, std::span<const Ray> rays, std::span<Hit> hits) {
  // Leaves that do not carry their triangles report pack slots, mapped
  // to triangles here, after the batch (traverse_wide's PackSlots).
  constexpr bool kSlots = !Leaf::kPrimsInPack;
  for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = traverse_wide<false, Leaf, BoxTest, kSlots>(bvh, rays[i]);
  if constexpr (kSlots)
    for (Hit& h : hits)
      if (h.hit()) h.prim = bvh.pack_prims[static_cast<std::uint32_t>(h.prim)];
}

// Any hit of every ray within its interval: 1 when occluded, 0 otherwise;
// screened rays, as above.
template <typename Leaf, typename BoxTest, int W>
inline void occluded_wide_batch(const WideBvh<W>& bvh, std::span<const Ray> rays, std::span<std::uint8_t> occluded) {
  for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = occluded_wide<Leaf, BoxTest>(bvh, rays[i]);
}

}  // namespace raybench
