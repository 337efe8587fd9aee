// A ray and a hit record, laid out as raybench stores them on disk.
//
// Ray is exactly one row of a ray file (float32, 8 columns:
// ox oy oz tnear dx dy dz tfar), so a loaded file is used in place.
// A ray covers the parameter interval (max(tnear, 0), tfar]: open at tnear,
// closed at tfar, as Embree's default triangle test does.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "raybench/math/vec.h"

namespace raybench {

struct Ray {
  Vec3f org;
  float tnear = 0.0f;
  Vec3f dir;
  float tfar = std::numeric_limits<float>::infinity();
};
static_assert(sizeof(Ray) == 8 * sizeof(float), "Ray must match one row of a ray file");

// The closest hit: t = +inf and prim = kNoHit on a miss; u, v are the
// barycentric coordinates of the hit point p = (1-u-v) v0 + u v1 + v v2.
inline constexpr std::int32_t kNoHit = -1;

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  std::int32_t prim = kNoHit;
  float u = 0.0f;
  float v = 0.0f;

  bool hit() const { return prim != kNoHit; }
};

// Largest coordinate Embree accepts (FLT_LARGE in Embree's common/math): its
// debug-assert build aborts on anything larger, on NaN and on Inf.
inline constexpr float kLargestTraceableCoordinate = 1.844e18f;

// True when every backend can trace the ray. Untraceable rays (NaN or Inf in
// origin or direction, NaN interval bounds, coordinates beyond Embree's range)
// are reported as misses by every backend without being traced: this is the
// one screening rule, applied identically to Embree and to our kernels.
inline bool is_traceable(const Ray& r) {
  const auto ok = [](float c) { return std::fabs(c) <= kLargestTraceableCoordinate; };  // false for NaN
  return ok(r.org.x) && ok(r.org.y) && ok(r.org.z) && ok(r.dir.x) && ok(r.dir.y) && ok(r.dir.z) &&
         !std::isnan(r.tnear) && !std::isnan(r.tfar);
}

// The ray every backend traces: a negative tnear is raised to 0 (Embree clamps
// it for its box tests but not for its triangle test, so without this the two
// would disagree on triangles behind the origin).
inline Ray with_nonnegative_tnear(Ray r) {
  r.tnear = r.tnear > 0.0f ? r.tnear : 0.0f;
  return r;
}

}  // namespace raybench
