// Moving a secondary ray's origin off the surface it starts on.
//
// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
// Ray Tracing Gems (2019), ch. 6: offset the hit point along the geometric
// normal by a fixed number of float ulps (scale-independent), and by a small
// absolute amount near the origin where ulps are tiny.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "raybench/math/vec.h"

namespace raybench {

// n: the unit geometric normal, on the side the new ray leaves from.
inline Vec3f offset_ray_origin(Vec3f p, Vec3f n) {
  constexpr float kOrigin = 1.0f / 32.0f;        // below this |p|, use the absolute offset
  constexpr float kFloatScale = 1.0f / 65536.0f;  // absolute offset near the origin
  constexpr float kIntScale = 256.0f;             // ulps to move elsewhere
  Vec3f out;
  for (int axis = 0; axis < 3; ++axis) {
    const auto of_i = static_cast<std::int32_t>(kIntScale * n[axis]);
    const auto bits = std::bit_cast<std::int32_t>(p[axis]);
    const float moved = std::bit_cast<float>(bits + (p[axis] < 0.0f ? -of_i : of_i));
    out[axis] = std::fabs(p[axis]) < kOrigin ? p[axis] + kFloatScale * n[axis] : moved;
  }
  return out;
}

}  // namespace raybench
