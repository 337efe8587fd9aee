// Our BVH families (bvh2, bvh8, bvh4) on scenes with analytic primitives
// (issue 31). Each family registers itself through
// RAYBENCH_BVH_FAMILY_WITH_ANALYTIC instead of RAYBENCH_BACKEND_FAMILY: every
// backend its factory makes is paired, in an AnalyticDispatchBackend
// (analytic_dispatch.h), with a backend tracing one tree over triangles,
// spheres, boxes and oriented boxes (raybench/bvh/mixed_bvh2.h,
// mixed_wide_bvh.h) with the same triangle test and box test; the families'
// names gain the seed options of analytic_test_choice.h.
// Why from here and not in the families' files: a scene without analytic
// primitives must run exactly the code it ran before. Any change to those
// translation units (a branch in the backend, the mixed instantiations
// beside it, even a longer factory) changed how GCC inlined and allocated
// registers in some of their traversal loops; with only their registration
// line changed, their code is the same, instruction for instruction.
// The mixed backends accept only the binned builder (primitive boxes). So
// capabilities() is every type with the binned builder and triangles only
// with another (the run skips such a backend on scenes with analytic
// primitives), and build() of such a scene with another builder throws an
// InputError naming the backend and the scene.
#pragma once

#include <string>

#include "backends/backend.h"

namespace raybench {

// Registers `family` ("bvh2", "bvh8" or "bvh4"; std::logic_error for any
// other) with the registry, its factory `make` and its names `names` (as
// register_backend_family takes them) wrapped as said above.
bool register_bvh_family_with_analytic(std::string family, int order, BackendFactory make, BackendNames names);

#define RAYBENCH_BVH_FAMILY_WITH_ANALYTIC(family, order, make, names)                                \
  [[maybe_unused]] static const bool RAYBENCH_BACKEND_CAT_(raybench_bvh_family_, __LINE__) = \
      ::raybench::register_bvh_family_with_analytic(family, order, make, names)

}  // namespace raybench
