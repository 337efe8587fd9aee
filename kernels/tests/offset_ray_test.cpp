// Specification of offset_ray_origin (Wächter & Binder, Ray Tracing Gems ch. 6).
#include <cmath>

#include <gtest/gtest.h>

#include "raybench/math/offset_ray.h"

namespace raybench {
namespace {

TEST(OffsetRayOrigin, MovesAlongTheNormalByAScaleIndependentAmount) {
  for (float scale : {1.0f, 1e3f, 1e6f}) {  // all above the 1/32 absolute-offset zone
    const Vec3f p{scale, 0.5f * scale, -2.0f * scale};
    const Vec3f n{0, 1, 0};
    const Vec3f q = offset_ray_origin(p, n);
    EXPECT_EQ(q.x, p.x);
    EXPECT_EQ(q.z, p.z);
    EXPECT_GT(q.y, p.y) << "scale " << scale;
    // 256 ulps, whatever the scale: between 256 * 2^-24 and 256 * 2^-23 of |p|.
    const double relative = (q.y - p.y) / std::fabs(p.y);
    EXPECT_GE(relative, 256.0 * 0x1p-24);
    EXPECT_LE(relative, 256.0 * 0x1p-23);
  }
}

TEST(OffsetRayOrigin, NegativeCoordinatesAndNormalsMoveTheRightWay) {
  const Vec3f q = offset_ray_origin({-5.0f, -5.0f, -5.0f}, {0, 0, -1});
  EXPECT_LT(q.z, -5.0f);
  EXPECT_EQ(q.x, -5.0f);
}

TEST(OffsetRayOrigin, NearTheOriginUsesAnAbsoluteOffset) {
  const Vec3f q = offset_ray_origin({0.0f, 0.0f, 0.0f}, {0, 0, 1});
  EXPECT_FLOAT_EQ(q.z, 1.0f / 65536.0f);
}

}  // namespace
}  // namespace raybench
