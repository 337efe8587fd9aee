// A binary BVH over triangles: the topology only. What a leaf's triangles
// look like to the intersector (Prepared data) is kept by the caller, in the
// order of `prim_ids`, so one tree serves every triangle test.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "raybench/math/bbox.h"
#include "raybench/prim/triangle.h"

namespace raybench {

// 32 bytes, two to a cache line. An inner node's children are stored next to
// each other at first_index and first_index + 1; a leaf holds prim_count > 0
// primitives starting at prim_ids[first_index].
struct Bvh2Node {
  BBox bounds;
  std::uint32_t first_index = 0;
  std::uint32_t prim_count = 0;

  bool is_leaf() const { return prim_count != 0; }
};
static_assert(sizeof(Bvh2Node) == 32);

struct Bvh2 {
  std::vector<Bvh2Node> nodes;           // nodes[0] is the root
  std::vector<std::uint32_t> prim_ids;   // leaf order -> index in the input array

  std::size_t memory_bytes() const {
    return nodes.size() * sizeof(Bvh2Node) + prim_ids.size() * sizeof(std::uint32_t);
  }
  // Surface-area-heuristic cost of the tree, relative to the root's area,
  // with traversal cost 1 and intersection cost 1 per primitive; with
  // leaf_granularity g a leaf of n primitives costs ceil(n / g) tests, the
  // cost a builder given the same granularity minimises (bvh8 leaves: g = 8).
  double sah_cost(int leaf_granularity = 1) const;
};

// How much reinsertion optimisation (bvh2_reinsertion.h) follows a build:
// none; kLight, one batch over the largest nodes, what every backend's
// default build does (within Embree's medium build time); kFull, the
// ':reinsert' option's batches, about as long again as the build.
enum class Bvh2Reinsertion { kNone, kLight, kFull };

struct Bvh2BuildOptions {
  int bin_count = 16;       // SAH bins per axis (Wald 2007, "On fast construction of SAH-based BVHs")
  int max_leaf_size = 8;    // a larger range is always split
  float traversal_cost = 1.0f;  // relative to one ray-triangle test
  int max_sah_depth = 64;   // deeper ranges are halved, bounding the traversal stack
  // Triangles tested together in a leaf: the SAH counts a range of n as
  // ceil(n / granularity) tests, so an 8-wide leaf test (simd/triangle8.h)
  // makes full leaves of 8 as cheap as leaves of 1. 1 for scalar leaves.
  int leaf_granularity = 1;
  // Subtrees at least this large are built as TBB tasks: a task costs
  // microseconds, a 1024-triangle subtree ~0.2 ms
  // (measured: docs/notes/kernels-builders.md).
  std::size_t parallel_threshold = 1024;
  // SBVH only: spatial splits add at most this fraction of the triangle
  // count in extra references (0.5: prim_ids holds at most 1.5 n entries).
  float spatial_split_budget = 0.5f;
  // Reinsertion optimisation after the build (bvh2_reinsertion.h), made by
  // build_bvh2 (bvh2_builders.h) for any builder: none, the default
  // backends' light batch, or the full optimisation of ':reinsert'.
  Bvh2Reinsertion reinsertion = Bvh2Reinsertion::kNone;
};

// Every builder places each triangle in at least one leaf, degenerate ones
// included, and keeps the depth within max_sah_depth + 32 (deeper ranges are
// halved), so kBvh2StackSize bounds the traversal stack. The tree's shape is
// deterministic for a given input; raybench/bvh/bvh2_builders.h selects one
// by name. The object-split builders (binned, sweep, LBVH) place each
// triangle in exactly one leaf, whose box contains it; the SBVH may place a
// triangle in several leaves (prim_ids repeats it, at most once per leaf),
// each leaf's box containing the part of the triangle assigned to it and the
// union of those boxes covering the triangle, so no hit is lost.

// Binned SAH, top-down, centroid binning on all three axes (bin_count bins).
Bvh2 build_bvh2_binned_sah(std::span<const Triangle> triangles, const Bvh2BuildOptions& options = {});

// The same builder over primitives of any kind given by their boxes
// (raybench/prim/primitives.h: a scene with analytic primitives): leaf i of
// prim_ids is an index into prim_bounds. Each primitive is in exactly one
// leaf, whose box contains prim_bounds[i].
Bvh2 build_bvh2_binned_sah(std::span<const BBox> prim_bounds, const Bvh2BuildOptions& options = {});

// Full-sweep SAH, top-down: every object split between centroid-sorted
// neighbours on all three axes is evaluated (bin_count is ignored). The
// quality reference for the binned builder; O(n log n) sorting up front,
// O(n) per tree level after that.
Bvh2 build_bvh2_sweep_sah(std::span<const Triangle> triangles, const Bvh2BuildOptions& options = {});

// Linear BVH: centroids sorted along a 63-bit Morton curve, ranges split at
// their highest differing Morton bit, bounds refitted bottom-up; ranges of at
// most max_leaf_size become leaves when the SAH says a leaf is cheaper than
// the best subtree (bin_count is ignored). Fast, lower quality.
Bvh2 build_bvh2_lbvh(std::span<const Triangle> triangles, const Bvh2BuildOptions& options = {});

// Spatial-split BVH (Stich, Friedrich & Dietrich, HPG 2009): binned object
// splits as build_bvh2_binned_sah, plus binned spatial splits where the best
// object split's children overlap (by more than 1e-5 of the root's area):
// triangles straddling a split plane are clipped to either side, each part
// with a tight box, or kept whole on one side where the SAH prefers that.
// At most spatial_split_budget * n references are added. Lower SAH cost on
// scenes of large or long thin overlapping triangles, slower to build.
Bvh2 build_bvh2_sbvh(std::span<const Triangle> triangles, const Bvh2BuildOptions& options = {});

}  // namespace raybench
