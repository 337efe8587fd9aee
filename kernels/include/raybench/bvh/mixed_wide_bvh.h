// A wide BVH (8 or 4 wide) over every primitive of a scene with analytic
// ones (issue 31): triangles, spheres, boxes and oriented boxes in one tree.
//
// Design: the triangle-only wide BVH, reused whole. The BVH2 is built by the
// binned SAH builder over the primitives' boxes (PrimitiveSpans::bounds) and
// collapsed by collapse_bvh2 as a triangle BVH2 is (the same nodes, lane
// orders and octant orders); the traversal is traverse_wide itself, with the
// leaf test MixedWideLeaf. Each pack of up to W primitives keeps its
// triangles in its first lanes, in the triangle pack the leaf test of the
// triangle-only tree reads (Möller–Trumbore, its edge form, or 8-wide
// watertight: one SIMD test for all of them), and its analytic primitives in
// the lanes after them, tested one by one (scalar) by their surface tests
// (mixed_leaf.h: SpherePrecise, Slab, Obb, or the seed-faithful ones).
// pack_prims holds every lane's global prim id, so hits map to ids as in
// the triangle-only tree. The packs without analytic primitives come first
// (in the collapse's order), the others after them, so a leaf tells which
// it is by comparing its pack index with first_mixed_pack, without a load.
// Cost against the triangle-only tree: per pack visited one comparison; per
// pack with analytic primitives 8 bytes (MixedPack), one load of it, and
// their tests, scalar, one after the other (any-hit included: the leaf test
// does not know the query, and a triangle hit ends an occlusion ray only
// after the pack's analytic tests); a pack with no triangle skips the SIMD
// test. 4 bytes per analytic primitive beside its copy. The collapse's SAH
// counts a pack as one test whatever it holds, which underestimates packs of
// several analytic primitives; packs moved to the end lose some locality.
// The collapse needs a triangle per primitive to pack: an analytic one is
// given a stand-in, a triangle across its box (whose area feeds the
// occlusion lane order's hit chance), which the repacking then drops, so no
// ray ever meets it.
// Guarantee: with a conservative box test the answers are those of the
// leaf tests over every primitive whose box the ray touches; hits keep
// global prim ids (PrimitiveSpans), analytic hits u = v = 0.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/bvh2.h"
#include "raybench/bvh/bvh2_reinsertion.h"
#include "raybench/bvh/mixed_leaf.h"
#include "raybench/bvh/wide_bvh.h"
#include "raybench/bvh/wide_bvh_traverse.h"

namespace raybench {

// The analytic lanes of one pack: lanes [lane, lane + count), count > 0,
// their references at MixedWideBvh::analytic_refs[first ...]. Lanes below
// `lane` are the pack's triangles.
struct MixedPack {
  std::uint32_t first = 0;
  std::uint8_t lane = 0;
  std::uint8_t count = 0;
};

// A WideBvh<W> whose packs may hold analytic primitives: MixedWideLeaf reads
// what this adds through the WideBvh<W> the traversal hands it.
template <int W>
struct MixedWideBvh : WideBvh<W> {
  std::uint32_t first_mixed_pack = 0;        // packs below hold triangles only
  std::vector<MixedPack> mixed_packs;        // pack first_mixed_pack + i: mixed_packs[i]
  std::vector<std::uint32_t> analytic_refs;  // mixed_ref of each analytic lane, pack by pack
  AnalyticLeafPrims analytic;                // the analytic primitives in pack order, and their tests

  std::size_t memory_bytes() const {
    return WideBvh<W>::memory_bytes() + mixed_packs.size() * sizeof(MixedPack) +
           analytic_refs.size() * sizeof(std::uint32_t) + analytic.memory_bytes();
  }
};

// The leaf test of a MixedWideBvh: TriangleLeaf's pack test (WideMollerTrumbore,
// WideMollerTrumboreEdges, Bvh8Watertight) on the pack's triangle lanes, then
// each analytic lane; returns the lane of the closest hit in (tnear, tmax]
// (on equal t the last tested), or -1; with AnyLane, a lane that hits (any
// hit), `out` then not necessarily set. Only for trees built by
// build_mixed_wide_bvh: it reads the MixedWideBvh behind the WideBvh.
template <typename TriangleLeaf>
struct MixedWideLeaf {
  static constexpr WideLeaves kLeaves = TriangleLeaf::kLeaves;
  // build_mixed_wide_bvh collapses with one pack per leaf (and its leaf
  // references say so after the packs move).
  static constexpr bool kOnePackLeaves = true;
  static constexpr bool kPrimsInPack = false;  // hits report pack slots, mapped through pack_prims

  struct RayData {
    typename TriangleLeaf::RayData triangle;
    AnalyticRay analytic;
  };
  RAYBENCH_INLINE static RayData precompute(const Ray& ray) {
    return {TriangleLeaf::precompute(ray), AnalyticRay::precompute(ray)};
  }

  template <bool AnyLane = false, int W>
  RAYBENCH_INLINE static int intersect(const RayData& ray, float tmax, const WideBvh<W>& bvh, std::uint32_t pack,
                                       TriangleHit& out) {
    const auto& m = static_cast<const MixedWideBvh<W>&>(bvh);
    if (pack < m.first_mixed_pack) return TriangleLeaf::template intersect<AnyLane>(ray.triangle, tmax, bvh, pack, out);
    const MixedPack p = m.mixed_packs[pack - m.first_mixed_pack];
    int lane = -1;
    if (p.lane != 0) {
      lane = TriangleLeaf::template intersect<AnyLane>(ray.triangle, tmax, bvh, pack, out);
      if constexpr (AnyLane) {
        if (lane >= 0) return lane;
      } else if (lane >= 0) {
        tmax = out.t;
      }
    }
    for (int k = 0; k < p.count; ++k) {
      float t;
      if (m.analytic.intersect(ray.analytic, tmax, m.analytic_refs[p.first + k], t)) {
        if constexpr (AnyLane) return p.lane + k;
        tmax = t;
        out = {t, 0.0f, 0.0f};
        lane = p.lane + k;
      }
    }
    return lane;
  }

  template <int W>
  RAYBENCH_INLINE static std::int32_t prim(const WideBvh<W>& bvh, std::uint32_t pack, int lane) {
    return bvh.pack_prims[WideBvh<W>::slot(pack, lane)];
  }
};

// The stand-in the collapse packs for an analytic primitive with box b: a
// triangle across the box, never traced.
inline Triangle mixed_stand_in(const BBox& b) { return {b.lower, b.upper, {b.lower.x, b.upper.y, b.upper.z}}; }

// The wide tree over every primitive of `prims` for TriangleLeaf's triangle
// packs, built as build_wide_bvh (wide_bvh_batch.h) builds the triangle-only
// tree with the binned SAH builder: leaves of up to W primitives (the SAH
// counting them in packs of W), or with the full reinsertion leaves of
// single primitives gathered by the collapse, in occlusion lane order.
// Throws std::length_error for more than kMaxMixedPrimsPerKind primitives of
// one kind.
template <int W, typename TriangleLeaf>
MixedWideBvh<W> build_mixed_wide_bvh(const PrimitiveSpans& prims, Bvh2Reinsertion reinsertion = Bvh2Reinsertion::kNone,
                                     AnalyticTestChoice tests = {}) {
  for (std::size_t n : {prims.triangles.size(), prims.spheres.size(), prims.boxes.size(), prims.obbs.size()})
    if (n > kMaxMixedPrimsPerKind) throw std::length_error("build_mixed_wide_bvh: too many primitives of one kind");
  const bool quality = reinsertion == Bvh2Reinsertion::kFull;
  Bvh2BuildOptions options;
  options.leaf_granularity = quality ? 1 : W;
  options.max_leaf_size = W;  // a BVH2 leaf fits one pack
  options.reinsertion = reinsertion;
  const HugePageVector<BBox> bounds = primitive_bounds(prims);
  Bvh2 bvh2 = build_bvh2_binned_sah(std::span<const BBox>(bounds), options);
  optimize_bvh2_after_build(bvh2, options);

  // Filled on every thread, never zeroed first (as primitive_bounds).
  HugePageVector<Triangle> stand_ins;
  stand_ins.resize(prims.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, stand_ins.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t id = r.begin(); id != r.end(); ++id)
      stand_ins[id] = id < prims.triangles.size() ? prims.triangles[id] : mixed_stand_in(bounds[id]);
  });
  MixedWideBvh<W> m;
  // Leaves of one pack: the packs with analytic primitives move to the end
  // below, which would part a leaf's consecutive packs.
  static_cast<WideBvh<W>&>(m) = collapse_bvh2<W>(bvh2, stand_ins, TriangleLeaf::kLeaves,
                                                 quality ? WideLaneOrder::kOcclusion : WideLaneOrder::kByArea, 1);

  // Each pack with analytic primitives: its triangles to its first lanes,
  // repacked without the stand-ins, its analytic primitives to the lanes
  // after them. A pack of triangles only is already what the triangle-only
  // tree holds.
  m.analytic.tests = tests;
  const std::size_t pack_count = m.pack_prims.size() / W;
  const auto analytic_lane = [&](std::size_t p, int lane) {
    const std::int32_t id = m.pack_prims[WideBvh<W>::slot(static_cast<std::uint32_t>(p), lane)];
    return id >= 0 && static_cast<std::size_t>(id) >= prims.first_sphere();
  };
  // Which packs hold analytic primitives, found on every thread; only
  // those are repacked, in pack order (analytic_refs' order).
  std::vector<std::uint8_t> is_mixed(pack_count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pack_count, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t p = r.begin(); p != r.end(); ++p) {
      bool mixed = false;
      for (int lane = 0; lane < W; ++lane) mixed = mixed || analytic_lane(p, lane);
      is_mixed[p] = mixed;
    }
  });
  std::vector<MixedPack> infos(pack_count);
  for (std::size_t p = 0; p < pack_count; ++p) {
    if (!is_mixed[p]) continue;
    std::int32_t ids[W];
    Triangle tris[W];
    int triangles = 0, count = 0;
    for (int lane = 0; lane < W; ++lane) {
      const std::int32_t id = m.pack_prims[WideBvh<W>::slot(static_cast<std::uint32_t>(p), lane)];
      if (id >= 0 && prims.kind(static_cast<std::size_t>(id)) == PrimitiveKind::kTriangle) {
        tris[triangles] = prims.triangles[static_cast<std::size_t>(id)];
        ids[triangles++] = id;
      }
    }
    count = triangles;
    MixedPack& info = infos[p];
    info.first = static_cast<std::uint32_t>(m.analytic_refs.size());
    info.lane = static_cast<std::uint8_t>(triangles);
    for (int lane = 0; lane < W; ++lane) {
      const std::int32_t id = m.pack_prims[WideBvh<W>::slot(static_cast<std::uint32_t>(p), lane)];
      if (id < 0 || prims.kind(static_cast<std::size_t>(id)) == PrimitiveKind::kTriangle) continue;
      ids[count++] = id;
      m.analytic_refs.push_back(m.analytic.add(prims, static_cast<std::size_t>(id)));
    }
    info.count = static_cast<std::uint8_t>(count - triangles);
    for (int lane = 0; lane < W; ++lane)
      m.pack_prims[WideBvh<W>::slot(static_cast<std::uint32_t>(p), lane)] = lane < count ? ids[lane] : -1;
    const std::span<const Triangle> used(tris, static_cast<std::size_t>(triangles));
    switch (TriangleLeaf::kLeaves) {
      case WideLeaves::kMollerTrumbore: m.packs[p] = TrianglePack<W>::pack(used); break;
      case WideLeaves::kMollerTrumboreEdges: m.edge_packs[p] = TriangleEdgePack<W>::pack(used); break;
      case WideLeaves::kVertices:
        if constexpr (W == 8) m.vertex_packs[p] = TriangleVertices8::pack(used);
        break;
    }
  }

  // The packs without analytic primitives first, then the others, each in
  // the collapse's order; the nodes' references follow.
  std::vector<std::uint32_t> new_index(pack_count);
  std::uint32_t next = 0;
  for (std::size_t p = 0; p < pack_count; ++p)
    if (infos[p].count == 0) new_index[p] = next++;
  m.first_mixed_pack = next;
  for (std::size_t p = 0; p < pack_count; ++p)
    if (infos[p].count != 0) {
      new_index[p] = next++;
      m.mixed_packs.push_back(infos[p]);
    }
  // Moved on every thread into fresh memory (this function's serial loops
  // were 5 % of its one-thread profile: docs/notes/kernels-builders.md).
  const auto permute = [&](auto& v, std::size_t per_pack) {
    if (v.empty()) return;
    std::remove_reference_t<decltype(v)> permuted;
    permuted.resize(v.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pack_count, 256), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t p = r.begin(); p != r.end(); ++p)
        std::copy_n(v.begin() + static_cast<std::ptrdiff_t>(p * per_pack), per_pack,
                    permuted.begin() + static_cast<std::ptrdiff_t>(new_index[p] * per_pack));
    });
    v.swap(permuted);
  };
  permute(m.packs, 1);
  permute(m.edge_packs, 1);
  permute(m.vertex_packs, 1);
  permute(m.pack_prims, W);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m.nodes.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      for (std::uint32_t& child : m.nodes[i].child)
        if (child != WideBvh<W>::kEmptyChild && (child & WideBvh<W>::kLeafBit))
          child = WideBvh<W>::leaf_ref(new_index[WideBvh<W>::first_pack(child)], 1);
  });
  return m;
}

}  // namespace raybench
