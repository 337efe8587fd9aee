// The one list of kernel variants. The harness registers a backend per entry
// (bvh2:<name>), the typed tests run over it, and benchmark names come from
// each type's `name`. Adding a ray-triangle test means writing its header in
// prim/ and adding its type here; nothing else changes.
#pragma once

#include <tuple>

#include "raybench/prim/triangle_baldwin_weber.h"
#include "raybench/prim/triangle_mt.h"
#include "raybench/prim/triangle_mt_double.h"
#include "raybench/prim/triangle_mt_seed.h"
#include "raybench/prim/triangle_watertight.h"

namespace raybench {

// The first entry is the default test of every BVH backend.
using TriangleTests =
    std::tuple<MollerTrumbore, MollerTrumboreSeed, WatertightTriangle, BaldwinWeber, MollerTrumboreDouble>;

}  // namespace raybench
