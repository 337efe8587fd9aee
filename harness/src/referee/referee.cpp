#include "referee/referee.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/bvh2_traverse.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "referee/exact_triangle.h"

namespace raybench {

Referee::Referee(const Scene& scene) : scene_(scene), bvh_(build_bvh2_binned_sah(scene.triangles)) {}

RefereeVerdict Referee::judge(const Ray& ray) const {
  RefereeVerdict verdict;
  if (!is_traceable(ray)) return verdict;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  ExactTriangleHit best;
  double near_miss_t = kInf;  // the nearest t at which the ray passes within the band of a missed triangle
  const double lo = std::max(static_cast<double>(ray.tnear), 0.0);
  traverse_bvh2<false, SlabRobust>(bvh_, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
    for (std::uint32_t i = first; i < first + count; ++i) {
      const auto prim = static_cast<std::int32_t>(bvh_.prim_ids[i]);
      const Triangle& tri = scene_.triangles[prim];
      const ExactTriangleHit h = exact_intersect(ray, tri, TValue::kEnclosed);
      if (!h.hit) {
        if (h.min_barycentric > -kAmbiguityBand && h.plane_t > lo && h.plane_t <= ray.tfar)
          near_miss_t = std::min(near_miss_t, h.plane_t);
        continue;
      }
      int order = -1;  // h against the best so far
      if (verdict.hit()) {
        if (h.t_upper < best.t_lower) order = -1;
        else if (h.t_lower > best.t_upper) order = 1;
        else order = compare_exact_t(ray, tri, scene_.triangles[verdict.prim]);
      }
      if (order < 0) {
        best = h;
        verdict.prim = prim;
        verdict.tie = false;
      } else if (order == 0) {
        verdict.tie = true;
        verdict.prim = std::min(verdict.prim, prim);
      }
    }
    // Nothing beyond the best exact t can win: cull conservatively above it.
    return verdict.hit() ? std::min(tmax, std::nextafter(static_cast<float>(best.t_upper), static_cast<float>(kInf))) : tmax;
  });
  if (verdict.hit()) {
    verdict.t = best.t;
    verdict.ambiguous = verdict.tie || best.min_barycentric < kAmbiguityBand || near_miss_t <= best.t_upper;
  } else {
    verdict.ambiguous = near_miss_t < kInf;
  }
  return verdict;
}

void Referee::judge(std::span<const Ray> rays, std::span<RefereeVerdict> verdicts) const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) verdicts[i] = judge(rays[i]);
  });
}

bool Referee::accepts(const Ray& ray, const RefereeVerdict& verdict, std::int32_t prim) const {
  if (!verdict.hit() || prim < 0 || static_cast<std::size_t>(prim) >= scene_.triangles.size()) return false;
  if (prim == verdict.prim) return true;
  if (!verdict.tie) return false;
  const Triangle& tri = scene_.triangles[prim];
  return exact_intersect(ray, tri).hit && compare_exact_t(ray, tri, scene_.triangles[verdict.prim]) == 0;
}

}  // namespace raybench
