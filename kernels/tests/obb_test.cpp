// Specification of the ray-OBB tests: prim/obb_eigen.h (raybench's
// semantics) and prim/obb_seed.h (the ray-OBB seed note as written, whose faults are pinned
// as KnownFailure_* tests).
//
// Semantics (obb_eigen.h): the box is closed and solid; a hit is a point of
// it at t in [tnear, tmax], both ends included; out = that part of the ray,
// clipped to [tnear, tmax] (aabb.h's BoxHit), so a ray from inside enters at
// tnear; NaN/Inf input is a miss.
//
// Known answers worked by hand. kCube is [-1, 1]^3. kDiamond is the same cube
// turned 45 degrees about z: in its frame x' = (x + y)/sqrt2, y' = (y - x)/sqrt2,
// so its z = 0 section is |x| + |y| <= sqrt2, and a ray along +x at height y
// is inside for |x| <= sqrt2 - |y|.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/obb_seed.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kHalfSqrt2 = 0x1.6a09e6p-1f;  // sqrt(1/2) rounded to float
constexpr double kSqrt2 = 1.41421356237309505;
const Vec3f kU{kHalfSqrt2, kHalfSqrt2, 0};   // the diamond's axes
const Vec3f kV{-kHalfSqrt2, kHalfSqrt2, 0};
const OrientedBox kCube{{0, 0, 0}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {1, 1, 1}};
const OrientedBox kDiamond{{0, 0, 0}, {kU, kV, {0, 0, 1}}, {1, 1, 1}};
// Turned 90 degrees about z: local x is world y, local y is world -x; so the
// box is x in [1, 5], y in [-1, 1], z in [-0.5, 0.5], every face exact in float.
const OrientedBox kTurned{{3, 0, 0}, {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}, {1, 2, 0.5f}};

Ray make_ray(Vec3f org, Vec3f dir, float tnear = 0.0f) {
  Ray r;
  r.org = org;
  r.dir = dir;
  r.tnear = tnear;
  return r;
}

template <class K>
bool hits(const Ray& r, const OrientedBox& box, BoxHit* out = nullptr, float tmax = kInf) {
  BoxHit h{};
  const bool hit = K::intersect(r, tmax, box, h);
  if (out) *out = h;
  return hit;
}

// ---------------------------------------------------------------------------
// obb: the fixed test.

TEST(Obb, AxisAlignedHitReportsEntryAndExit) {
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({-5, 0.5f, 0.5f}, {1, 0, 0}), kCube, &h));
  EXPECT_FLOAT_EQ(h.t_entry, 4.0f);
  EXPECT_FLOAT_EQ(h.t_exit, 6.0f);
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 1.5f, 0.5f}, {1, 0, 0}), kCube));
}

TEST(Obb, RotatedBoxHandWorked) {
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({-5, 0, 0}, {1, 0, 0}), kDiamond, &h));  // through two corners
  EXPECT_NEAR(h.t_entry, 5.0 - kSqrt2, 1e-6);
  EXPECT_NEAR(h.t_exit, 5.0 + kSqrt2, 1e-6);
  ASSERT_TRUE(hits<Obb>(make_ray({-5, 0.5f, 0}, {1, 0, 0}), kDiamond, &h));
  EXPECT_NEAR(h.t_entry, 5.0 - (kSqrt2 - 0.5), 1e-6);
  EXPECT_NEAR(h.t_exit, 5.0 + (kSqrt2 - 0.5), 1e-6);
  // The diamond's corner reaches y = sqrt2: y = 1.5 passes above it, y = 1.2
  // hits it though it passes above the unturned cube.
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 1.5f, 0}, {1, 0, 0}), kDiamond));
  EXPECT_TRUE(hits<Obb>(make_ray({-5, 1.2f, 0}, {1, 0, 0}), kDiamond));
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 1.2f, 0}, {1, 0, 0}), kCube));
}

TEST(Obb, TheTighterSlabDecides) {
  // Centre (10,0,0), turned 45 degrees, half extents 2 along u and 1 along v.
  // Along the x axis x - 10 = s: |s|/sqrt2 <= 2 and |s|/sqrt2 <= 1, so
  // |s| <= sqrt2: t in [10 - sqrt2, 10 + sqrt2].
  const OrientedBox box{{10, 0, 0}, {kU, kV, {0, 0, 1}}, {2, 1, 1}};
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({0, 0, 0}, {1, 0, 0}), box, &h));
  EXPECT_NEAR(h.t_entry, 10.0 - kSqrt2, 2e-6);
  EXPECT_NEAR(h.t_exit, 10.0 + kSqrt2, 2e-6);
}

TEST(Obb, RotationsThatAreNotSymmetries) {
  // A 3-4-5 turn (cos = 0.6, sin = 0.8) with half extents 2 and 1: unlike
  // the 45 and 90 degree boxes, turning the other way gives another answer,
  // so this pins which way the frame change goes. About z, centre (1, 2, 3),
  // from centre + (-10, 0.5, 0) along +x: at centre + (s, 0.5, 0) the box
  // coordinates are u = 0.6 s + 0.4 (|u| <= 2: s in [-4, 8/3]) and
  // v = -0.8 s + 0.3 (|v| <= 1: s in [-0.875, 1.625]); t = 10 + s.
  const OrientedBox about_z{{1, 2, 3}, {{0.6f, 0.8f, 0}, {-0.8f, 0.6f, 0}, {0, 0, 1}}, {2, 1, 1}};
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({-9, 2.5f, 3}, {1, 0, 0}), about_z, &h));
  EXPECT_NEAR(h.t_entry, 9.125f, 1e-5f);
  EXPECT_NEAR(h.t_exit, 11.625f, 1e-5f);
  // The same numbers about x: axes x, (0, 0.6, 0.8), (0, -0.8, 0.6), from
  // (0, -10, 0.5) along +y.
  const OrientedBox about_x{{0, 0, 0}, {{1, 0, 0}, {0, 0.6f, 0.8f}, {0, -0.8f, 0.6f}}, {1, 2, 1}};
  ASSERT_TRUE(hits<Obb>(make_ray({0, -10, 0.5f}, {0, 1, 0}), about_x, &h));
  EXPECT_NEAR(h.t_entry, 9.125f, 1e-5f);
  EXPECT_NEAR(h.t_exit, 11.625f, 1e-5f);
}

TEST(Obb, RayParallelToFacesOfARotatedBox) {
  // Along u, offset along v: in the box frame the direction's v and w
  // components are exactly 0 (u.v = a^2 - a^2), so the slab decides alone.
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray(kU * -5.0f + kV * 0.5f, kU), kDiamond, &h));
  EXPECT_NEAR(h.t_entry, 4.0f, 1e-6f);
  EXPECT_NEAR(h.t_exit, 6.0f, 1e-6f);
  EXPECT_FALSE(hits<Obb>(make_ray(kU * -5.0f + kV * 1.5f, kU), kDiamond));
  EXPECT_FALSE(hits<Obb>(make_ray(kU * -5.0f + kV * 1.5f, kU * -1.0f), kDiamond));
}

TEST(Obb, SignedZeroDirectionsGiveTheClosedBoxAnswer) {
  // Origins on a face plane (y = 1), an edge line (y = z = 1) and a corner
  // (x = -1, y = z = 1), with every sign of the zero components.
  for (const float sy : {0.0f, -0.0f}) {
    for (const float sz : {0.0f, -0.0f}) {
      SCOPED_TRACE(testing::Message() << "dir (1, " << std::signbit(sy) << ", " << std::signbit(sz) << ")");
      BoxHit h;
      ASSERT_TRUE(hits<Obb>(make_ray({-5, 1, 0.5f}, {1, sy, sz}), kCube, &h));
      EXPECT_EQ(h.t_entry, 4.0f);
      EXPECT_EQ(h.t_exit, 6.0f);
      ASSERT_TRUE(hits<Obb>(make_ray({-5, 1, 1}, {1, sy, sz}), kCube, &h));
      EXPECT_EQ(h.t_entry, 4.0f);
      EXPECT_EQ(h.t_exit, 6.0f);
      ASSERT_TRUE(hits<Obb>(make_ray({-1, 1, 1}, {1, sy, sz}), kCube, &h));  // corner, inward
      EXPECT_EQ(h.t_entry, 0.0f);
      EXPECT_EQ(h.t_exit, 2.0f);
      ASSERT_TRUE(hits<Obb>(make_ray({-1, 1, 1}, {-1, sy, sz}), kCube, &h));  // corner, outward
      EXPECT_EQ(h.t_entry, 0.0f);  // slab interval [-2, 0], clipped at tnear = 0
      EXPECT_EQ(h.t_exit, 0.0f);
      // One ulp outside the face plane: a miss, whatever the sign.
      EXPECT_FALSE(hits<Obb>(make_ray({-5, 0x1.000002p+0f, 0.5f}, {1, sy, sz}), kCube));
    }
  }
}

TEST(Obb, InfiniteDirectionComponentsMiss) {
  // Not a ray (is_traceable rejects it); turning it into the box frame would
  // make inf * 0 = NaN anyway.
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 0.5f, 0.5f}, {kInf, 0, 0}), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({0.5f, 5, 0.5f}, {0, -kInf, 0}), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 0, 0}, {kInf, 0, 0}), kDiamond));
}

TEST(Obb, OriginOnAFacePointingOutwardHits) {
  // The closed box touches the ray at t = 0 = tnear: the slab intervals end
  // at 0 ([-2, 0], [-1.25, 0] obliquely, [-4, 0]), so the hit is [0, 0].
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({1, 0, 0}, {1, 0, 0}), kCube, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 0.0f);
  ASSERT_TRUE(hits<Obb>(make_ray({1, 0.25f, 0}, {1, 1, 0}), kCube, &h));  // obliquely
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 0.0f);
  ASSERT_TRUE(hits<Obb>(make_ray({5, 0.5f, 0}, {1, 0, 0}), kTurned, &h));  // the face x = 5
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 0.0f);
  Ray before = make_ray({1, 0, 0}, {1, 0, 0}, -1.0f);  // a negative tnear reaches back in
  ASSERT_TRUE(hits<Obb>(before, kCube, &h));
  EXPECT_EQ(h.t_entry, -1.0f);
  EXPECT_EQ(h.t_exit, 0.0f);
  ASSERT_TRUE(hits<Obb>(make_ray({1, 0, 0}, {-1, 0, 0}), kCube, &h));  // pointing inward
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 2.0f);
}

TEST(Obb, OriginInsideEntersAtTnearAndExitsAtTheFarFace) {
  // Slab interval [-1, 1]: the entry lies behind, so the ray is in the box
  // from tnear on and leaves it at t = 1.
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({0, 0, 0}, {1, 0, 0}), kCube, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 1.0f);
  ASSERT_TRUE(hits<Obb>(make_ray({3.5f, 0, 0}, {0, -1, 0}), kTurned, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 1.0f);
  // A solid box: the segment [0, 0.5] lies in it, which is a hit.
  ASSERT_TRUE(hits<Obb>(make_ray({0, 0, 0}, {1, 0, 0}), kCube, &h, 0.5f));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 0.5f);
}

TEST(Obb, BoxBehindTheOriginMisses) {
  EXPECT_FALSE(hits<Obb>(make_ray({5, 0, 0}, {1, 0, 0}), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({5, 0, 0}, {1, 0, 0}), kDiamond));
}

TEST(Obb, IntervalIsClosedAtBothEnds) {
  const Ray r = make_ray({-5, 0, 0}, {1, 0, 0});  // box at [4, 6]
  EXPECT_FALSE(hits<Obb>(r, kCube, nullptr, 3.9f));
  EXPECT_TRUE(hits<Obb>(r, kCube, nullptr, 4.0f));
  EXPECT_TRUE(hits<Obb>(make_ray({-5, 0, 0}, {1, 0, 0}, 6.0f), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 0, 0}, {1, 0, 0}, 6.1f), kCube));
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({-5, 0, 0}, {1, 0, 0}, 4.5f), kCube, &h, 5.5f));
  EXPECT_EQ(h.t_entry, 4.5f);  // out is the overlap of [4.5, 5.5] and [4, 6]
  EXPECT_EQ(h.t_exit, 5.5f);
  ASSERT_TRUE(hits<Obb>(r, kCube, &h, 4.0f));  // touching at tmax
  EXPECT_EQ(h.t_entry, 4.0f);
  EXPECT_EQ(h.t_exit, 4.0f);
}

TEST(Obb, HitMissDoesNotDependOnDirectionLength) {
  for (const float len : {1e-21f, 1e-7f, 1.0f, 1e7f, 1e18f}) {
    SCOPED_TRACE(len);
    BoxHit h;
    ASSERT_TRUE(hits<Obb>(make_ray({-5, 0.5f, 0.5f}, {len, 0, 0}), kCube, &h));
    EXPECT_NEAR(double(h.t_entry) * len, 4.0, 4e-6);
    EXPECT_NEAR(double(h.t_exit) * len, 6.0, 6e-6);
    EXPECT_FALSE(hits<Obb>(make_ray({-5, 1.5f, 0.5f}, {len, 0, 0}), kCube));
    EXPECT_TRUE(hits<Obb>(make_ray({-5, 0.5f, 0}, {len, 0, 0}), kDiamond));
  }
}

TEST(Obb, HugeTinyAndFarScales) {
  BoxHit h;
  const OrientedBox huge{{0, 0, 5e6f}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {1e6f, 1e6f, 1e6f}};
  ASSERT_TRUE(hits<Obb>(make_ray({5e5f, 0, 0}, {0, 0, 1}), huge, &h));
  EXPECT_EQ(h.t_entry, 4e6f);
  EXPECT_EQ(h.t_exit, 6e6f);
  EXPECT_FALSE(hits<Obb>(make_ray({1.5e6f, 0, 0}, {0, 0, 1}), huge));
  const OrientedBox tiny{{0, 0, 5e-4f}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {1e-4f, 1e-4f, 1e-4f}};
  ASSERT_TRUE(hits<Obb>(make_ray({5e-5f, 0, 0}, {0, 0, 1}), tiny, &h));
  EXPECT_NEAR(h.t_entry, 4e-4f, 1e-10f);
  EXPECT_NEAR(h.t_exit, 6e-4f, 1e-10f);
  EXPECT_FALSE(hits<Obb>(make_ray({1.5e-4f, 0, 0}, {0, 0, 1}), tiny));
  // The diamond seen from 1e6 along -x: inside for |x| <= sqrt2 - 0.5.
  ASSERT_TRUE(hits<Obb>(make_ray({1e6f, 0.5f, 0}, {-1, 0, 0}), kDiamond, &h));
  EXPECT_NEAR(h.t_entry, 1e6 - (kSqrt2 - 0.5), 0.0625);  // one ulp of 1e6
  EXPECT_NEAR(h.t_exit, 1e6 + (kSqrt2 - 0.5), 0.0625);
  EXPECT_FALSE(hits<Obb>(make_ray({1e6f, 1.5f, 0}, {-1, 0, 0}), kDiamond));
}

TEST(Obb, ZeroThicknessBoxIsHitAndNegativeExtentIsEmpty) {
  const OrientedBox flat{{0, 0, 0}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {1, 1, 0}};
  BoxHit h;
  ASSERT_TRUE(hits<Obb>(make_ray({0.5f, 0.5f, -5}, {0, 0, 1}), flat, &h));
  EXPECT_EQ(h.t_entry, 5.0f);
  EXPECT_EQ(h.t_exit, 5.0f);
  const OrientedBox inverted{{0, 0, 0}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {-1, 1, 1}};  // x: [1, -1]
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 0, 0}, {1, 0, 0}), inverted));
}

TEST(Obb, NonFiniteAndEmptyInputMisses) {
  const Ray good = make_ray({-5, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(hits<Obb>(good, kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({kNaN, 0, 0}, {1, 0, 0}), kCube));  // NaN inside every slab test
  EXPECT_FALSE(hits<Obb>(make_ray({-5, kNaN, 0}, {1, 0, 0}), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({0, 0, 0}, {kNaN, kNaN, kNaN}), kCube));  // from inside
  EXPECT_FALSE(hits<Obb>(make_ray({-kInf, 0, 0}, {1, 0, 0}), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({0, 0, 0}, {0, 0, 0}), kCube));  // no direction, origin inside
  EXPECT_FALSE(hits<Obb>(good, kCube, nullptr, kNaN));
  EXPECT_FALSE(hits<Obb>(make_ray({-5, 0, 0}, {1, 0, 0}, kNaN), kCube));
  OrientedBox bad = kCube;
  bad.center.y = kNaN;
  EXPECT_FALSE(hits<Obb>(good, bad));
  bad = kCube;
  bad.axis[1].x = kNaN;
  EXPECT_FALSE(hits<Obb>(good, bad));
  bad = kCube;
  bad.half_extent.z = kNaN;
  EXPECT_FALSE(hits<Obb>(good, bad));
}

// ---------------------------------------------------------------------------
// obb_seed: the ray-OBB seed note as written. What it gets right, then its faults, each
// beside obb's answer on the same input.

TEST(ObbSeed, HitsAndMissesAxisAlignedAndRotatedBoxes) {
  BoxHit h;
  ASSERT_TRUE(hits<ObbSeed>(make_ray({-5, 0.5f, 0.5f}, {1, 0, 0}), kCube, &h));
  EXPECT_FLOAT_EQ(h.t_entry, 4.0f);
  EXPECT_FLOAT_EQ(h.t_exit, 6.0f);
  ASSERT_TRUE(hits<ObbSeed>(make_ray({-5, 0.5f, 0}, {1, 0, 0}), kDiamond, &h));
  EXPECT_NEAR(h.t_entry, 5.0 - (kSqrt2 - 0.5), 1e-6);
  EXPECT_NEAR(h.t_exit, 5.0 + (kSqrt2 - 0.5), 1e-6);
  EXPECT_FALSE(hits<ObbSeed>(make_ray({-5, 1.5f, 0}, {1, 0, 0}), kDiamond));
  // Obb.RotationsThatAreNotSymmetries, about x.
  const OrientedBox about_x{{0, 0, 0}, {{1, 0, 0}, {0, 0.6f, 0.8f}, {0, -0.8f, 0.6f}}, {1, 2, 1}};
  ASSERT_TRUE(hits<ObbSeed>(make_ray({0, -10, 0.5f}, {0, 1, 0}), about_x, &h));
  EXPECT_NEAR(h.t_entry, 9.125f, 1e-5f);
  EXPECT_NEAR(h.t_exit, 11.625f, 1e-5f);
  EXPECT_FALSE(hits<ObbSeed>(make_ray({5, 0, 0}, {1, 0, 0}), kCube));  // behind: minT > maxT rejects it
  // Parallel to a face, on its plane, either sign of zero: its closed slab check.
  EXPECT_TRUE(hits<ObbSeed>(make_ray({-5, 1, 0.5f}, {1, -0.0f, 0}), kCube));
  EXPECT_FALSE(hits<ObbSeed>(make_ray({-5, 0x1.000002p+0f, 0.5f}, {1, 0.0f, 0}), kCube));
}

TEST(ObbSeed, IntervalIsAppliedAtTheEnd) {
  EXPECT_FALSE(hits<ObbSeed>(make_ray({-5, 0, 0}, {1, 0, 0}), kCube, nullptr, 3.9f));
  EXPECT_TRUE(hits<ObbSeed>(make_ray({-5, 0, 0}, {1, 0, 0}), kCube, nullptr, 4.0f));
  EXPECT_FALSE(hits<ObbSeed>(make_ray({-5, 0, 0}, {1, 0, 0}, 6.1f), kCube));
}

TEST(ObbSeed, OriginInsideReportsEntryAsDblMin) {
  // minT starts at DBL_MIN and no slab lowers it: the entry reads 0.0f.
  BoxHit h;
  ASSERT_TRUE(hits<ObbSeed>(make_ray({0, 0, 0}, {1, 0, 0}), kCube, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 1.0f);
}

TEST(ObbSeed, KnownFailure_OriginOnFacePointingOutwardMisses) {
  // exit = 0 < minT = DBL_MIN, so `minT > maxT` rejects a box the ray touches.
  const Ray straight = make_ray({1, 0, 0}, {1, 0, 0});
  const Ray oblique = make_ray({1, 0.25f, 0}, {1, 1, 0});
  const Ray turned = make_ray({5, 0.5f, 0}, {1, 0, 0});
  const Ray corner = make_ray({-1, 1, 1}, {-1, 0, 0});
  EXPECT_FALSE(hits<ObbSeed>(straight, kCube));
  EXPECT_FALSE(hits<ObbSeed>(oblique, kCube));
  EXPECT_FALSE(hits<ObbSeed>(turned, kTurned));
  EXPECT_FALSE(hits<ObbSeed>(corner, kCube));
  EXPECT_TRUE(hits<Obb>(straight, kCube));
  EXPECT_TRUE(hits<Obb>(oblique, kCube));
  EXPECT_TRUE(hits<Obb>(turned, kTurned));
  EXPECT_TRUE(hits<Obb>(corner, kCube));
}

TEST(ObbSeed, KnownFailure_TinyDirectionIsParallelToEverySlab) {
  // |f| = 1e-21 <= 1e-20 on all three axes: the origin, outside the x slab, misses.
  const Ray r = make_ray({-5, 0.5f, 0.5f}, {1e-21f, 0, 0});
  EXPECT_FALSE(hits<ObbSeed>(r, kCube));
  EXPECT_TRUE(hits<Obb>(r, kCube));
  EXPECT_TRUE(hits<ObbSeed>(make_ray({-5, 0.5f, 0.5f}, {1e-7f, 0, 0}), kCube));  // fine above 1e-20
}

TEST(ObbSeed, KnownFailure_NaNRayHits) {
  // NaN fails every `>` and `<` rejection, so all three slabs pass.
  BoxHit h;
  ASSERT_TRUE(hits<ObbSeed>(make_ray({-5, kNaN, 0}, {1, 0, 0}), kCube, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, kInf);  // DBL_MAX, never lowered, as a float
  EXPECT_TRUE(hits<ObbSeed>(make_ray({kNaN, kNaN, kNaN}, {1, 0, 0}), kDiamond));
  EXPECT_TRUE(hits<ObbSeed>(make_ray({0, 0, 0}, {kNaN, kNaN, kNaN}), kCube));  // NaN dir from inside
  EXPECT_TRUE(hits<ObbSeed>(make_ray({-5, 0, 0}, {1, 0, 0}), kCube, nullptr, kNaN));  // NaN tmax
  EXPECT_FALSE(hits<Obb>(make_ray({-5, kNaN, 0}, {1, 0, 0}), kCube));
  EXPECT_FALSE(hits<Obb>(make_ray({0, 0, 0}, {kNaN, kNaN, kNaN}), kCube));
}

TEST(ObbVariants, NamesAndAccuracy) {
  EXPECT_EQ(ObbSeed::name, "obb_seed");
  EXPECT_EQ(Obb::name, "obb");
  EXPECT_EQ(ObbSeed::accuracy, AccuracyClass::kEpsilon);
  EXPECT_EQ(Obb::accuracy, AccuracyClass::kFast);
}

}  // namespace
}  // namespace raybench
