// The one list of kernel variants; benchmark and CSV names come from each
// type's `name`. Adding a ray-triangle test means writing its header in
// prim/, including it below and adding its type to the end of TriangleTests
// (docs/backends.md); nothing else is edited, and
// from this list alone the harness makes the backend bvh2:<name>
// (backends/bvh2_backend.cpp), the accuracy suite judges it
// (meshes/accuracy.toml names "bvh2:*"), the typed specification runs over
// it unless its accuracy class is epsilon (kernels/tests/
// triangle_variants_test.cpp), and `raybench kernels` and the kernel-level
// accuracy rows time and judge it. The box, sphere and OBB typed tests pick
// their types by the property they specify.
#pragma once

#include <tuple>

#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_fma.h"
#include "raybench/prim/aabb_slab_fma_robust.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/prim/aabb_slab_robust_ray.h"
#include "raybench/prim/aabb_slab_seed.h"
#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/obb_seed.h"
#include "raybench/prim/sphere_precise.h"
#include "raybench/prim/sphere_quadratic.h"
#include "raybench/prim/sphere_seed.h"

#include "raybench/prim/triangle_baldwin_weber.h"
#include "raybench/prim/triangle_mt.h"
#include "raybench/prim/triangle_mt_double.h"
#include "raybench/prim/triangle_mt_edges.h"
#include "raybench/prim/triangle_mt_normal.h"
#include "raybench/prim/triangle_mt_seed.h"
#include "raybench/prim/triangle_watertight.h"

namespace raybench {

// The first entry is the default test of every BVH backend.
using TriangleTests =
    std::tuple<MollerTrumbore, MollerTrumboreSeed, WatertightTriangle, BaldwinWeber, MollerTrumboreDouble,
               MollerTrumboreNormal, MollerTrumboreEdges>;

// Ray-box tests (seed 000), ray-sphere tests (seed 003), ray-OBB tests
// (seed 004). The microbenchmarks (raybench kernels) time every entry.
using BoxTests = std::tuple<Slab, SlabSeed, SlabRobust, SlabRobustRay, SlabFma, SlabFmaRobust>;
using SphereTests = std::tuple<SpherePrecise, SphereSeed, SphereQuadratic>;
using ObbTests = std::tuple<Obb, ObbSeed>;

// Calls f(Variant{}) for each type of a tuple of variants.
template <typename Variants, typename F>
void for_each_variant(F&& f) {
  std::apply([&](auto... variants) { (f(variants), ...); }, Variants{});
}

}  // namespace raybench
