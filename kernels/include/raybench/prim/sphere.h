// The sphere as every ray-sphere test receives it, and what a test returns.
#pragma once

#include "raybench/math/ray.h"

namespace raybench {

struct Sphere {
  Vec3f center;
  float radius = 0.0f;
};

// Both roots of |org + t dir - center|^2 = radius^2, t_near <= t_far (equal for
// a tangent ray). A ray starting inside has t_near < 0 < t_far: the reported
// hit is then the far side. Distances are in units of |dir|, as for triangles.
struct SphereHit {
  float t_near, t_far;
};

// The shared last step of the fixed sphere tests: with roots t0 <= t1, a hit
// when either lies in (tnear, tmax] (the far one when starting inside).
// NaN roots reject.
inline bool report_sphere_roots(const Ray& ray, float tmax, float t0, float t1, SphereHit& out) {
  const bool in0 = t0 > ray.tnear && t0 <= tmax;
  const bool in1 = t1 > ray.tnear && t1 <= tmax;
  if (!(in0 || in1)) return false;
  out = {t0, t1};
  return true;
}

}  // namespace raybench
