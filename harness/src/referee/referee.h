// The referee: ground truth for every ray of a scene, as exact arithmetic
// answers it. Candidates come from our BVH2 walked with a conservative box
// test (SlabRobust's padding, Ize 2013, in double), which never culls a box
// the exact ray touches; each candidate is judged exactly by its type
// (triangles: referee/exact_triangle.h; spheres, boxes and oriented boxes as
// surfaces: exact_intersect_surface of referee/exact_primitives.h), and the
// nearest exact t wins. A scene with analytic primitives gets one tree over
// every primitive's box (raybench/prim/primitives.h), prim ids global.
//
// Ties: triangles at exactly the same t (decided in rationals) are a tie,
// each of them a right answer. Where an analytic primitive is involved, two
// hits tie when their t cannot be told apart by the referee's double
// enclosures of the exact t (a few double ulps, 2^-27 of a float ulp): a
// box resting on a triangle's plane, coincident boxes, spheres touching where
// the ray passes. No float tracer can order such hits, so either is right.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "raybench/bvh/bvh2.h"
#include "raybench/math/ray.h"
#include "scene/scene.h"

namespace raybench {

// Barycentric distance from an edge under which a float kernel may fairly
// pick either neighbour: the "ambiguity band" of ../shared/EXTREMES.md. For
// analytic primitives the same fraction of their size (referee/analytic_band.h).
inline constexpr double kAmbiguityBand = 1e-5;

struct RefereeVerdict {
  // A double within a few double ulps of the exact t (a float ulp is 2^29
  // double ulps; exact_intersect gives the nearest double when that matters,
  // at ~20 us of rationals per hit); inf on a miss.
  double t = std::numeric_limits<double>::infinity();
  std::int32_t prim = kNoHit;  // the nearest primitive (the lowest id among tied ones)
  bool tie = false;            // another primitive lies at the same t (see above)
  // Within the ambiguity band: the hit is that close to an edge or vertex of
  // its triangle, or to the silhouette, an edge or a corner of its analytic
  // primitive (referee/analytic_band.h), or the ray passes that close to a
  // primitive it misses (no farther than the hit), or it starts exactly on an
  // analytic surface it hits or touches (start_contact: a float test sees
  // that origin on either side), or there is a tie.
  bool ambiguous = false;

  bool hit() const { return prim != kNoHit; }
};

// Whether the ray hits primitives a and b (global ids of `prims`) at the
// same t as the referee ties hits (above): two triangles whose planes the
// ray's line crosses at exactly the same t (same_exact_t; no hit needed);
// otherwise both hit, their enclosures of the exact t overlapping.
bool same_t(const Ray& ray, const PrimitiveSpans& prims, std::size_t a, std::size_t b);

class Referee {
 public:
  // Keeps a reference to the scene: it must outlive the referee.
  explicit Referee(const Scene& scene);

  RefereeVerdict judge(const Ray& ray) const;
  // Judges every ray, in parallel on the calling thread's TBB arena.
  void judge(std::span<const Ray> rays, std::span<RefereeVerdict> verdicts) const;
  // True when `prim` is a right closest hit for the ray: the verdict's
  // primitive, or one tied with it (see above).
  bool accepts(const Ray& ray, const RefereeVerdict& verdict, std::int32_t prim) const;

  const Scene& scene() const { return scene_; }
  std::size_t memory_bytes() const { return bvh_.memory_bytes() + bounds_.size() * sizeof(BBox); }

 private:
  const Scene& scene_;
  // With analytic primitives: every primitive's box grown by the ambiguity
  // band (referee.cpp), in prim id order; the tree is built over them.
  std::vector<BBox> bounds_;
  Bvh2 bvh_;
};

}  // namespace raybench
