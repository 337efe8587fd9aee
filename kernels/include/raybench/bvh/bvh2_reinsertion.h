// Reinsertion optimisation of a built Bvh2: subtrees are taken out and put
// back where the tree's SAH cost drops most (Bittner, Hapala & Havran, "Fast
// insertion-based optimization of bounding volume hierarchies", CGF 2013), in
// batches searched in parallel (Meister & Bittner, "Parallel reinsertion for
// bounding volume hierarchy optimization", CGF 2018).
// Guarantee: the same triangles in the leaves, a tree whose SAH cost never
// rises, no deeper than max_depth.
#pragma once

#include <cstddef>

#include "raybench/bvh/bvh2.h"

namespace raybench {

struct Bvh2ReinsertionOptions {
  // 8 batches of 5 % (Bvh2Reinsertion::kFull): about a quarter lower SAH
  // cost than the binned build, for about as much build time again
  // (measured: docs/notes/kernels-builders.md).
  int passes = 8;                // batches; fewer when a batch improves nothing
  float batch_fraction = 0.05f;  // the nodes of largest area tried per batch, as a fraction of all nodes
  int max_depth = 96;            // no reinsertion makes the tree deeper (Bvh2BuildOptions::max_sah_depth + 32)

  // The options of a level, within max_depth: kNone makes no pass. kLight
  // is one batch of the 2 % largest nodes: the moves high in the tree,
  // where most of the cost is, for a few per cent of the binned build's
  // time, most of what more batches gain on the architectural interiors
  // (measured: docs/notes/kernels-builders.md).
  static Bvh2ReinsertionOptions of(Bvh2Reinsertion level, int max_depth) {
    switch (level) {
      case Bvh2Reinsertion::kNone: return {.passes = 0, .max_depth = max_depth};
      case Bvh2Reinsertion::kLight: return {.passes = 1, .batch_fraction = 0.02f, .max_depth = max_depth};
      case Bvh2Reinsertion::kFull: break;
    }
    return {.max_depth = max_depth};
  }
};

// Moves subtrees (a leaf or an inner node with everything below it) of `bvh`
// to lower Bvh2::sah_cost, which never increases: each move is made only if
// it lowers the cost by more than 1e-6 of the root's area, as computed on the
// tree as it stands. Leaves keep their triangles and boxes (prim_ids is
// untouched), so the cost changes only by the areas of inner nodes, whatever
// the leaf granularity: the moves that pay for one granularity pay for all.
// Nodes change places in the array; the root stays at nodes[0], children
// stay side by side, inner boxes stay the unions of their children's, and
// the depth stays within max_depth (or what it was, if deeper). The result
// depends only on the input tree. Returns the number of moves made.
std::size_t optimize_bvh2_reinsertion(Bvh2& bvh, const Bvh2ReinsertionOptions& options = {});

// The reinsertion a build's options ask for (options.reinsertion), within
// that build's depth bound (max_sah_depth + 32, as every builder keeps it):
// what build_bvh2 and the mixed trees' builds do after building.
inline std::size_t optimize_bvh2_after_build(Bvh2& bvh, const Bvh2BuildOptions& options) {
  return optimize_bvh2_reinsertion(bvh, Bvh2ReinsertionOptions::of(options.reinsertion, options.max_sah_depth + 32));
}

}  // namespace raybench
