// The referee (referee/referee.h): our BVH2 walked with a conservative box
// test carried out in double (SlabRobustDouble below), every candidate
// triangle judged exactly (referee/exact_triangle.h), the nearest exact t
// winning and exact ties reported.
#include "referee/referee.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/bvh2_traverse.h"
#include "referee/exact_triangle.h"

namespace raybench {
namespace {

// The referee's box test: SlabRobust's argument (aabb_slab_robust.h; Ize,
// JCGT 2013) carried out in double from the float ray, so the exit is padded
// by 8 double unit roundoffs (2^-50) instead of 8 float ones. The float
// test's padding is 2^-21 of t: from 1e7 units away that is ~5 units, which
// makes every box of a small mesh a candidate (and the referee 1000x slower).
struct SlabRobustDouble {
  struct Precomputed {
    double org[3], inv_dir[3];
    bool negative[3];
    double tnear;
  };
  static Precomputed precompute(const Ray& ray) {
    Precomputed p;
    for (int a = 0; a < 3; ++a) {
      p.org[a] = ray.org[a];
      p.inv_dir[a] = 1.0 / static_cast<double>(ray.dir[a]);
      p.negative[a] = std::signbit(p.inv_dir[a]);
    }
    p.tnear = ray.tnear;
    return p;
  }
  static bool intersect(const Precomputed& r, const BBox& box, float tmax, BoxHit& out) {
    double entry = r.tnear, exit = tmax;
    for (int a = 0; a < 3; ++a) {
      const double near_plane = r.negative[a] ? box.upper[a] : box.lower[a];
      const double far_plane = r.negative[a] ? box.lower[a] : box.upper[a];
      const double t_near = (near_plane - r.org[a]) * r.inv_dir[a];
      const double t_far = (far_plane - r.org[a]) * r.inv_dir[a];
      entry = t_near > entry ? t_near : entry;  // a NaN distance is ignored, as in Slab::clip
      exit = t_far < exit ? t_far : exit;
    }
    exit += std::fabs(exit) * 0x1p-50;
    if (!(entry <= exit && entry < std::numeric_limits<double>::infinity())) return false;
    // t_entry only orders the children; it must stay finite to count as entered.
    out = {static_cast<float>(std::min(entry, static_cast<double>(std::numeric_limits<float>::max()))),
           static_cast<float>(exit)};
    return true;
  }
};

}  // namespace

Referee::Referee(const Scene& scene) : scene_(scene), bvh_(build_bvh2_binned_sah(scene.triangles)) {}

RefereeVerdict Referee::judge(const Ray& ray) const {
  RefereeVerdict verdict;
  if (!is_traceable(ray)) return verdict;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  ExactTriangleHit best;
  double near_miss_t = kInf;  // the nearest t at which the ray passes within the band of a missed triangle
  const double lo = std::max(static_cast<double>(ray.tnear), 0.0);
  traverse_bvh2<false, SlabRobustDouble>(bvh_, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
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
  // Only hit or miss is needed here, and same_exact_t decides t exactly.
  return exact_intersect(ray, tri, TValue::kEnclosed).hit && same_exact_t(ray, tri, scene_.triangles[verdict.prim]);
}

}  // namespace raybench
