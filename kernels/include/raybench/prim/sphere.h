// The sphere as every ray-sphere test receives it, and what a test returns.
#pragma once

#include "raybench/math/vec.h"

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

}  // namespace raybench
