// Per-ray agreement of a backend with a reference (Embree's default build):
// the "agree" columns of a run. disagreements() counts the rays that differ
// on hit/miss and those where both hit different triangles; of the latter,
// prim_ties counts those at the same t (float, or exact given the scene),
// for a reader to discount.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "raybench/math/ray.h"
#include "raybench/prim/primitives.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct Agreement {
  std::size_t rays = 0;
  std::size_t hits = 0;            // rays the tested backend reports as hit/occluded
  std::size_t same_hit = 0;        // rays where both agree on hit or miss
  std::size_t both_hit = 0;        // closest-hit queries only
  std::size_t same_prim = 0;       // of both_hit, the same triangle
  std::size_t prim_ties = 0;       // of both_hit, another triangle at the same t (see compare_hits)
  double t_relerr_max = 0.0;       // over both_hit: |t - t_ref| / |t_ref|
  double t_relerr_p999 = 0.0;      // 99.9th percentile of the same
  bool has_prims = false;          // false for occlusion queries: no prim or t to compare

  double hit_rate() const { return rays ? static_cast<double>(hits) / rays : 0.0; }
  double agree_hit() const { return rays ? static_cast<double>(same_hit) / rays : 1.0; }
  double agree_prim() const { return both_hit ? static_cast<double>(same_prim) / both_hit : 1.0; }
  // Rays that disagree on hit/miss, plus rays where both hit different triangles.
  std::size_t disagreements() const { return (rays - same_hit) + (both_hit - same_prim); }
};

// The nearest-rank p-th percentile (0 < p <= 1): the smallest value with at
// least p of the values at or below it; NaN for none. Reorders `values`.
double nearest_rank_percentile(std::vector<double>& values, double p);

// Where both hit different triangles, a tie is another triangle at the same
// t: the same float t, or, given the rays and the scene's triangles (indexed
// by Hit::prim), the same exact t (same_exact_t, the referee's arithmetic).
// Exact ties are what "not counting ties" means: two tracers rounding t
// their own ways rarely return the same float for coincident triangles
// (observed: docs/notes/harness-measurement.md).
Agreement compare_hits(std::span<const Hit> tested, std::span<const Hit> reference, std::span<const Ray> rays = {},
                       std::span<const Triangle> triangles = {});
// The same for a scene with analytic primitives (issue 31): Hit::prim is a
// global id of `prims`, and a tie involving an analytic primitive is the
// referee's (referee/referee.h, same_t: both hit, t equal to within the
// referee's enclosures of the exact t, a few double ulps).
Agreement compare_hits(std::span<const Hit> tested, std::span<const Hit> reference, std::span<const Ray> rays,
                       const PrimitiveSpans& prims);
Agreement compare_occlusion(std::span<const std::uint8_t> tested, std::span<const std::uint8_t> reference);

}  // namespace raybench
