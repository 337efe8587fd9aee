// The one list of kernel variants. The harness registers a backend per entry
// (bvh2:<name>), the typed tests run over it, and benchmark names come from
// each type's `name`. Adding a ray-triangle test means writing its header in
// prim/ and adding its type here; nothing else changes.
#pragma once

#include <tuple>

#include "raybench/prim/triangle_mt.h"

namespace raybench {

// The first entry is the default test of every BVH backend.
using TriangleTests = std::tuple<MollerTrumbore>;

}  // namespace raybench
