// The referee: ground truth for every ray of a triangle scene, as exact
// arithmetic answers it (referee/exact_triangle.h). Candidates come from our
// BVH2 walked with a conservative box test (SlabRobust's padding, Ize 2013, in
// double), which never culls a box the exact ray touches; each candidate is
// judged exactly, and the nearest exact t wins. Triangles at exactly the same
// t are a tie: each of them is a right answer.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "raybench/bvh/bvh2.h"
#include "raybench/math/ray.h"
#include "scene/scene.h"

namespace raybench {

// Barycentric distance from an edge under which a float kernel may fairly
// pick either neighbour: the "ambiguity band" of ../shared/EXTREMES.md.
inline constexpr double kAmbiguityBand = 1e-5;

struct RefereeVerdict {
  // A double within a few double ulps of the exact t (a float ulp is 2^29
  // double ulps; exact_intersect gives the nearest double when that matters,
  // at ~20 us of rationals per hit); inf on a miss.
  double t = std::numeric_limits<double>::infinity();
  std::int32_t prim = kNoHit;  // the nearest triangle (the lowest id among tied ones)
  bool tie = false;            // another triangle lies at exactly the same t
  // Within the ambiguity band: the hit is that close to an edge or vertex of
  // its triangle, or the ray passes that close to a triangle it misses (no
  // farther than the hit), or there is a tie.
  bool ambiguous = false;

  bool hit() const { return prim != kNoHit; }
};

class Referee {
 public:
  // Keeps a reference to the scene: it must outlive the referee.
  explicit Referee(const Scene& scene);

  RefereeVerdict judge(const Ray& ray) const;
  // Judges every ray, in parallel on the calling thread's TBB arena.
  void judge(std::span<const Ray> rays, std::span<RefereeVerdict> verdicts) const;
  // True when `prim` is a right closest hit for the ray: the verdict's
  // triangle, or one tied with it at exactly the same t.
  bool accepts(const Ray& ray, const RefereeVerdict& verdict, std::int32_t prim) const;

  const Scene& scene() const { return scene_; }
  std::size_t memory_bytes() const { return bvh_.memory_bytes(); }

 private:
  const Scene& scene_;
  Bvh2 bvh_;
};

}  // namespace raybench
