// Which test judges each analytic primitive type in the leaves of our BVHs
// over mixed primitive types (mixed_leaf.h): our fixed defaults, or the seed
// notes' tests as written, so that their failures show at scene level. Its
// own header because the backends' option parser (harness backends/
// bvh_options.h) names it without needing the tests.
#pragma once

namespace raybench {

struct AnalyticTestChoice {
  bool sphere_seed = false;  // SphereSeed instead of SpherePrecise
  bool box_seed = false;     // SlabSeed instead of Slab
  bool obb_seed = false;     // ObbSeed instead of Obb

  bool operator==(const AnalyticTestChoice&) const = default;
};

}  // namespace raybench
