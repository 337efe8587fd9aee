// The oriented box as every ray-OBB test receives it. The hit record is the
// ray-box one, BoxHit (prim/aabb.h): the ray's parameter interval inside the box.
#pragma once

#include "raybench/math/vec.h"
#include "raybench/prim/aabb.h"

namespace raybench {

// The points center + s0 axis[0] + s1 axis[1] + s2 axis[2] with
// |si| <= half_extent[i]: a closed box. The axes must be unit length and
// mutually orthogonal (the tests project onto them and do not check).
struct OrientedBox {
  Vec3f center;
  Vec3f axis[3];
  Vec3f half_extent;
};

}  // namespace raybench
