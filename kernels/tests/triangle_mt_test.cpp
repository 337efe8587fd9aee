// Specification of the Möller–Trumbore test (kernels/.../prim/triangle_mt.h):
// known answers worked by hand on the unit right triangle in the z = 0 plane.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "raybench/prim/triangle_mt.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
const Triangle kUnit{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

Ray down_from(float x, float y, float z = 1.0f) {
  Ray r;
  r.org = {x, y, z};
  r.dir = {0, 0, -1};
  return r;
}

bool hits(const Ray& r, const Triangle& tri, TriangleHit* out = nullptr, float tmax = kInf) {
  TriangleHit h{};
  const bool hit = MollerTrumbore::intersect(r, tmax, tri, h);
  if (out) *out = h;
  return hit;
}

TEST(MollerTrumbore, HitReportsDistanceAndBarycentrics) {
  TriangleHit h;
  ASSERT_TRUE(hits(down_from(0.25f, 0.5f), kUnit, &h));
  EXPECT_FLOAT_EQ(h.t, 1.0f);
  EXPECT_FLOAT_EQ(h.u, 0.25f);  // weight of v1 = (1,0,0)
  EXPECT_FLOAT_EQ(h.v, 0.5f);   // weight of v2 = (0,1,0)
}

TEST(MollerTrumbore, MissesOutsideEachEdge) {
  EXPECT_FALSE(hits(down_from(-0.1f, 0.5f), kUnit));  // u < 0
  EXPECT_FALSE(hits(down_from(0.5f, -0.1f), kUnit));  // v < 0
  EXPECT_FALSE(hits(down_from(0.6f, 0.6f), kUnit));   // u + v > 1
}

TEST(MollerTrumbore, BackFacesHitToo) {
  Ray r = down_from(0.25f, 0.25f, -2.0f);
  r.dir = {0, 0, 1};
  TriangleHit h;
  ASSERT_TRUE(hits(r, kUnit, &h));
  EXPECT_FLOAT_EQ(h.t, 2.0f);
}

TEST(MollerTrumbore, IntervalIsOpenAtTnearAndClosedAtTfar) {
  EXPECT_FALSE(hits(down_from(0.25f, 0.25f), kUnit, nullptr, 0.5f));  // beyond tfar
  EXPECT_TRUE(hits(down_from(0.25f, 0.25f), kUnit, nullptr, 1.0f));   // t == tfar counts
  Ray r = down_from(0.25f, 0.25f);
  r.tnear = 1.0f;
  EXPECT_FALSE(hits(r, kUnit));  // t == tnear does not (Embree's convention)
  r.tnear = 0.999f;
  EXPECT_TRUE(hits(r, kUnit));
}

TEST(MollerTrumbore, TriangleBehindOriginMisses) {
  // The Möller–Trumbore seed note never checks t >= 0 and reports this with t = -1.
  Ray r = down_from(0.25f, 0.25f, -1.0f);
  EXPECT_FALSE(hits(r, kUnit));
}

TEST(MollerTrumbore, RayInThePlaneMisses) {
  Ray r;
  r.org = {-1.0f, 0.25f, 0.0f};
  r.dir = {1, 0, 0};
  EXPECT_FALSE(hits(r, kUnit));  // det == 0 exactly
}

TEST(MollerTrumbore, DegenerateTrianglesMiss) {
  const Triangle point{{0.25f, 0.25f, 0}, {0.25f, 0.25f, 0}, {0.25f, 0.25f, 0}};
  const Triangle collinear{{0, 0, 0}, {1, 1, 0}, {2, 2, 0}};
  EXPECT_FALSE(hits(down_from(0.25f, 0.25f), point));
  EXPECT_FALSE(hits(down_from(1.0f, 1.0f), collinear));
}

TEST(MollerTrumbore, SmallUnitMeshesAreNotHidden) {
  // Bunny scale: legs of 5e-3 give det = 2.5e-5 with a unit direction, which
  // the seed note's `det < 1e-4` rejects. Without the epsilon it hits.
  const Triangle tiny{{0, 0, 0}, {5e-3f, 0, 0}, {0, 5e-3f, 0}};
  TriangleHit h;
  ASSERT_TRUE(hits(down_from(1e-3f, 1e-3f), tiny, &h));
  EXPECT_FLOAT_EQ(h.t, 1.0f);
}

TEST(MollerTrumbore, HugeScaleHits) {
  const Triangle huge{{0, 0, 0}, {1e6f, 0, 0}, {0, 1e6f, 0}};
  TriangleHit h;
  ASSERT_TRUE(hits(down_from(2.5e5f, 2.5e5f, 1e6f), huge, &h));
  EXPECT_FLOAT_EQ(h.t, 1e6f);
}

TEST(MollerTrumbore, NanAndInfiniteInputMisses) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Ray r = down_from(0.25f, 0.25f);
  r.dir = {nan, nan, nan};
  EXPECT_FALSE(hits(r, kUnit));
  r = down_from(nan, 0.25f);
  EXPECT_FALSE(hits(r, kUnit));
  r = down_from(0.25f, 0.25f, kInf);
  EXPECT_FALSE(hits(r, kUnit));
}

}  // namespace
}  // namespace raybench
