// The referee (referee/referee.h): our BVH2 walked with a conservative box
// test carried out in double (SlabRobustDouble below), every candidate
// judged exactly by its type (Candidate below), the nearest exact t winning
// and ties reported.
#include "referee/referee.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/bvh2_traverse.h"
#include "referee/analytic_band.h"
#include "referee/exact_primitives.h"
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

constexpr double kInf = std::numeric_limits<double>::infinity();

// One primitive judged exactly: whether it is hit, t, an enclosure
// [t_lower, t_upper] of the exact t, and what puts the ray in the ambiguity
// band. Triangles keep exact_intersect's enclosure and barycentrics; an
// analytic hit's t is the nearest double (box, OBB) or within one double ulp
// (sphere) of the exact t, so two double steps either side enclose it.
struct Candidate {
  bool hit = false;
  bool triangle = false;
  double t = kInf, t_lower = kInf, t_upper = kInf;
  bool near_boundary = false;  // hits: within the band of an edge, corner or silhouette
  double near_miss_t = kInf;   // misses: where the ray passes within the band (or touches at lo)
};

double steps(double t, int n, double toward) {
  for (int i = 0; i < n; ++i) t = std::nextafter(t, toward);
  return t;
}

// True when the ray's line certainly passes a sphere farther than its
// radius grown by 4 ambiguity bands: no hit, no contact and no near miss,
// without rationals. |f x d| (f = o - c) is the line's distance from the
// centre times |d|; computed in double it is within a few double unit
// roundoffs of |f| |d| of the exact value, and 1e-13 |f| |d| (~450 of them)
// bounds that error with room to spare.
bool clearly_misses(const Ray& ray, const Sphere& s) {
  const double f[3] = {static_cast<double>(ray.org.x) - s.center.x, static_cast<double>(ray.org.y) - s.center.y,
                       static_cast<double>(ray.org.z) - s.center.z};
  const double d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
  const double c[3] = {f[1] * d[2] - f[2] * d[1], f[2] * d[0] - f[0] * d[2], f[0] * d[1] - f[1] * d[0]};
  const double f_len = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  const double d_len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double distance_times_d = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  return distance_times_d - 1e-13 * f_len * d_len > std::fabs(static_cast<double>(s.radius)) * d_len * (1.0 + 4.0 * kAmbiguityBand);
}
template <typename Primitive>
bool clearly_misses(const Ray&, const Primitive&) { return false; }  // boxes: the grown-box test in judge() filters

template <typename Primitive>
Candidate analytic_candidate(const Ray& ray, const Primitive& p, double lo) {
  if (clearly_misses(ray, p)) return {};
  const ExactPrimitiveHit h = exact_intersect_surface(ray, p);
  Candidate c;
  if (!h.hit) {
    c.near_miss_t = h.start_contact ? lo : near_miss_t(ray, p, lo, ray.tfar, kAmbiguityBand);
    return c;
  }
  c.hit = true;
  c.t = h.t;
  c.t_lower = steps(h.t, 2, -kInf);
  c.t_upper = steps(h.t, 2, kInf);
  c.near_boundary = h.start_contact || near_boundary(ray, p, h.t, kAmbiguityBand);
  return c;
}

Candidate judge_candidate(const PrimitiveSpans& prims, const Ray& ray, std::size_t id, double lo) {
  const std::size_t i = prims.local(id);
  switch (prims.kind(id)) {
    case PrimitiveKind::kTriangle: {
      const ExactTriangleHit h = exact_intersect(ray, prims.triangles[i], TValue::kEnclosed);
      Candidate c;
      c.triangle = true;
      if (!h.hit) {
        if (h.min_barycentric > -kAmbiguityBand && h.plane_t > lo && h.plane_t <= ray.tfar) c.near_miss_t = h.plane_t;
        return c;
      }
      c.hit = true;
      c.t = h.t;
      c.t_lower = h.t_lower;
      c.t_upper = h.t_upper;
      c.near_boundary = h.min_barycentric < kAmbiguityBand;
      return c;
    }
    case PrimitiveKind::kSphere: return analytic_candidate(ray, prims.spheres[i], lo);
    case PrimitiveKind::kBox: return analytic_candidate(ray, prims.boxes[i], lo);
    case PrimitiveKind::kOrientedBox: return analytic_candidate(ray, prims.obbs[i], lo);
  }
  return {};
}

// Every primitive's box, in prim id order, for the tree of a scene with
// analytic primitives; grown by twice the ambiguity band of the primitive's
// largest extent (and rounded outward), so that a ray passing just outside a
// primitive still reaches its leaf and is flagged as a near miss: an
// analytic primitive's box is tight (a box's is the box itself), and a ray
// grazing its edge would otherwise be culled before the band is looked at.
std::vector<BBox> band_grown_bounds(const PrimitiveSpans& prims) {
  std::vector<BBox> bounds(prims.size());
  for (std::size_t id = 0; id < bounds.size(); ++id) {
    BBox b = prims.bounds(id);
    const Vec3f e = b.extent();
    const float grow = static_cast<float>(2.0 * kAmbiguityBand) * std::max({e.x, e.y, e.z});
    for (int a = 0; a < 3; ++a) {
      b.lower[a] = std::nextafter(b.lower[a] - grow, -std::numeric_limits<float>::infinity());
      b.upper[a] = std::nextafter(b.upper[a] + grow, std::numeric_limits<float>::infinity());
    }
    bounds[id] = b;
  }
  return bounds;
}

}  // namespace

Referee::Referee(const Scene& scene) : scene_(scene) {
  if (!scene.has_analytic()) {
    bvh_ = build_bvh2_binned_sah(scene.triangles);
    return;
  }
  bounds_ = band_grown_bounds(scene.primitives());
  bvh_ = build_bvh2_binned_sah(std::span<const BBox>(bounds_));
}

RefereeVerdict Referee::judge(const Ray& ray) const {
  RefereeVerdict verdict;
  if (!is_traceable(ray)) return verdict;
  const PrimitiveSpans prims = scene_.primitives();
  Candidate best;
  bool best_boundary = false;  // the best or a primitive tied with it lies in the band
  double near_miss_t = kInf;  // the nearest t at which the ray passes within the band of a missed primitive
  const double lo = std::max(static_cast<double>(ray.tnear), 0.0);
  const SlabRobustDouble::Precomputed slab = SlabRobustDouble::precompute(ray);
  traverse_bvh2<false, SlabRobustDouble>(bvh_, ray, [&](std::uint32_t first, std::uint32_t count, float tmax) {
    for (std::uint32_t i = first; i < first + count; ++i) {
      const auto prim = static_cast<std::int32_t>(bvh_.prim_ids[i]);
      // An analytic primitive whose grown box the ray misses (the tree's own
      // conservative test) is neither hit nor touched nor nearly missed:
      // skip its rationals. Triangles have their own interval filter.
      BoxHit culled;
      if (!bounds_.empty() && prims.kind(bvh_.prim_ids[i]) != PrimitiveKind::kTriangle &&
          !SlabRobustDouble::intersect(slab, bounds_[bvh_.prim_ids[i]], tmax, culled))
        continue;
      const Candidate h = judge_candidate(prims, ray, static_cast<std::size_t>(prim), lo);
      if (!h.hit) {
        near_miss_t = std::min(near_miss_t, h.near_miss_t);
        continue;
      }
      int order = -1;  // h against the best so far
      if (verdict.hit()) {
        if (h.t_upper < best.t_lower) order = -1;
        else if (h.t_lower > best.t_upper) order = 1;
        else if (h.triangle && best.triangle)
          order = compare_exact_t(ray, prims.triangles[static_cast<std::size_t>(prim)],
                                  prims.triangles[static_cast<std::size_t>(verdict.prim)]);
        else order = 0;  // enclosures overlap: tied (referee.h)
      }
      if (order < 0) {
        best = h;
        best_boundary = h.near_boundary;
        verdict.prim = prim;
        verdict.tie = false;
      } else if (order == 0) {
        verdict.tie = true;
        best_boundary = best_boundary || h.near_boundary;
        verdict.prim = std::min(verdict.prim, prim);
      }
    }
    // Nothing beyond the best exact t can win: cull conservatively above it.
    return verdict.hit() ? std::min(tmax, std::nextafter(static_cast<float>(best.t_upper), static_cast<float>(kInf))) : tmax;
  });
  if (verdict.hit()) {
    verdict.t = best.t;
    verdict.ambiguous = verdict.tie || best_boundary || near_miss_t <= best.t_upper;
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
  const PrimitiveSpans prims = scene_.primitives();
  if (!verdict.hit() || prim < 0 || static_cast<std::size_t>(prim) >= prims.size()) return false;
  if (prim == verdict.prim) return true;
  if (!verdict.tie) return false;
  const auto id = static_cast<std::size_t>(prim), winner = static_cast<std::size_t>(verdict.prim);
  if (prims.kind(id) == PrimitiveKind::kTriangle && prims.kind(winner) == PrimitiveKind::kTriangle) {
    // Only hit or miss is needed here, and same_exact_t decides t exactly.
    const Triangle& tri = prims.triangles[id];
    return exact_intersect(ray, tri, TValue::kEnclosed).hit && same_exact_t(ray, tri, prims.triangles[winner]);
  }
  return same_t(ray, prims, id, winner);
}

bool same_t(const Ray& ray, const PrimitiveSpans& prims, std::size_t a, std::size_t b) {
  if (a >= prims.size() || b >= prims.size()) return false;
  if (prims.kind(a) == PrimitiveKind::kTriangle && prims.kind(b) == PrimitiveKind::kTriangle)
    return same_exact_t(ray, prims.triangles[a], prims.triangles[b]);
  if (!is_traceable(ray)) return false;
  const double lo = std::max(static_cast<double>(ray.tnear), 0.0);
  const Candidate ha = judge_candidate(prims, ray, a, lo), hb = judge_candidate(prims, ray, b, lo);
  return ha.hit && hb.hit && ha.t_lower <= hb.t_upper && hb.t_lower <= ha.t_upper;
}

}  // namespace raybench
