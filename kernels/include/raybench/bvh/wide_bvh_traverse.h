// Single-ray traversal of a WideBvh<W> (W = 8: AVX2, W = 4: SSE, or their
// scalar fallback), closest hit and any hit.
// Algorithm: one W-wide slab test per node; the children entered are pushed
// in the node's stored far-to-near order for the ray's octant
// (WideNode::far_to_near), without sorting distances: one permutation orders
// them and a table-driven compaction pushes them with two stores,
// branch-free. Their entry distances go on the stack too, so a subtree
// farther than the current hit is skipped when popped. A leaf's packs are
// tested in order, W triangles at once. The traversal descends straight
// into the child it visits next instead of pushing it and popping it back,
// so a node with one child entered (the commonest case) pushes nothing, as
// Embree's traversal does (bvh_traverser1.h).
// Any hit (shadow rays) returns at the first hit in the interval and orders
// nothing per ray: the children entered are pushed in the node's lane order,
// ref only (its interval never shrinks), as Embree's any-hit traversal does.
// The lane order is the collapse's (WideLaneOrder): kByArea, the default
// build, visits the smallest box first, an approximation of Ize & Hansen's
// occlusion order ("RTSAH Traversal Order for Occlusion Rays", EG 2011);
// kOcclusion, the quality builds, is that termination order itself.
// The leaf test and the box test are policies: WideMollerTrumbore,
// WideMollerTrumboreEdges (needs WideLeaves::kMollerTrumboreEdges), or
// Bvh8Watertight (8 wide, needs WideLeaves::kVertices); SlabFma (the
// backends' plain test: one fused multiply-add per plane, as Embree's),
// Slab, or a conservative test: SlabRobust pads every exit, SlabRobustRay
// folds the padding into the ray (the backends' choice), SlabFmaRobust into
// per-ray offsets of the fused form (prim/aabb_slab_fma_robust.h).
// Guarantee: the answers are those of the leaf test over every triangle
// whose box the box test enters; with the watertight leaves and a
// conservative box test no ray leaks through the tree (as bvh2:watertight).
// A popped subtree is skipped only when it is farther than the current hit.
// With AVX-512VL the leaf tests compare into mask registers (same answers)
// and any hit's push compresses in a register; the node test and the
// ordered push stay AVX2's, which measured faster.
// measured (child orders, pushes, inlining, AVX-512; tried and dropped):
// docs/notes/kernels-wide-traversal.md
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "raybench/bvh/wide_bvh.h"
#include "raybench/math/inline.h"

namespace raybench {

namespace wide_bvh_detail {
// Each level pushes at most W - 1 entries beyond the one popped next; the
// tree's depth bounds the levels. The SIMD pushes store W entries whatever
// their count, hence the slack.
inline constexpr std::size_t kMaxDepth = 128;  // BVH2 depth is bounded by 96 (bvh2_traverse.h)

// The traversal stack, structure-of-arrays: node references and the entry
// distance of each.
template <int W>
struct Stack {
  static constexpr std::size_t kSize = (W - 1) * kMaxDepth + 2 * W;
  alignas(32) std::uint32_t ref[kSize];
  alignas(32) float entry[kSize];
  int top = 0;
};

// Pushes the children of `node` in `lanes` (bit i: lane i) in lane order,
// refs only (any hit: its interval never shrinks), as Embree does
// (bvh_traverser1.h). With AVX-512VL, 8 wide: one compress of the 8 refs in
// a register (vpcompressd; never its memory form, microcoded on AMD) and one
// store of 8 into the stack's slack, no branch per child; else child by
// child, which for the two or three children a shadow ray usually enters
// measured faster than AVX2's compacted push through a permute table
// (measured: docs/notes/kernels-wide-traversal.md).
template <int W>
inline void push_in_lane_order(Stack<W>& stack, const WideNode<W>& node, unsigned lanes) {
#if defined(RAYBENCH_AVX512)
  if constexpr (W == 8) {
    const __m256i refs = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(node.child));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.ref + stack.top),
                        _mm256_maskz_compress_epi32(static_cast<__mmask8>(lanes), refs));
    stack.top += __builtin_popcount(lanes);
    return;
  }
#endif
  for (; lanes; lanes &= lanes - 1) stack.ref[stack.top++] = node.child[__builtin_ctz(lanes)];
}

// Pushes the children of `node` in `lanes` in the node's far-to-near order
// for `octant`, lane by lane, with their entry distances: the scalar form of
// the compacted SIMD push below, same order. With `ordered` false, in lane
// order and without entry distances (push_in_lane_order).
template <bool Ordered, int W>
inline void push_children_scalar(Stack<W>& stack, const WideNode<W>& node, int octant, unsigned lanes,
                                 const float entry[W]) {
  if constexpr (!Ordered) {
    push_in_lane_order(stack, node, lanes);
  } else {
    for (int rank = 0; rank < W; ++rank) {
      const int lane = far_to_near_lane(node, octant, rank);
      if (!(lanes >> lane & 1u)) continue;
      stack.ref[stack.top] = node.child[lane];
      stack.entry[stack.top] = entry[lane];
      ++stack.top;
    }
  }
}

#if defined(__AVX2__)
// kCompactLanes<W>[mask]: the set bits of mask in increasing order, 4 bits
// each, lowest first: the permutation that packs the selected lanes to the front.
template <int W>
inline constexpr std::array<std::uint32_t, (1u << W)> kCompactLanes = [] {
  std::array<std::uint32_t, (1u << W)> table{};
  for (unsigned mask = 0; mask < (1u << W); ++mask) {
    int k = 0;
    for (unsigned lane = 0; lane < W; ++lane)
      if (mask >> lane & 1u) table[mask] |= lane << (4 * k++);
  }
  return table;
}();

// Unpacks W fields of `Bits` bits each from `packed` into the W lanes.
template <int W, int Bits>
inline simd::IntLanes<W> unpack_lanes(std::uint32_t packed) {
  using I = simd::IntLanes<W>;
  return I::set1(packed).shift_right(I::iota(Bits)) & I::set1((1u << Bits) - 1);
}

// Pushes the lanes of `refs`/`entry` selected by `lanes`, keeping their order.
template <int W>
inline void push_compacted(Stack<W>& stack, simd::IntLanes<W> refs, simd::FloatLanes<W> entry, unsigned lanes) {
  const simd::IntLanes<W> pick = unpack_lanes<W, 4>(kCompactLanes<W>[lanes]);
  refs.permute(pick).storeu(stack.ref + stack.top);
  entry.permute(pick).storeu(stack.entry + stack.top);
  stack.top += __builtin_popcount(lanes);
}

#endif
}  // namespace wide_bvh_detail

struct WideMollerTrumbore {
  static constexpr WideLeaves kLeaves = WideLeaves::kMollerTrumbore;  // what collapse_bvh2 must store
  // Whether every leaf of the trees this test serves holds one pack: the
  // traversal then tests a leaf's pack without the loop over several.
  static constexpr bool kOnePackLeaves = false;
  // Whether a hit's triangle is read from the pack the test has just loaded
  // (else from pack_prims, an array of its own: a caller tracing many rays
  // maps pack slots to triangles after the traversals, see traverse_wide).
  static constexpr bool kPrimsInPack = false;
  using RayData = Ray;
  static RayData precompute(const Ray& ray) { return ray; }
  // The lane of the pack's closest hit (intersect_pack), or -1. AnyLane
  // (any hit: some lane hit is the whole answer) asks for no more than a lane
  // that hits; this test answers the closest all the same: returning its
  // first hit lane measured 1.5-3 % slower on shadow rays, its choice of the
  // closest being a few instructions (docs/notes/kernels-wide-traversal.md).
  template <bool AnyLane = false, int W>
  RAYBENCH_INLINE static int intersect(const RayData& ray, float tmax, const WideBvh<W>& bvh, std::uint32_t pack, TriangleHit& out) {
    return intersect_pack(ray, tmax, bvh.packs[pack], out);
  }
  // The input triangle of a pack's lane.
  template <int W>
  RAYBENCH_INLINE static std::int32_t prim(const WideBvh<W>& bvh, std::uint32_t pack, int lane) {
    return bvh.pack_prims[WideBvh<W>::slot(pack, lane)];
  }
};

// WideMollerTrumbore's test on packs without normals (TriangleEdgePack,
// prim/triangle_mt_edges.h): a quarter less leaf memory.
struct WideMollerTrumboreEdges : WideMollerTrumbore {
  static constexpr WideLeaves kLeaves = WideLeaves::kMollerTrumboreEdges;
  template <bool AnyLane = false, int W>
  RAYBENCH_INLINE static int intersect(const RayData& ray, float tmax, const WideBvh<W>& bvh, std::uint32_t pack, TriangleHit& out) {
    return intersect_pack(ray, tmax, bvh.edge_packs[pack], out);
  }
};

struct Bvh8Watertight {
  static constexpr WideLeaves kLeaves = WideLeaves::kVertices;
  static constexpr bool kOnePackLeaves = true;  // collapse_bvh2 makes no other
  // Triangle indices through pack slots, not in the packs: with the normals
  // the test reads six cache lines and the indices would take a seventh;
  // the same speed with a seventh less leaf memory
  // (measured: docs/notes/kernels-wide-traversal.md).
  static constexpr bool kPrimsInPack = false;
  using RayData = WatertightTriangle::RayData;
  RAYBENCH_INLINE static RayData precompute(const Ray& ray) { return WatertightTriangle::precompute(ray); }
  template <bool AnyLane = false>
  RAYBENCH_INLINE static int intersect(const RayData& ray, float tmax, const Bvh8& bvh, std::uint32_t pack, TriangleHit& out) {
    return intersect8_watertight<AnyLane>(ray, tmax, bvh.vertex_packs[pack], out);
  }
  RAYBENCH_INLINE static std::int32_t prim(const Bvh8& bvh, std::uint32_t pack, int lane) {
    return bvh.pack_prims[Bvh8::slot(pack, lane)];
  }
};

// The Hit at (t, u, v) on lane `lane` of pack `pack`: its input triangle,
// or with PackSlots its pack slot (WideBvh::slot), for the caller to map.
template <typename Leaf, bool PackSlots, int W>
RAYBENCH_INLINE Hit pack_lane_hit(const WideBvh<W>& bvh, std::uint32_t pack, int lane, float t, float u, float v) {
  if constexpr (PackSlots) return {t, static_cast<std::int32_t>(WideBvh<W>::slot(pack, lane)), u, v};
  else return {t, Leaf::prim(bvh, pack, lane), u, v};
}

// Inlined into the caller's loop over rays: called, the ray a backend has
// just adjusted (with_nonnegative_tnear) goes through memory, where the
// traversal's first loads of it likely span two stores and wait for them
// (failed store forwarding). measured: docs/notes/kernels-wide-traversal.md
// Closest hit: the Hit. Any hit: whether the ray hits anything in its interval.
// With PackSlots the closest hit's prim is its pack slot (WideBvh::slot),
// for the caller to map through pack_prims once its rays are all traced:
// there, independent loads overlap; inside the traversal each could miss and
// hold it up (measured: docs/notes/kernels-wide-traversal.md).
// traverse_wide_from continues a ray's traversal in the subtree `start` (a
// node or a leaf) with the closest hit found so far, `hit` (none:
// the default Hit; its t is then the ray's tfar): what the packet traversal
// (wide_bvh_packet.h) hands a ray to when its packet thins out. From the
// root with no hit it is traverse_wide itself.
template <bool AnyHit, typename Leaf = WideMollerTrumbore, typename BoxTest = SlabFma, bool PackSlots = false, int W>
RAYBENCH_INLINE std::conditional_t<AnyHit, bool, Hit> traverse_wide_from(const WideBvh<W>& bvh, const Ray& ray,
                                                                         std::uint32_t start, Hit hit) {
  if (bvh.nodes.empty()) {
    if constexpr (AnyHit) return false;
    else return hit;
  }
  const Slab::Precomputed r = Slab::precompute(ray);
  // SlabFma serves rays with no zero direction component (the others take
  // Slab, exact for them), SlabFmaRobust too (the others take SlabRobust),
  // SlabRobustRay rays with tnear >= 0 (the others pad every exit): the
  // whole traversal runs with the test the ray gets.
  if constexpr (HasFallback<BoxTest>)
    if (!BoxTest::serves(r))
      return traverse_wide_from<AnyHit, Leaf, typename BoxTest::Fallback, PackSlots>(bvh, ray, start, hit);
  const int octant = ray_octant(r);
#if defined(__AVX2__)
  const RayLanes<W> ray_lanes = RayLanes<W>::template from<BoxTest>(r, bvh.bounds);
#endif
  const typename Leaf::RayData leaf_ray = Leaf::precompute(ray);
  // A popped subtree farther than the current hit is skipped; a
  // conservative test compares with the padded bound (each pads tmax or
  // every exit by SlabRobust's 8u), so it never skips what it entered.
  const auto reach_bound = [](float tmax) {
    if constexpr (BoxTest::accuracy == AccuracyClass::kConservative) return SlabRobust::padded(tmax);
    else return tmax;
  };
  float tmax = hit.hit() ? hit.t : ray.tfar;
  // Both bounds change with tmax only, at a hit: set there, not per node
  // (the padding alone is five scalar operations).
  float reach = reach_bound(tmax);
#if defined(__AVX2__)
  float exit_bound = box_exit_bound<BoxTest>(tmax);
#endif
  wide_bvh_detail::Stack<W> stack;
  stack.top = 0;
  std::uint32_t ref = start;  // the node or leaf visited next
  for (;;) {
    if (ref & WideBvh<W>::kLeafBit) {
      // Tests one pack within the hit so far (tmax inclusive: on equal t a
      // later pack's triangle wins, as a later lane within a pack); any hit:
      // whether it hit.
      const auto test_pack = [&](std::uint32_t pack) __attribute__((always_inline)) {
        TriangleHit th{};  // set when a lane hits (initialised: the scalar fallback sets it conditionally)
        // Any hit: a lane hit, which is the whole answer. The leaf test need
        // not find the closest lane (the watertight one stops at its first),
        // and the triangle is not looked up in pack_prims, an array the
        // traversal never reads otherwise, which the answer waited for
        // (measured: docs/notes/kernels-wide-traversal.md).
        const int lane = Leaf::template intersect<AnyHit>(leaf_ray, tmax, bvh, pack, th);
        if constexpr (!AnyHit) {
          if (lane >= 0) {
            tmax = th.t;
            reach = reach_bound(tmax);
#if defined(__AVX2__)
            exit_bound = box_exit_bound<BoxTest>(tmax);
#endif
            hit = pack_lane_hit<Leaf, PackSlots>(bvh, pack, lane, th.t, th.u, th.v);
          }
        }
        return lane >= 0;
      };
      if constexpr (Leaf::kOnePackLeaves) {
        // One pack per leaf: the watertight leaves, whose traversal a step
        // over several packs slowed by 4-10 %, more than such leaves gain
        // (measured: docs/notes/kernels-collapse.md), and the mixed tree's.
        // Also one inlined leaf test per traversal, not two as below.
        const bool hit_here = test_pack(WideBvh<W>::first_pack(ref));
        if constexpr (AnyHit)
          if (hit_here) return true;
      } else {
        // The leaf's packs in order: the first, then any others (most
        // leaves have one; a loop over all of them cost the single-pack
        // leaves 4-5 %: docs/notes/kernels-collapse.md).
        std::uint32_t pack = WideBvh<W>::first_pack(ref), more = WideBvh<W>::pack_count(ref) - 1;
        if constexpr (AnyHit) {
          if (test_pack(pack)) return true;
          for (; more != 0; --more)
            if (test_pack(++pack)) return true;
        } else {
          test_pack(pack);
          for (; more != 0; --more) test_pack(++pack);
        }
      }
    } else {
      const WideNode<W>& node = bvh.nodes[ref];
#if defined(__AVX2__)
      const BoxHits<W> box = slab_lanes<BoxTest>(ray_lanes, exit_bound, node.bounds);
      const unsigned hit_lanes = box.hit.mask();
      // Descend straight into the child visited next, without a round trip
      // through the stack; its entry distance is within tmax (the box test
      // just compared them). One child entered: nothing else to do.
      if (hit_lanes != 0 && (hit_lanes & (hit_lanes - 1)) == 0) {
        ref = node.child[__builtin_ctz(hit_lanes)];
        continue;
      }
      if constexpr (AnyHit) {
        // In lane order; the highest lane entered is visited first.
        if (hit_lanes) {
          const int highest = 31 - __builtin_clz(hit_lanes);
          wide_bvh_detail::push_in_lane_order(stack, node, hit_lanes & ~(1u << highest));
          ref = node.child[highest];
          continue;
        }
      } else if (hit_lanes) {
        // Permute the node's lanes into far-to-near order, push the entered
        // ones compacted, and visit the nearest (pushed last) at once.
        const simd::IntLanes<W> order =
            wide_bvh_detail::unpack_lanes<W, WideNode<W>::kOrderBits>(node.far_to_near[octant]);
        const unsigned entered = box.hit.permute(order).mask();
        const simd::IntLanes<W> refs = simd::IntLanes<W>::load(node.child).permute(order);
        wide_bvh_detail::push_compacted(stack, refs, box.t_entry.permute(order), entered);
        --stack.top;
        ref = node.child[far_to_near_lane(node, octant, 31 - __builtin_clz(entered))];
        continue;
      }
#else
      alignas(32) float entry[W];
      const unsigned entered = intersect_boxes<BoxTest>(r, tmax, node.bounds, entry);
      wide_bvh_detail::push_children_scalar<!AnyHit>(stack, node, octant, entered, entry);
#endif
    }
    // Pop the next subtree, skipping those farther than a hit found since
    // they were pushed (closest hit only: any hit returns at its first).
    do {
      if (stack.top == 0) {
        if constexpr (AnyHit) return false;
        else return hit;
      }
      --stack.top;
    } while (!AnyHit && !(stack.entry[stack.top] <= reach));
    ref = stack.ref[stack.top];
  }
}

template <bool AnyHit, typename Leaf = WideMollerTrumbore, typename BoxTest = SlabFma, bool PackSlots = false, int W>
RAYBENCH_INLINE std::conditional_t<AnyHit, bool, Hit> traverse_wide(const WideBvh<W>& bvh, const Ray& ray) {
  return traverse_wide_from<AnyHit, Leaf, BoxTest, PackSlots>(bvh, ray, 0, Hit{});
}

template <typename Leaf = WideMollerTrumbore, typename BoxTest = SlabFma, int W>
RAYBENCH_INLINE Hit intersect_wide(const WideBvh<W>& bvh, const Ray& ray) {
  return traverse_wide<false, Leaf, BoxTest>(bvh, ray);
}
template <typename Leaf = WideMollerTrumbore, typename BoxTest = SlabFma, int W>
RAYBENCH_INLINE bool occluded_wide(const WideBvh<W>& bvh, const Ray& ray) {
  return traverse_wide<true, Leaf, BoxTest>(bvh, ray);
}

}  // namespace raybench
