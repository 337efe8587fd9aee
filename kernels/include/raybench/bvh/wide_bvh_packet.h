// Packets of coherent rays (32 with AVX-512, 16 with AVX2) traced together
// through a Bvh8, closest hit and any hit, with exactly the answers of the
// single-ray traversal (wide_bvh_traverse.h): the `bvh8:packet` backends.
// Algorithm: a packet visits a node once for all its rays (Wald, Slusallek,
// Benthin & Wagner, "Interactive Rendering with Coherent Ray Tracing", EG
// 2001). A conservative frustum test picks the children any ray may enter,
// with one 8-wide test of interval bounds over the packet's 1/d and o/d,
// padded beyond every rounding error (Wald, Boulos & Shirley, TOG 2007;
// Embree's node_intersector_frustum.h). Each picked child is then tested
// against every ray at once with the single-ray box test's own operations
// in the same order, so a ray is active in exactly the subtrees its own
// traversal enters. Children are visited in the node's far-to-near order
// for the packet's octant (closest hit) or in lane order (any hit), as each
// ray alone: the first at once, the others pushed (as Embree's coherent
// traversal goes on into the nearest child, bvh_intersector_hybrid.cpp); a
// popped subtree is skipped for a ray farther than its hit.
// So every ray meets its leaves in its own order and keeps its ties.
// Möller-Trumbore leaves reached by most of the packet's rays test each
// triangle against every ray at once (the pack test with the lanes' roles
// swapped, same operations); other leaves, and those reached by fewer
// rays, ray by ray with the single-ray pack test. A packet stays whole down
// to one active ray: handing the last few to single-ray traversal, as
// Embree's hybrid traversal does (bvh_intersector_hybrid.cpp), measured
// slower with 16-ray packets, in AVX-512 and AVX2 builds alike.
// Grouping: a group of kPacketRays consecutive rays forms a packet of those
// that share the first usable ray's octant (finite, no zero direction
// component: SlabFma's rays), point within kMinPacketCosine of its
// direction and start within kMaxPacketOriginSpread of its origin, then
// another led by the first ray left, up to kMaxPacketsPerGroup tries (a
// tile across an octant boundary or a depth edge); a packet needs
// kMinPacketRays, the rays left are traced alone. A batch whose first groups
// all fail a scalar glance at two of their rays (diffuse, uniform rays) is
// traced by the single-ray batch loop itself (wide_bvh_batch.h).
// Guarantee: every ray's answer is traverse_wide's with SlabFma, the Hit bit
// for bit and the occlusion bit, whatever the grouping (tested:
// kernels/tests/wide_bvh_packet_test.cpp). Design and measurements:
// docs/notes/kernels-packets.md
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>

#include "raybench/bvh/wide_bvh_batch.h"
#include "raybench/bvh/wide_bvh_traverse.h"
#include "raybench/math/prefetch.h"

namespace raybench {

// Rays per packet, one per float lane, in two registers: AVX-512's 32 or
// AVX2's 16. On Zen 5, tiled rays 18-26 % faster than 16 in one AVX-512
// register, and with AVX-512 off 9-12 % faster than 8 in one AVX2 register
// (docs/notes/kernels-packets.md).
#if defined(RAYBENCH_AVX512)
inline constexpr int kPacketRays = 32;
#else
inline constexpr int kPacketRays = 16;
#endif
inline constexpr int kMinPacketRays = 3;
// Active rays at a Möller-Trumbore leaf that test its packs each alone (the
// single-ray pack test, 8 triangles at once) rather than all at once
// (intersect_pack_rays, every ray at once): three quarters of the packet.
// Measured on Zen 4 with 16-ray packets, 12 of 16: tiled primary and shadow
// rays 5-8 % faster than with every leaf tested for all rays at once, 8 or
// 16 of 16 less so; with 32 on Zen 5, 16, 20, 24 and 28 of 32 within noise
// of each other (docs/notes/kernels-packets.md).
inline constexpr int kLeafAloneAtMost = kPacketRays * 3 / 4;
// Active rays at a node, for any hit, that test its 8 children each alone
// (children_ray_by_ray) instead of the frustum test and a packet-wide test per
// child it picks: 2. Measured on Zen 4: the terrain's tiled shadow rays
// 3-12 % faster, ten other scenes within noise; for closest hit, tiled
// primary rays were 2 % slower (docs/notes/kernels-packets.md).
inline constexpr int kNodeAloneAtMost = 2;
// How alike a packet's rays must be. Measured on Sponza, Conference, the
// terrain and the bunny (docs/notes/kernels-packets.md): from 0.99 and 2 %,
// these made tiled shadow rays 2-18 % faster and left the others as fast;
// looser ones (0.9 and 5 % or more) cost diffuse and uniform rays up to 8 %.
inline constexpr float kMinPacketCosine = 0.97f;        // directions within about 14 degrees of the first ray's
inline constexpr float kMaxPacketOriginSpread = 0.05f;  // of the tree's bounds diagonal
// kMaxPacketOriginSpread of the diagonal of `extent`, a tree's bounds.
inline float max_packet_origin_distance(const BBox& extent) { return kMaxPacketOriginSpread * length(extent.extent()); }

// Bits 0 to n - 1 (n <= 32): a group of n rays, one bit each.
inline unsigned lanes_below(int n) { return n >= 32 ? ~0u : (1u << n) - 1u; }

// The rays of a group traced as one packet (bit i: ray i of the group), and
// their shared octant; lanes == 0: every ray alone.
struct PacketPlan {
  unsigned lanes = 0;
  int octant = 0;
};

#if defined(__AVX2__)
namespace wide_packet_detail {

// One ray per lane: two registers of 16 (AVX-512) or of 8 (AVX2).
#if defined(RAYBENCH_AVX512)
using F = simd::LanePair<simd::FloatLanes<16>, 16>;
#else
using F = simd::LanePair<simd::FloatLanes<8>, 8>;
#endif
using F8 = simd::FloatLanes<8>;  // a node's 8 children

using M = decltype(F::set1(0.0f) <= F::set1(0.0f));  // a lane mask: LanePair's Mask

inline F nan_lanes() { return F::set1(std::numeric_limits<float>::quiet_NaN()); }

// The packet's rays lane by lane as the single-ray tests read each (the box
// test: 1/d and the fused offset o/d of RayLanes<8>::from<SlabFma>, each
// the same single rounding; the triangle test: origin, direction, tnear),
// and the frustum: per axis the bounds of 1/d and of o/d over the packet,
// widened by a padding that covers the rounding of both the per-ray
// distances and the interval's own (16 times the worst case: 3 half-ulps of
// the largest term). Lanes outside the plan hold their own ray or NaN.
struct Packet {
  std::array<F, 3> org, dir;
  F inv_dir[3], fused[3], tnear, tfar;
  int near_offset[3];  // the shared octant's entry planes (RayLanes::near_offset)
  F8 inv_lo[3], inv_hi[3], fused_hi[3], fused_lo[3];
  F8 tnear_min, exit_max;
};

// A glance at a group of rays[0..n) (n <= kPacketRays), in scalar code: the
// middle and the last ray go with the first (same octant, within the
// cosine and the origin distance). batch_looks_coherent samples a batch's
// first groups with it; a group where either does not looks incoherent.
inline bool looks_coherent(const Ray* rays, int n, float max_origin_distance) {
  const auto together = [&](const Ray& a, const Ray& b) {
    const float cosine = dot(a.dir, b.dir);
    const Vec3f offset = a.org - b.org;
    return a.dir.x * b.dir.x > 0.0f && a.dir.y * b.dir.y > 0.0f && a.dir.z * b.dir.z > 0.0f && cosine > 0.0f &&
           cosine * cosine >= kMinPacketCosine * kMinPacketCosine * dot(a.dir, a.dir) * dot(b.dir, b.dir) &&
           dot(offset, offset) <= max_origin_distance * max_origin_distance;
  };
  return n >= kMinPacketRays && together(rays[0], rays[n / 2]) && together(rays[0], rays[n - 1]);
}

// Whether a batch is worth planning packets for: some of its first
// kSampledGroups groups look coherent. A batch of incoherent rays is then
// traced exactly as the single-ray batch traces it, the same code, at the
// cost of a few glances.
inline constexpr int kSampledGroups = 4;
inline bool batch_looks_coherent(std::span<const Ray> rays, float max_origin_distance) {
  for (std::size_t g = 0; g < kSampledGroups && g * kPacketRays < rays.size(); ++g) {
    const std::size_t first = g * kPacketRays;
    const int n = static_cast<int>(std::min<std::size_t>(kPacketRays, rays.size() - first));
    if (looks_coherent(&rays[first], n, max_origin_distance)) return true;
  }
  return false;
}

// Reads rays[0..n) (n <= kPacketRays) into the lanes of `p` (NaN beyond
// n); returns the rays a packet can take: a finite origin and direction and
// no zero direction component.
inline unsigned load_group(const Ray* rays, int n, Packet& p) {
  // fields[k]: field k of a Ray's 8 floats (ox oy oz tnear dx dy dz tfar) of each ray, NaN beyond n: the rays
  // transposed from row loads (not gathered: docs/notes/kernels-packets.md), a short group's through a copy
  // padded with NaN rays.
  static_assert(sizeof(Ray) == 8 * sizeof(float));
  F fields[8];
  if (n == kPacketRays) {
    F::load_transposed8(reinterpret_cast<const float*>(rays), fields);
  } else {
    alignas(64) std::array<float, 8 * kPacketRays> padded;
    padded.fill(std::numeric_limits<float>::quiet_NaN());
    std::copy_n(reinterpret_cast<const float*>(rays), 8 * n, padded.data());
    F::load_transposed8(padded.data(), fields);
  }
  const F inf = F::set1(std::numeric_limits<float>::infinity());
  auto usable = F::set1(0.0f) <= F::set1(0.0f);  // every lane
  for (int a = 0; a < 3; ++a) {
    p.org[a] = fields[a];
    p.dir[a] = fields[4 + a];
    p.inv_dir[a] = F::set1(1.0f) / p.dir[a];  // Slab::precompute's 1/d, rounded alike
    p.fused[a] = p.org[a] * p.inv_dir[a];
    usable = usable & (p.org[a].abs() < inf) & (p.dir[a].abs() < inf) & (p.inv_dir[a].abs() < inf);
  }
  p.tnear = fields[3];
  p.tfar = fields[7];
  return usable.mask();
}

// A packet's lanes folded to 8 by min or max (for the frustum).
inline F8 fold_min(F8 x) { return x; }
inline F8 fold_max(F8 x) { return x; }
#if defined(RAYBENCH_AVX512)
inline F8 fold_min(simd::FloatLanes<16> x) { return min(simd::half_of<0>(x), simd::half_of<1>(x)); }
inline F8 fold_max(simd::FloatLanes<16> x) { return max(simd::half_of<0>(x), simd::half_of<1>(x)); }
#endif
template <typename Half, int H>
inline F8 fold_min(simd::LanePair<Half, H> x) { return fold_min(min(x.lo, x.hi)); }
template <typename Half, int H>
inline F8 fold_max(simd::LanePair<Half, H> x) { return fold_max(max(x.lo, x.hi)); }

// Among the rays `candidates` of a group loaded into `p` (load_group), the
// packet led by the first: those that share its octant, point within
// kMinPacketCosine of its direction and start within max_origin_distance
// of its origin; sets up p's frustum for them. No packet (lanes 0) when
// fewer than kMinPacketRays go together.
inline PacketPlan plan_packet(const Ray* rays, unsigned candidates, float max_origin_distance, const BBox& extent,
                              Packet& p) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const F inf = F::set1(kInf);
  if (std::popcount(candidates) < kMinPacketRays) return {};
  const M usable = M::from_bits(candidates);
  const int lead = std::countr_zero(candidates);
  std::array<F, 3> lead_org, lead_dir;
  for (int a = 0; a < 3; ++a) {
    lead_org[a] = F::set1(rays[lead].org[a]);
    lead_dir[a] = F::set1(rays[lead].dir[a]);
  }
  const auto dot = [](const std::array<F, 3>& x, const std::array<F, 3>& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  const F cosine = dot(p.dir, lead_dir);
  const std::array<F, 3> offset{p.org[0] - lead_org[0], p.org[1] - lead_org[1], p.org[2] - lead_org[2]};
  const F zero = F::set1(0.0f);
  // Same octant: every component's sign the lead's (none is zero: 1/d is finite).
  const auto in = usable & (p.dir[0] * lead_dir[0] > zero) & (p.dir[1] * lead_dir[1] > zero) &
                  (p.dir[2] * lead_dir[2] > zero) & (cosine > zero) &
                  (cosine * cosine >= F::set1(kMinPacketCosine * kMinPacketCosine) * dot(p.dir, p.dir) * dot(lead_dir, lead_dir)) &
                  (dot(offset, offset) <= F::set1(max_origin_distance * max_origin_distance));
  PacketPlan plan;
  plan.lanes = in.mask();
  if (std::popcount(plan.lanes) < kMinPacketRays) return {};
  // The frustum's bounds over the packet's rays, 16 reductions at once: rows
  // 0-2 of `lows` the smallest 1/d per axis, 3-5 the smallest o/d, 6 tnear;
  // `highs` the largest, 6 the exit bound (box_exit_bound<SlabFma>).
  const F minus_inf = F::set1(-kInf);
  const F exit_bound = min(p.tfar, F::set1(std::numeric_limits<float>::max()));
  F8 lows[8], highs[8];
  for (int a = 0; a < 3; ++a) {
    const bool negative = std::signbit(rays[lead].dir[a]);
    plan.octant |= static_cast<int>(negative) << a;
    p.near_offset[a] = negative ? 3 * 8 : 0;
    lows[a] = fold_min(select(in, p.inv_dir[a], inf));
    highs[a] = fold_max(select(in, p.inv_dir[a], minus_inf));
    lows[3 + a] = fold_min(select(in, p.fused[a], inf));
    highs[3 + a] = fold_max(select(in, p.fused[a], minus_inf));
  }
  lows[6] = lows[7] = fold_min(select(in, p.tnear, inf));
  highs[6] = highs[7] = fold_max(select(in, exit_bound, minus_inf));
  const F8 lo = simd::reduce_min_each(lows), hi = simd::reduce_max_each(highs);
  // pad: 2^-20 (largest |plane| * largest |1/d| + largest |o/d|) per axis, in lanes 0-2.
  const F8 largest = max(lo.abs(), hi.abs());  // |1/d| in lanes 0-2, |o/d| in 3-5
  const auto plane_abs = [&](int a) { return std::max(std::fabs(extent.lower[a]), std::fabs(extent.upper[a])); };
  const F8 planes{_mm256_setr_ps(plane_abs(0), plane_abs(1), plane_abs(2), 0.0f, 0.0f, 0.0f, 0.0f, 0.0f)};
  const F8 fused_largest = largest.permute(simd::IntLanes<8>{_mm256_setr_epi32(3, 4, 5, 3, 4, 5, 3, 4)});
  const F8 pad = F8::set1(0x1p-20f) * (planes * largest + fused_largest);
  for (int a = 0; a < 3; ++a) {
    const F8 pad_a = simd::broadcast_lane(pad, a);
    p.inv_lo[a] = simd::broadcast_lane(lo, a);
    p.inv_hi[a] = simd::broadcast_lane(hi, a);
    p.fused_hi[a] = simd::broadcast_lane(hi, 3 + a) + pad_a;
    p.fused_lo[a] = simd::broadcast_lane(lo, 3 + a) - pad_a;
  }
  p.tnear_min = simd::broadcast_lane(lo, 6);
  p.exit_max = simd::broadcast_lane(hi, 6);
  return plan;
}

// The children of `node` some ray of the packet may enter (bit i: lane i);
// never fewer than the exact tests enter. A NaN anywhere keeps the child.
inline unsigned frustum_children(const Packet& p, const WideNode<8>& node) {
  const float* planes = reinterpret_cast<const float*>(&node.bounds);
  F8 entry = p.tnear_min, exit = p.exit_max;
  for (int a = 0; a < 3; ++a) {
    const F8 near_plane = F8::load(planes + a * 8 + p.near_offset[a]);
    const F8 far_plane = F8::load(planes + a * 8 + (24 - p.near_offset[a]));
    // max/min keep their second operand (the bound so far) when the first is NaN.
    entry = max(min(near_plane * p.inv_lo[a], near_plane * p.inv_hi[a]) - p.fused_hi[a], entry);
    exit = min(max(far_plane * p.inv_lo[a], far_plane * p.inv_hi[a]) - p.fused_lo[a], exit);
  }
  return ~(entry > exit).mask() & 0xffu;
}

// Child `lane` of `node` against every ray, as slab_lanes<SlabFma> computes
// it for each: `node_tnear` is the rays' tnear in the lanes active at the
// node and NaN in the others (max keeps NaN, so they miss), `exit` their
// box_exit_bound. Returns the hit lanes; `entry` gets their entry distances
// and NaN in the other lanes.
RAYBENCH_INLINE unsigned child_hits(const Packet& p, const WideNode<8>& node, int lane, F node_tnear, F exit, F& entry) {
  const float* planes = reinterpret_cast<const float*>(&node.bounds);
  F t_entry = node_tnear, t_exit = exit;
  for (int a = 0; a < 3; ++a) {
    const F near_plane = F::set1(planes[a * 8 + p.near_offset[a] + lane]);
    const F far_plane = F::set1(planes[a * 8 + (24 - p.near_offset[a]) + lane]);
    t_entry = max(fmsub(near_plane, p.inv_dir[a], p.fused[a]), t_entry);
    t_exit = min(fmsub(far_plane, p.inv_dir[a], p.fused[a]), t_exit);
  }
  const auto hit = t_entry <= t_exit;
  entry = select(hit, t_entry, nan_lanes());
  return hit.mask();
}

// Any hit, for the few rays `active` at `node`: each ray tests the node's 8
// children at once as it would alone (slab_lanes<SlabFma> up to
// box_exit_bound, as traverse_wide), so it enters the same children. Sets
// child_rays[lane] to the rays that enter child `lane`; returns the
// children some ray enters.
inline unsigned children_ray_by_ray(const Packet& p, const Ray* rays, const float* tmax, unsigned active,
                                    const WideNode<8>& node, unsigned child_rays[8]) {
  unsigned entered = 0;
  for (int lane = 0; lane < 8; ++lane) child_rays[lane] = 0;
  for (; active; active &= active - 1) {
    const int i = std::countr_zero(active);
    RayLanes<8> rl;
    for (int a = 0; a < 3; ++a) {
      rl.inv_dir[a] = simd::broadcast_lane8(p.inv_dir[a], i);
      rl.fused_near[a] = rl.fused_far[a] = simd::broadcast_lane8(p.fused[a], i);
      rl.near_offset[a] = p.near_offset[a];
    }
    rl.tnear = rays[i].tnear;
    const unsigned hit_lanes = slab_lanes<SlabFma>(rl, box_exit_bound<SlabFma>(tmax[i]), node.bounds).hit.mask();
    entered |= hit_lanes;
    for (unsigned hl = hit_lanes; hl; hl &= hl - 1) child_rays[std::countr_zero(hl)] |= 1u << i;
  }
  return entered;
}

// Whether a leaf's triangles are tested for all rays at once (the
// Möller-Trumbore packs) or ray by ray with the leaf's own test (the
// watertight vertices).
template <typename Leaf>
inline constexpr bool kRayLanesLeaf =
    Leaf::kLeaves == WideLeaves::kMollerTrumbore || Leaf::kLeaves == WideLeaves::kMollerTrumboreEdges;

// The triangles of pack `t` against every ray at once: intersect_pack_simd
// with the roles of the lanes swapped (a triangle broadcast, a ray per
// lane), each step the same operation on the same operands, so each ray
// gets the same t, u, v. Triangles in lane order, each replacing a ray's
// hit when at or before it (tmax inclusive): the pack test's answer, the
// closest lane and the last of equal ones. `node_tnear` is NaN in the
// inactive lanes (they fail every comparison). Updates tmax, u, v and
// `lane_of` (the pack lane) of the rays it hit; returns them. AnyHit: only
// which rays some triangle hits within (node_tnear, tmax], no u, v, lane.
template <bool AnyHit, typename Pack>
RAYBENCH_INLINE unsigned intersect_pack_rays(const Packet& p, F node_tnear, const Pack& t, F& tmax, F& u, F& v,
                                             int* lane_of) {
  const F zero = F::set1(0.0f);
  const auto dot = [](const std::array<F, 3>& a, const std::array<F, 3>& b) {  // MollerTrumboreNormal::dot_fma
    return fmadd(a[0], b[0], fmadd(a[1], b[1], a[2] * b[2]));
  };
  // First every triangle's tests but the distance's bound (no branch: which
  // triangles pass for which rays is data, not control flow), then, in lane
  // order, only those that some ray passed.
  alignas(64) float t_scaled_of[8][kPacketRays], abs_det_of[8][kPacketRays], u_scaled_of[8][kPacketRays],
      v_scaled_of[8][kPacketRays];
  M ok_of[8];
  unsigned candidates = 0;
  // Only the pack's triangles: its unused lanes (NaN, never hit) are skipped,
  // as a quality build's packs hold 5 of 8 on average.
  const F8 v0_x = F8::load(t.v0[0]);
  for (unsigned filled = (v0_x <= v0_x).mask(); filled; filled &= filled - 1) {
    const int j = std::countr_zero(filled);
    const auto at = [&](const float (&x)[3][8]) { return std::array<F, 3>{F::set1(x[0][j]), F::set1(x[1][j]), F::set1(x[2][j])}; };
    const std::array<F, 3> e1 = at(t.e1), e2 = at(t.e2);
    const std::array<F, 3> normal = [&] {
      if constexpr (StoresNormals<Pack>) {
        return at(t.normal);
      } else {
        return std::array<F, 3>{fmsub(e1[1], e2[2], e1[2] * e2[1]), fmsub(e1[2], e2[0], e1[0] * e2[2]),
                                fmsub(e1[0], e2[1], e1[1] * e2[0])};
      }
    }();
    const std::array<F, 3>& d = p.dir;
    const std::array<F, 3> c{F::set1(t.v0[0][j]) - p.org[0], F::set1(t.v0[1][j]) - p.org[1], F::set1(t.v0[2][j]) - p.org[2]};
    const std::array<F, 3> r{fmsub(d[1], c[2], d[2] * c[1]), fmsub(d[2], c[0], d[0] * c[2]), fmsub(d[0], c[1], d[1] * c[0])};
    const F det = dot(normal, d);
    const F abs_det = det.abs(), det_sign = det.sign();
    const F u_scaled = dot(r, e2) ^ det_sign;
    const F v_scaled = dot(r, e1) ^ det_sign;
    const F t_scaled = dot(normal, c) ^ det_sign;
    ok_of[j] = (det != zero) & (u_scaled >= zero) & (v_scaled >= zero) & (u_scaled + v_scaled <= abs_det) &
               (t_scaled > abs_det * node_tnear);
    candidates |= static_cast<unsigned>(ok_of[j].mask() != 0) << j;
    t_scaled.storeu(t_scaled_of[j]);
    abs_det.storeu(abs_det_of[j]);
    if constexpr (!AnyHit) {
      u_scaled.storeu(u_scaled_of[j]);
      v_scaled.storeu(v_scaled_of[j]);
    }
  }
  unsigned hit_rays = 0;
  for (; candidates; candidates &= candidates - 1) {
    const int j = std::countr_zero(candidates);
    const F inv_det = F::set1(1.0f) / F::load(abs_det_of[j]);
    const F tt = F::load(t_scaled_of[j]) * inv_det;
    const auto accept = ok_of[j] & (tt > node_tnear) & (tt <= tmax);
    unsigned rays = accept.mask();
    if constexpr (AnyHit) {
      hit_rays |= rays;
      continue;
    }
    if (!rays) continue;
    tmax = select(accept, tt, tmax);
    u = select(accept, F::load(u_scaled_of[j]) * inv_det, u);
    v = select(accept, F::load(v_scaled_of[j]) * inv_det, v);
    hit_rays |= rays;
    for (; rays; rays &= rays - 1) lane_of[std::countr_zero(rays)] = j;
  }
  return hit_rays;
}

// The traversal stack: a subtree and each ray's entry distance into it (NaN
// for the rays that do not enter it), or for any hit, whose interval never
// shrinks, only the rays that enter it (bit i: ray i).
struct PacketStack {
  static constexpr std::size_t kSize = 8 * wide_bvh_detail::kMaxDepth + 8;
  alignas(64) float entry[kSize][kPacketRays];
  std::uint32_t lanes[kSize];
  std::uint32_t ref[kSize];
  int top = 0;
};

}  // namespace wide_packet_detail

// Traces the rays of `plan` among rays[0..kPacketRays) as one packet, set
// up in `p` by plan_packet. Closest hit: hits[i] for each ray i of
// the plan (the pack slot as prim with PackSlots, as traverse_wide). Any
// hit: occluded[i].
template <bool AnyHit, typename Leaf, bool PackSlots>
void trace_packet(const Bvh8& bvh, const Ray* rays, const wide_packet_detail::Packet& p, PacketPlan plan, Hit* hits,
                  std::uint8_t* occluded) {
  using namespace wide_packet_detail;
  typename Leaf::RayData leaf_ray[kPacketRays];
  // Each ray's hit distance so far, 0 outside the plan; written as a vector
  // where it is read as one (scalar stores could not be forwarded to the load).
  alignas(64) float tmax[kPacketRays];
  const M planned = M::from_bits(plan.lanes);
  select(planned, p.tfar, F::set1(0.0f)).storeu(tmax);
  // Each ray's closest hit so far, field by field (its t is tmax): a Hit
  // array written field by field and read whole stalled on every read.
  std::int32_t hit_prim[kPacketRays];
  float hit_u[kPacketRays], hit_v[kPacketRays];
  std::fill_n(hit_prim, kPacketRays, kNoHit);
  const auto set_hit = [&](int i, const Hit& h) {
    tmax[i] = h.t;
    hit_prim[i] = h.prim;
    hit_u[i] = h.u;
    hit_v[i] = h.v;
  };
  const auto hit_of = [&](int i) { return hit_prim[i] == kNoHit ? Hit{} : Hit{tmax[i], hit_prim[i], hit_u[i], hit_v[i]}; };
  if constexpr (!kRayLanesLeaf<Leaf>)
    for (unsigned lanes = plan.lanes; lanes; lanes &= lanes - 1)
      leaf_ray[std::countr_zero(lanes)] = Leaf::precompute(rays[std::countr_zero(lanes)]);
  constexpr float kLargest = std::numeric_limits<float>::max();
  F reach = F::load(tmax);  // SlabFma is not conservative: a subtree is skipped when farther than tmax
  F exit;
  const auto set_exit = [&] { exit = min(reach, F::set1(kLargest)); };
  set_exit();
  const auto update_bounds = [&] {
    reach = F::load(tmax);
    set_exit();
  };
  // An occluded ray's tmax, so that it enters nothing more (any hit), and
  // the occluded rays. Any hit's reach is always tmax as a vector: marking
  // narrows both.
  const float kDone = -std::numeric_limits<float>::infinity();
  unsigned done = 0;
  const auto mark_occluded = [&](unsigned lanes) {
    done |= lanes;
    reach = select(M::from_bits(lanes), F::set1(kDone), reach);
    reach.storeu(tmax);
    set_exit();
  };
  PacketStack stack;
  std::uint32_t ref = 0;
  unsigned active = plan.lanes;
  F node_tnear = select(planned, p.tnear, nan_lanes());  // tnear in the lanes active at the node, NaN in the others
  for (;;) {
    if (ref & Bvh8::kLeafBit) {
      // The leaf's packs in order, as the single-ray traversal tests them.
      const std::uint32_t first = Bvh8::first_pack(ref), end = first + Bvh8::pack_count(ref);
      const bool ray_lanes = kRayLanesLeaf<Leaf> && std::popcount(active & ~done) > kLeafAloneAtMost;
      for (std::uint32_t pack = first; pack != end; ++pack) {
        if (ray_lanes) {
          if constexpr (kRayLanesLeaf<Leaf>) {
            F best_t = reach, u = F::set1(0.0f), v = u;
            alignas(64) int lane_of[kPacketRays];
            unsigned hit_rays;
            if constexpr (Leaf::kLeaves == WideLeaves::kMollerTrumbore)
              hit_rays = intersect_pack_rays<AnyHit>(p, node_tnear, bvh.packs[pack], best_t, u, v, lane_of);
            else
              hit_rays = intersect_pack_rays<AnyHit>(p, node_tnear, bvh.edge_packs[pack], best_t, u, v, lane_of);
            if (hit_rays) {
              if constexpr (AnyHit) {
                mark_occluded(hit_rays);
              } else {
                alignas(64) float us[kPacketRays], vs[kPacketRays];
                best_t.storeu(tmax);
                u.storeu(us);
                v.storeu(vs);
                for (unsigned lanes = hit_rays; lanes; lanes &= lanes - 1) {
                  const int i = std::countr_zero(lanes);
                  set_hit(i, pack_lane_hit<Leaf, PackSlots>(bvh, pack, lane_of[i], tmax[i], us[i], vs[i]));
                }
                update_bounds();
              }
            }
          }
        } else {
          // Each hit narrows its ray's lane of reach in registers: reloading
          // reach from tmax just after these scalar stores would wait for them.
          unsigned hit_rays = 0;
          for (unsigned lanes = active & ~done; lanes; lanes &= lanes - 1) {
            const int i = std::countr_zero(lanes);
            TriangleHit th{};
            int lane;
            if constexpr (kRayLanesLeaf<Leaf>) lane = Leaf::template intersect<AnyHit>(rays[i], tmax[i], bvh, pack, th);
            else lane = Leaf::template intersect<AnyHit>(leaf_ray[i], tmax[i], bvh, pack, th);
            if (lane < 0) continue;
            hit_rays |= 1u << i;
            if constexpr (!AnyHit) {
              set_hit(i, pack_lane_hit<Leaf, PackSlots>(bvh, pack, lane, th.t, th.u, th.v));
              reach = select(M::from_bits(1u << i), F::set1(th.t), reach);
            }
          }
          if (hit_rays) {
            if constexpr (AnyHit) mark_occluded(hit_rays);
            else set_exit();
          }
        }
      }
    } else {
      const WideNode<8>& node = bvh.nodes[ref];
      F child_entry[8];
      unsigned child_rays[8];
      unsigned entered = 0;
      if (AnyHit && std::popcount(active) <= kNodeAloneAtMost) {
        entered = children_ray_by_ray(p, rays, tmax, active, node, child_rays);
      } else {
        for (unsigned lanes = frustum_children(p, node); lanes; lanes &= lanes - 1) {
          const int lane = std::countr_zero(lanes);
          child_rays[lane] = child_hits(p, node, lane, node_tnear, exit, child_entry[lane]);
          if (child_rays[lane]) entered |= 1u << lane;
        }
      }
      const auto push = [&](int lane) {
        if constexpr (AnyHit) stack.lanes[stack.top] = child_rays[lane];
        else child_entry[lane].storeu(stack.entry[stack.top]);
        stack.ref[stack.top] = node.child[lane];
        ++stack.top;
        // Popped only after the nearer subtrees: its node (or its leaf's
        // first pack) is fetched meanwhile, as the tree outgrows L2
        // (docs/notes/kernels-packets.md, "prefetching pushed children").
        const std::uint32_t child = node.child[lane];
        if (!(child & Bvh8::kLeafBit)) prefetch_lines(bvh.nodes[child]);
        else if constexpr (Leaf::kLeaves == WideLeaves::kMollerTrumbore) prefetch_lines(bvh.packs[Bvh8::first_pack(child)]);
      };
      // The child visited next is entered straight away, the others pushed
      // (in the order the pops would have visited all of them): its rays
      // are those the pop would find within reach, which has not changed.
      if (entered) {
        int next;
        if constexpr (AnyHit) {
          next = 31 - std::countl_zero(entered);  // the highest lane, popped first
          for (unsigned lanes = entered & ~(1u << next); lanes; lanes &= lanes - 1) push(std::countr_zero(lanes));
        } else if ((entered & (entered - 1)) == 0) {
          next = std::countr_zero(entered);  // one child entered: no order to read
        } else {
          // Far to near, up to the last entered child: the nearest, visited next.
          next = -1;
          for (unsigned left = entered, rank = 0; left; ++rank) {
            const int lane = far_to_near_lane(node, plan.octant, static_cast<int>(rank));
            if (!(left >> lane & 1u)) continue;
            if (next >= 0) push(next);
            next = lane;
            left &= ~(1u << lane);
          }
        }
        ref = node.child[next];
        active = child_rays[next];
        node_tnear = select(M::from_bits(active), p.tnear, nan_lanes());
        continue;
      }
    }
    // Pop the next subtree some ray still reaches.
    for (;;) {
      if (stack.top == 0) {
        for (unsigned lanes = plan.lanes; lanes; lanes &= lanes - 1) {
          const int i = std::countr_zero(lanes);
          if constexpr (AnyHit) occluded[i] = done >> i & 1u;
          else hits[i] = hit_of(i);
        }
        return;
      }
      --stack.top;
      if constexpr (AnyHit) {
        active = stack.lanes[stack.top] & ~done;
        if (active) {
          ref = stack.ref[stack.top];
          node_tnear = select(M::from_bits(active), p.tnear, nan_lanes());
          break;
        }
      } else {
        const auto within = F::load(stack.entry[stack.top]) <= reach;
        active = within.mask();
        if (active) {
          ref = stack.ref[stack.top];
          node_tnear = select(within, p.tnear, nan_lanes());
          break;
        }
      }
    }
  }
}
#endif

#if defined(__AVX2__)
namespace wide_packet_detail {
// Packets one group of rays may try to form: the first packet's lead is the
// group's first usable ray, each further packet's the first ray left over.
inline constexpr int kMaxPacketsPerGroup = 4;

// Splits rays[0..n) (n <= kPacketRays) into packets, each traced by
// in_packet(p, plan) as soon as it is planned (p is reused); a lead with
// too few companions goes alone and the next ray leads. At most
// kMaxPacketsPerGroup tries. Returns the rays left to go alone.
template <typename InPacket>
unsigned plan_group(const Ray* rays, int n, float max_origin_distance, const BBox& extent, Packet& p,
                    InPacket&& in_packet) {
  unsigned left = lanes_below(n);
  unsigned candidates = load_group(rays, n, p);
  for (int k = 0; k < kMaxPacketsPerGroup && std::popcount(candidates) >= kMinPacketRays; ++k) {
    const PacketPlan plan = plan_packet(rays, candidates, max_origin_distance, extent, p);
    if (!plan.lanes) {
      candidates &= candidates - 1;  // the lead goes alone
      continue;
    }
    in_packet(p, plan);
    left &= ~plan.lanes;
    candidates &= ~plan.lanes;
  }
  return left;
}
}  // namespace wide_packet_detail
#endif

// The rays of rays[0..n) (n <= kPacketRays) that `intersect_packet_batch`
// traces in packets over a tree whose bounds are `extent` (bit i: ray i),
// in a batch that looks coherent; 0 where the traversal has no SIMD packets
// (without AVX2).
inline unsigned packet_lanes(const Ray* rays, int n, const BBox& extent) {
#if defined(__AVX2__)
  wide_packet_detail::Packet p;
  const unsigned left = wide_packet_detail::plan_group(rays, n, max_packet_origin_distance(extent), extent, p,
                                                       [](const wide_packet_detail::Packet&, PacketPlan) {});
  return lanes_below(n) & ~left;
#else
  (void)rays, (void)n, (void)extent;
  return 0;
#endif
}

#if defined(__AVX2__)
namespace wide_packet_detail {

// The batch loop of both queries, for a batch that looks coherent: each
// group's planned rays traced as one packet by in_packet(first, packet,
// plan), the others by alone(index).
template <typename Alone, typename InPacket>
void trace_groups(const Bvh8& bvh, std::span<const Ray> rays, float max_origin_distance, Alone&& alone,
                  InPacket&& in_packet) {
  for (std::size_t first = 0; first < rays.size(); first += kPacketRays) {
    const int n = static_cast<int>(std::min<std::size_t>(kPacketRays, rays.size() - first));
    prefetch_rays(rays, first + kPacketRays, kPacketRays);  // the next group's, read after this one's traversal
    Packet p;
    const unsigned left = plan_group(&rays[first], n, max_origin_distance, bvh.bounds, p,
                                     [&](const Packet& packet, PacketPlan plan) { in_packet(first, packet, plan); });
    for (unsigned lanes = left; lanes; lanes &= lanes - 1) alone(first + static_cast<std::size_t>(std::countr_zero(lanes)));
  }
}

}  // namespace wide_packet_detail
#endif

// Closest hit of every ray, consecutive coherent rays traced as packets
// (plan_group), the others alone, and a batch whose first groups all look
// incoherent (or any batch without AVX2) by intersect_wide_batch itself:
// the same Hit for every ray as intersect_wide_batch. Screened rays, as
// wide_bvh_batch.h's loops.
template <typename Leaf>
inline void intersect_packet_batch(const Bvh8& bvh, std::span<const Ray> rays, std::span<Hit> hits) {
#if defined(__AVX2__)
  using namespace wide_packet_detail;
  constexpr bool kSlots = !Leaf::kPrimsInPack;
  const float max_origin_distance = max_packet_origin_distance(bvh.bounds);
  if (!bvh.nodes.empty() && batch_looks_coherent(rays, max_origin_distance)) {
    trace_groups(
        bvh, rays, max_origin_distance,
        [&](std::size_t i) { hits[i] = traverse_wide<false, Leaf, SlabFma, kSlots>(bvh, rays[i]); },
        [&](std::size_t first, const Packet& p, PacketPlan plan) {
          trace_packet<false, Leaf, kSlots>(bvh, &rays[first], p, plan, &hits[first], nullptr);
        });
    if constexpr (kSlots)
      for (Hit& h : hits)
        if (h.hit()) h.prim = bvh.pack_prims[static_cast<std::uint32_t>(h.prim)];
    return;
  }
#endif
  intersect_wide_batch<Leaf, SlabFma>(bvh, rays, hits);
}

// Any hit of every ray, as occluded_wide_batch, packets as above.
template <typename Leaf>
inline void occluded_packet_batch(const Bvh8& bvh, std::span<const Ray> rays, std::span<std::uint8_t> occluded) {
#if defined(__AVX2__)
  using namespace wide_packet_detail;
  const float max_origin_distance = max_packet_origin_distance(bvh.bounds);
  if (!bvh.nodes.empty() && batch_looks_coherent(rays, max_origin_distance)) {
    trace_groups(
        bvh, rays, max_origin_distance,
        [&](std::size_t i) { occluded[i] = occluded_wide<Leaf, SlabFma>(bvh, rays[i]); },
        [&](std::size_t first, const Packet& p, PacketPlan plan) {
          trace_packet<true, Leaf, false>(bvh, &rays[first], p, plan, nullptr, &occluded[first]);
        });
    return;
  }
#endif
  occluded_wide_batch<Leaf, SlabFma>(bvh, rays, occluded);
}

}  // namespace raybench
