// Axis-aligned bounding box. An empty box has lower = +inf, upper = -inf so
// that extending it by any point gives that point.
#pragma once

#include <limits>

#include "raybench/math/vec.h"

namespace raybench {

struct BBox {
  Vec3f lower{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
              std::numeric_limits<float>::infinity()};
  Vec3f upper{-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
              -std::numeric_limits<float>::infinity()};

  void extend(Vec3f p) {
    lower = min(lower, p);
    upper = max(upper, p);
  }
  void extend(const BBox& b) {
    lower = min(lower, b.lower);
    upper = max(upper, b.upper);
  }
  bool empty() const { return !(lower.x <= upper.x && lower.y <= upper.y && lower.z <= upper.z); }
  Vec3f extent() const { return upper - lower; }
  Vec3f center() const { return (lower + upper) * 0.5f; }
  // Half the surface area: the SAH only needs ratios, and this is what it compares.
  float half_area() const {
    if (empty()) return 0.0f;
    const Vec3f e = extent();
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
  int largest_axis() const {
    const Vec3f e = extent();
    return (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
  }
  bool contains(const BBox& b) const {
    return lower.x <= b.lower.x && lower.y <= b.lower.y && lower.z <= b.lower.z &&
           upper.x >= b.upper.x && upper.y >= b.upper.y && upper.z >= b.upper.z;
  }
};

}  // namespace raybench
