// Specification of the ray-AABB tests (kernels/include/raybench/prim/aabb*.h):
// known answers worked by hand, mostly on the unit box [0,1]^3.
//
//   AllBoxTests    properties every variant has, the seed included
//   FixedBoxTests  what Slab, SlabRobust, SlabRobustRay and SlabFma do and the seed does not
//   SlabSeed.KnownFailure_*   the seed note's bugs, pinned as documented behaviour
//   Slab / SlabRobust         rounding: the unpadded test misses a box the exact
//   / SlabRobustRay           ray touches, the padded ones never do
//   SlabFmaRobust  the fused conservative test: never misses, answers within its margin
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "raybench/prim/aabb.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_fma.h"
#include "raybench/prim/aabb_slab_fma_robust.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/prim/aabb_slab_robust_ray.h"
#include "raybench/prim/aabb_slab_seed.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

BBox box(Vec3f lower, Vec3f upper) {
  BBox b;
  b.lower = lower;
  b.upper = upper;
  return b;
}
const BBox kUnit = box({0, 0, 0}, {1, 1, 1});

Ray ray(Vec3f org, Vec3f dir, float tnear = 0.0f, float tfar = kInf) {
  Ray r;
  r.org = org;
  r.dir = dir;
  r.tnear = tnear;
  r.tfar = tfar;
  return r;
}

// The box test as a BVH calls it: precompute once, test with tmax = tfar.
template <typename Box>
bool hits(const Ray& r, const BBox& b, BoxHit* out = nullptr) {
  BoxHit h{-1.0f, -2.0f};
  const bool hit = Box::intersect(Box::precompute(r), b, r.tfar, h);
  if (out) *out = h;
  return hit;
}

// t_entry is exact in every case below; t_exit too, except that the
// conservative variant pads it upward by its error bound (8u = 2^-21
// relative, aabb_slab_robust.h), allowed here as at most 2^-20.
template <typename Box>
::testing::AssertionResult exit_is(float got, float exact) {
  if constexpr (Box::accuracy == AccuracyClass::kConservative) {
    if (got >= exact && got <= exact + std::fabs(exact) * 0x1p-20f) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "t_exit " << got << " not in [" << exact << ", exact + 2^-20 |exact|]";
  } else {
    if (got == exact) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "t_exit " << got << " != " << exact;
  }
}

// ---------------------------------------------------------------------------
// Every variant.

template <typename Box>
class AllBoxTests : public ::testing::Test {};
using AllBoxes = ::testing::Types<SlabSeed, Slab, SlabRobust, SlabRobustRay, SlabFma>;
TYPED_TEST_SUITE(AllBoxTests, AllBoxes);

TYPED_TEST(AllBoxTests, ObliqueHitReportsEntryAndExit) {
  // Box [0,2]x[0,2]x[0,1]; o = (-1,-1,0.5), d = (1,2,0.25):
  //   x: t in [1, 3]   y: t in [0.5, 1.5]   z: t in [-2, 2]
  // entry = max(0, 1, 0.5, -2) = 1 (x face), exit = min(3, 1.5, 2) = 1.5 (y face).
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, -1, 0.5f}, {1, 2, 0.25f}), box({0, 0, 0}, {2, 2, 1}), &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.5f));
}

TYPED_TEST(AllBoxTests, MissesWhenTheSlabIntervalsDoNotOverlap) {
  // The same ray: y in [4,5] gives t in [2.5, 3], but it leaves z at t = 2.
  EXPECT_FALSE(hits<TypeParam>(ray({-1, -1, 0.5f}, {1, 2, 0.25f}), box({0, 4, 0}, {2, 5, 1})));
  // y in [3,4]: t in [2, 2.5], and z = 1 at t = 2: the ray touches the edge
  // x in [0,2], y = 3, z = 1 of the closed box at exactly one point.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, -1, 0.5f}, {1, 2, 0.25f}), box({0, 3, 0}, {2, 4, 1}), &h));
  EXPECT_EQ(h.t_entry, 2.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2.0f));
}

TYPED_TEST(AllBoxTests, DirectionsOfEveryOctantSelectTheRightPlanes) {
  // Box [-1,1]^3, o = -3 s, d = s for s in {+-1}^3: every slab gives t in [2, 4].
  for (float sx : {-1.0f, 1.0f})
    for (float sy : {-1.0f, 1.0f})
      for (float sz : {-1.0f, 1.0f}) {
        BoxHit h;
        ASSERT_TRUE(hits<TypeParam>(ray({-3 * sx, -3 * sy, -3 * sz}, {sx, sy, sz}), box({-1, -1, -1}, {1, 1, 1}), &h))
            << sx << " " << sy << " " << sz;
        EXPECT_EQ(h.t_entry, 2.0f);
        EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 4.0f));
      }
}

TYPED_TEST(AllBoxTests, BoxBehindTheOriginMisses) {
  // t in [-3, -2]: the whole box is behind; turned around, it is ahead.
  EXPECT_FALSE(hits<TypeParam>(ray({3, 0.5f, 0.5f}, {1, 0, 0}), kUnit));
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({3, 0.5f, 0.5f}, {-1, 0, 0}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 2.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 3.0f));
}

TYPED_TEST(AllBoxTests, TmaxClipsAndIsClosed) {
  // o = (-1,0.5,0.5) along +x: the box is at t in [1, 2].
  const Vec3f o{-1, 0.5f, 0.5f}, d{1, 0, 0};
  EXPECT_FALSE(hits<TypeParam>(ray(o, d, 0, 0.5f), kUnit));
  // One ulp short of the entry: a miss, except for the conservative variant,
  // whose padding (which covers tmax too) reaches that far.
  EXPECT_EQ(hits<TypeParam>(ray(o, d, 0, 0x1.fffffep-1f), kUnit),
            TypeParam::accuracy == AccuracyClass::kConservative);
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray(o, d, 0, 1.0f), kUnit, &h));  // touches the face at t = tmax
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.0f));
  ASSERT_TRUE(hits<TypeParam>(ray(o, d, 0, 1.5f), kUnit, &h));
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.5f));
}

TYPED_TEST(AllBoxTests, RayParallelToASlabHitsInsideItAndMissesOutside) {
  // d = (1,0,0) is parallel to the y and z slabs.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, 0.5f, 0.5f}, {1, 0, 0}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2.0f));
  EXPECT_FALSE(hits<TypeParam>(ray({-1, 1.5f, 0.5f}, {1, 0, 0}), kUnit));   // above the y slab
  EXPECT_FALSE(hits<TypeParam>(ray({-1, -0.5f, 0.5f}, {1, 0, 0}), kUnit));  // below it
  EXPECT_FALSE(hits<TypeParam>(ray({-1, 0.5f, 7.0f}, {1, 0, 0}), kUnit));   // beside the z slab
}

TYPED_TEST(AllBoxTests, SignOfZeroNeverChangesTheAnswer) {
  // EXTREMES.md G09: o = (ox, y, z) along d = (+-1, +-0, +-0), for y and z on
  // the slab planes (0, -0, 1), inside, and one ulp or more outside. The box
  // is closed: hit iff 0 <= y <= 1 and 0 <= z <= 1, at t in [1, 2], for
  // every sign of every zero.
  const float coords[] = {0.0f, -0.0f, 1.0f, 0.5f, -0x1p-149f, 0x1.000002p+0f, -1.0f, 2.0f};
  int hit_count = 0;
  for (float dx : {1.0f, -1.0f})
    for (float y : coords)
      for (float z : coords)
        for (float dy : {0.0f, -0.0f})
          for (float dz : {0.0f, -0.0f}) {
            const bool inside = y >= 0 && y <= 1 && z >= 0 && z <= 1;
            BoxHit h;
            const bool hit = hits<TypeParam>(ray({dx > 0 ? -1.0f : 2.0f, y, z}, {dx, dy, dz}), kUnit, &h);
            ASSERT_EQ(hit, inside) << "y=" << y << " z=" << z << " dx=" << dx << " signbit(dy)=" << std::signbit(dy)
                                   << " signbit(dz)=" << std::signbit(dz);
            if (!hit) continue;
            ++hit_count;
            EXPECT_EQ(h.t_entry, 1.0f);
            EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2.0f));
          }
  EXPECT_EQ(hit_count, 2 * 4 * 4 * 4);  // y, z in {0, -0, 1, 0.5}
}

TYPED_TEST(AllBoxTests, OriginOnASlabPlaneWithZeroComponentIsInside) {
  // o on the edge y = 1, z = 0 of the box's extension: (plane - o) * (1/0)
  // is 0 * inf = NaN in the branchless variants, and must not reject.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, 1, 0}, {1, 0, -0.0f}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2.0f));
  // A zero-thickness slab (a flat box) contains a ray lying in its plane.
  ASSERT_TRUE(hits<TypeParam>(ray({1, -1, 0.5f}, {0, 1, 0}), box({1, 0, 0}, {1, 1, 1}), &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2.0f));
  EXPECT_FALSE(hits<TypeParam>(ray({0x1.000002p+0f, -1, 0.5f}, {0, 1, 0}), box({1, 0, 0}, {1, 1, 1})));
}

TYPED_TEST(AllBoxTests, OriginInsideTheBoxEntersAtZero) {
  // o = (0.5,0.5,0.5), d = (1,2,-4): exits are 0.5 (x), 0.25 (y), 0.125 (z).
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({0.5f, 0.5f, 0.5f}, {1, 2, -4}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 0.125f));
}

TYPED_TEST(AllBoxTests, OriginOnAFaceTouchesAtZero) {
  // EXTREMES.md G11. Pointing outward the ray touches the closed box at t = 0
  // only (the seed note's policy, kept by all); inward it crosses it.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({1, 0.5f, 0.5f}, {1, 0, 0}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 0.0f));
  ASSERT_TRUE(hits<TypeParam>(ray({1, 0.5f, 0.5f}, {-1, 0, 0}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.0f));
  EXPECT_FALSE(hits<TypeParam>(ray({0x1.000002p+0f, 0.5f, 0.5f}, {1, 0, 0}), kUnit));  // one ulp outside
}

TYPED_TEST(AllBoxTests, HugeScale) {
  // Box [1e6, 2e6]^3; all values are integers below 2^24, so exact.
  const BBox b = box({1e6f, 1e6f, 1e6f}, {2e6f, 2e6f, 2e6f});
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({0, 1.5e6f, 1.5e6f}, {1, 0, 0}), b, &h));
  EXPECT_EQ(h.t_entry, 1e6f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2e6f));
  ASSERT_TRUE(hits<TypeParam>(ray({0, 0, 0}, {1, 1, 1}), b, &h));  // through two corners
  EXPECT_EQ(h.t_entry, 1e6f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2e6f));
  EXPECT_FALSE(hits<TypeParam>(ray({0, 2.5e6f, 1.5e6f}, {1, 0, 0}), b));
  EXPECT_FALSE(hits<TypeParam>(ray({0, 0, 0}, {1, 1, 3}), b));  // leaves z at 2e6/3 before entering x
}

TYPED_TEST(AllBoxTests, TinyScale) {
  // Box [0, 1e-4]^3 seen from t = 1 away, and obliquely from close by.
  const float s = 1e-4f;
  const BBox b = box({0, 0, 0}, {s, s, s});
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, s / 2, s / 2}, {1, 0, 0}), b, &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.0f + s));  // (s - (-1)) * 1, rounded once
  EXPECT_FALSE(hits<TypeParam>(ray({-1, 2 * s, s / 2}, {1, 0, 0}), b));
  // o = (-s, -s, s/2), d = (1,1,0): x and y both give t in [s, 2s], exactly.
  ASSERT_TRUE(hits<TypeParam>(ray({-s, -s, s / 2}, {1, 1, 0}), b, &h));
  EXPECT_EQ(h.t_entry, s);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2 * s));
}

TYPED_TEST(AllBoxTests, FarAwayOrigin) {
  // 1e7 units away along -x: t in [1e7 - 1, 1e7], both exact in float.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({1e7f, 0.5f, 0.5f}, {-1, 0, 0}), kUnit, &h));
  EXPECT_EQ(h.t_entry, 9999999.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1e7f));
  // A unit box at Embree's far test position (148376, 1234, -223423),
  // seen along -z from 1000 units away: t in [999, 1000].
  const BBox far_box = box({148376, 1234, -223423}, {148377, 1235, -223422});
  ASSERT_TRUE(hits<TypeParam>(ray({148376.5f, 1234.5f, -222423}, {0, 0, -1}), far_box, &h));
  EXPECT_EQ(h.t_entry, 999.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1000.0f));
  EXPECT_FALSE(hits<TypeParam>(ray({148378.5f, 1234.5f, -222423}, {0, 0, -1}), far_box));
}

TYPED_TEST(AllBoxTests, DegenerateBoxesAreClosedSets) {
  // Zero thickness in x: crossed at one parameter, t_entry = t_exit.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({0, 0.5f, 0.5f}, {1, 0, 0}), box({1, 0, 0}, {1, 1, 1}), &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.0f));
  // A point box, hit by a ray through it and missed beside it.
  ASSERT_TRUE(hits<TypeParam>(ray({0, 1, 1}, {2, 0, 0}), box({1, 1, 1}, {1, 1, 1}), &h));
  EXPECT_EQ(h.t_entry, 0.5f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 0.5f));
  EXPECT_FALSE(hits<TypeParam>(ray({0, 1, 0x1.000002p+0f}, {2, 0, 0}), box({1, 1, 1}, {1, 1, 1})));
}

TYPED_TEST(AllBoxTests, MissLeavesTheOutputUntouched) {
  const BoxHit before{-7.0f, -8.0f};
  BoxHit h = before;
  ASSERT_FALSE(TypeParam::intersect(TypeParam::precompute(ray({3, 0.5f, 0.5f}, {1, 0, 0})), kUnit, kInf, h));
  EXPECT_EQ(h.t_entry, before.t_entry);
  EXPECT_EQ(h.t_exit, before.t_exit);
}

// ---------------------------------------------------------------------------
// Slab and SlabRobust: the semantics the seed gets wrong.

template <typename Box>
class FixedBoxTests : public ::testing::Test {};
using FixedBoxes = ::testing::Types<Slab, SlabRobust, SlabRobustRay, SlabFma>;
TYPED_TEST_SUITE(FixedBoxTests, FixedBoxes);

TYPED_TEST(FixedBoxTests, TnearClipsAndIsClosed) {
  // o = (-1,0.5,0.5) along +x: the box is at t in [1, 2].
  const Vec3f o{-1, 0.5f, 0.5f}, d{1, 0, 0};
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray(o, d, 1.5f), kUnit, &h));
  EXPECT_EQ(h.t_entry, 1.5f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 2.0f));
  ASSERT_TRUE(hits<TypeParam>(ray(o, d, 2.0f), kUnit, &h));  // touches the exit face at t = tnear
  EXPECT_EQ(h.t_entry, 2.0f);
  // One ulp past it: a miss, except within SlabRobust's padding.
  EXPECT_EQ(hits<TypeParam>(ray(o, d, 0x1.000002p+1f), kUnit), TypeParam::accuracy == AccuracyClass::kConservative);
  EXPECT_FALSE(hits<TypeParam>(ray(o, d, 0x1.00002p+1f), kUnit));  // 2 + 2^-16: beyond any padding
  EXPECT_FALSE(hits<TypeParam>(ray(o, d, 2.5f, 3.0f), kUnit));
  // tnear is used as given: a negative tnear reaches a box behind the origin.
  ASSERT_TRUE(hits<TypeParam>(ray({3, 0.5f, 0.5f}, d, -10.0f), kUnit, &h));
  EXPECT_EQ(h.t_entry, -3.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, -2.0f));
}

TYPED_TEST(FixedBoxTests, NanAnywhereInTheRayMisses) {
  // The ray hits the unit box at t in [1, 2] before each component is spoiled.
  const Ray good = ray({-1, 0.5f, 0.5f}, {1, 0.125f, 0.125f});
  ASSERT_TRUE(hits<TypeParam>(good, kUnit));
  for (int axis = 0; axis < 3; ++axis) {
    Ray r = good;
    r.org[axis] = kNaN;
    EXPECT_FALSE(hits<TypeParam>(r, kUnit)) << "org[" << axis << "] = NaN";
    r = good;
    r.dir[axis] = kNaN;
    EXPECT_FALSE(hits<TypeParam>(r, kUnit)) << "dir[" << axis << "] = NaN";
  }
  EXPECT_FALSE(hits<TypeParam>(ray({-1, 0.5f, 0.5f}, {kNaN, kNaN, kNaN}), kUnit));
  EXPECT_FALSE(hits<TypeParam>(ray(good.org, good.dir, kNaN), kUnit));        // tnear
  EXPECT_FALSE(hits<TypeParam>(ray(good.org, good.dir, 0.0f, kNaN), kUnit));  // tmax
  // NaN with a parallel component, where the origin decides alone.
  EXPECT_FALSE(hits<TypeParam>(ray({-1, kNaN, 0.5f}, {1, 0, 0}), kUnit));
}

TYPED_TEST(FixedBoxTests, InfiniteOriginOrDirectionMisses) {
  // docs/raysets.md: a ray with Inf in its origin or direction counts as a miss.
  const Ray good = ray({-1, 0.5f, 0.5f}, {1, 0.125f, 0.125f});
  for (int axis = 0; axis < 3; ++axis)
    for (float inf : {kInf, -kInf}) {
      Ray r = good;
      r.org[axis] = inf;
      EXPECT_FALSE(hits<TypeParam>(r, kUnit)) << "org[" << axis << "] = " << inf;
      r = good;
      r.dir[axis] = inf;
      EXPECT_FALSE(hits<TypeParam>(r, kUnit)) << "dir[" << axis << "] = " << inf;
    }
}

TYPED_TEST(FixedBoxTests, EmptyBoxMisses) {
  // BBox{} is empty (lower = +inf, upper = -inf): the root of an empty BVH.
  for (const Vec3f d : {Vec3f{1, 1, 1}, Vec3f{1, 0, 0}, Vec3f{-1, -0.0f, 2}})
    EXPECT_FALSE(hits<TypeParam>(ray({0, 0, 0}, d), BBox{})) << d.x << " " << d.y << " " << d.z;
}

TYPED_TEST(FixedBoxTests, HitOrMissDoesNotDependOnDirectionLength) {
  // EXTREMES.md G16: the oblique ray of ObliqueHitReportsEntryAndExit with d
  // scaled by powers of two from 2^-66 (~1e-20) to 2^66: the distances
  // scale by exactly 1/s. And scaled by 1e-7, where the seed sees "parallel".
  const BBox b = box({0, 0, 0}, {2, 2, 1});
  for (int e : {-66, -23, 0, 23, 66}) {
    const float s = std::ldexp(1.0f, e);
    BoxHit h;
    ASSERT_TRUE(hits<TypeParam>(ray({-1, -1, 0.5f}, {s, 2 * s, 0.25f * s}), b, &h)) << "s = 2^" << e;
    EXPECT_EQ(h.t_entry, 1.0f / s);
    EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 1.5f / s));
    EXPECT_FALSE(hits<TypeParam>(ray({-1, -1, 0.5f}, {s, 2 * s, 0.25f * s}), box({0, 4, 0}, {2, 5, 1})));
  }
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, -1, 0.5f}, {1e-7f, 2e-7f, 0.25e-7f}), b, &h));
  EXPECT_FLOAT_EQ(h.t_entry, 1e7f);
  EXPECT_NEAR(h.t_exit, 1.5e7f, 15.0f);  // 1e-6 relative: three roundings, and the pad
}

TYPED_TEST(FixedBoxTests, ZeroDirectionHitsOnlyFromInside) {
  // d = 0: the "ray" stays at its origin for every t, so it meets the box on
  // the whole interval if the origin is inside, and never otherwise.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({0.5f, 1, 0}, {0, -0.0f, 0}, 0, 3), kUnit, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_TRUE(exit_is<TypeParam>(h.t_exit, 3.0f));
  EXPECT_FALSE(hits<TypeParam>(ray({0.5f, 2, 0}, {0, 0, 0}), kUnit));   // y exit (1 - 2) * inf = -inf
  EXPECT_FALSE(hits<TypeParam>(ray({0.5f, -1, 0}, {0, 0, 0}), kUnit));  // y entry +inf, every exit +inf
}

TYPED_TEST(FixedBoxTests, EntryAtInfinityIsAMiss) {
  // Box [0,inf)^3. o.y = -1 with d.y = 0: the ray never reaches y >= 0, its y
  // entry is (0 - (-1)) * (1/0) = +inf, and every exit is +inf too.
  const BBox quadrant = box({0, 0, 0}, {kInf, kInf, kInf});
  EXPECT_FALSE(hits<TypeParam>(ray({-1, -1, 5}, {1, 0, 0}), quadrant));
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, 1, 5}, {1, 0, 0}), quadrant, &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_EQ(h.t_exit, kInf);
}

// ---------------------------------------------------------------------------
// Rounding: the unpadded test is not conservative, the padded one is.

// o = (-54,-1,-1), d = (55,1,1) toward the unit box. Exactly, o + t d =
// (55t - 54, t - 1, t - 1): y, z >= 0 needs t >= 1 and x <= 1 needs t <= 1,
// so the exact ray touches the closed box at one point, the corner (1,0,0),
// at t = 1. In float the y and z entries are (0 + 1) * 1 = 1 exactly, but the
// x exit is 55 * fl(1/55) = 0x1.fffffep-1 = 1 - 2^-24: entry > exit.
// Found by a search over integer origins in [-60,60]^3 aimed at corners of the
// unit box (d = corner - o, exact in float, so every such ray touches the
// box exactly); this is one of the rays the unpadded test drops.
const Ray kCornerGrazer = ray({-54, -1, -1}, {55, 1, 1});

TEST(Slab, KnownLimitation_MissesBoxTheExactRayTouchesAtACorner) {
  const BoxHit c = Slab::clip(Slab::precompute(kCornerGrazer), kUnit, kInf);
  EXPECT_EQ(c.t_entry, 1.0f);
  EXPECT_EQ(c.t_exit, 0x1.fffffep-1f);
  EXPECT_FALSE(hits<Slab>(kCornerGrazer, kUnit));
}

// The two conservative tests: SlabRobust pads each exit, SlabRobustRay folds
// the same 8u into the ray (the far planes' 1/d and tmax).
template <typename Box>
class ConservativeBoxTests : public ::testing::Test {};
using ConservativeBoxes = ::testing::Types<SlabRobust, SlabRobustRay>;
TYPED_TEST_SUITE(ConservativeBoxTests, ConservativeBoxes);

TYPED_TEST(ConservativeBoxTests, HitsBoxTheUnpaddedTestMissesByRounding) {
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(kCornerGrazer, kUnit, &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_GE(h.t_exit, 1.0f);
}

TYPED_TEST(ConservativeBoxTests, PadsTheExitByEightUnitRoundoffsAndNoMore) {
  // Along +x through the unit box: exit 2, padded to 2 + 2 * 2^-21.
  BoxHit h;
  ASSERT_TRUE(hits<TypeParam>(ray({-1, 0.5f, 0.5f}, {1, 0, 0}), kUnit, &h));
  EXPECT_EQ(h.t_exit, 0x1.000008p+1f);  // 2 (1 + 2^-21)
  // o = 0, d = (1,1,0); box x in [1,2], y in [2 + g, 3]: exact entry 2 + g,
  // exact exit 2, a miss by g. Within the pad (g = 2^-21) the conservative
  // test reports it; beyond (g = 2^-19) it does not.
  EXPECT_TRUE(hits<TypeParam>(ray({0, 0, 0.5f}, {1, 1, 0}), box({1, 2 + 0x1p-21f, 0}, {2, 3, 1})));
  EXPECT_FALSE(hits<TypeParam>(ray({0, 0, 0.5f}, {1, 1, 0}), box({1, 2 + 0x1p-19f, 0}, {2, 3, 1})));
  EXPECT_FALSE(hits<Slab>(ray({0, 0, 0.5f}, {1, 1, 0}), box({1, 2 + 0x1p-21f, 0}, {2, 3, 1})));
}

TEST(SlabRobustRay, PadsTmaxByEightUnitRoundoffsAndNoMore) {
  // A box entered at t = 1 is reported for tmax one ulp below 1, not for
  // tmax 2^-18 below.
  const Vec3f o{-1, 0.5f, 0.5f}, d{1, 0, 0};
  EXPECT_FALSE(hits<Slab>(ray(o, d, 0.0f, 0x1.fffffep-1f), kUnit));
  EXPECT_TRUE(hits<SlabRobustRay>(ray(o, d, 0.0f, 0x1.fffffep-1f), kUnit));
  EXPECT_FALSE(hits<SlabRobustRay>(ray(o, d, 0.0f, 1.0f - 0x1p-18f), kUnit));
}

// Random boxes in [-4,4]^3 and rays from make_ray(rng, u) that `Box` defers
// to SlabRobust (its Fallback) get SlabRobust's answers, bit for bit.
template <typename Box, typename MakeRay>
void expect_answers_of_slab_robust(unsigned seed, MakeRay make_ray, int min_hits) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-4, 4);
  int hits_seen = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f p{u(rng), u(rng), u(rng)}, q{u(rng), u(rng), u(rng)};
    const Ray r = make_ray(rng, u, i);
    BoxHit a, b;
    const bool hit = hits<Box>(r, box(min(p, q), max(p, q)), &a);
    ASSERT_EQ(hit, hits<SlabRobust>(r, box(min(p, q), max(p, q)), &b)) << "ray " << i;
    if (hit) {
      EXPECT_EQ(a.t_entry, b.t_entry);
      EXPECT_EQ(a.t_exit, b.t_exit);
      ++hits_seen;
    }
  }
  EXPECT_GT(hits_seen, min_hits);
}

TEST(SlabRobustRay, WithANegativeTnearPadsEveryExitAsSlabRobust) {
  // Scaling a negative far distance up would shorten it, so rays that start
  // behind their origin take SlabRobust's padding: the same answers, bit for bit.
  expect_answers_of_slab_robust<SlabRobustRay>(7, [](std::mt19937& rng, auto& u, int) {
    return ray({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, -std::fabs(u(rng)), std::fabs(u(rng)));
  }, 1000);
}

TEST(SlabRobust, NeverMissesRaysAimedExactlyAtEdgesAndCorners) {
  // EXTREMES.md G17. Boxes, origins and targets on the grid 2^-10 Z (boxes in
  // [-16,16]^3, origins in [-64,64]^3); the target is a box corner or a point
  // of a box edge, and d = target - o is a multiple of 2^-10 below 2^7, so
  // exact in float: every ray passes exactly through its target at t = 1 and
  // touches its box. The unpadded test drops a few percent of them.
  std::mt19937 rng(20240613);  // raw mt19937 output is the same everywhere
  const auto grid = [&](std::uint32_t range) {
    return static_cast<float>(static_cast<std::int32_t>(rng() % (2 * range * 1024 + 1)) -
                              static_cast<std::int32_t>(range * 1024)) / 1024.0f;
  };
  constexpr int kRays = 100000;
  int slab_misses = 0, robust_misses = 0, robust_ray_misses = 0, fused_misses = 0, fused_robust_misses = 0;
  for (int i = 0; i < kRays; ++i) {
    const Vec3f p{grid(16), grid(16), grid(16)}, q{grid(16), grid(16), grid(16)};
    const BBox b = box(min(p, q), max(p, q));
    const Vec3f o{grid(64), grid(64), grid(64)};
    Vec3f target;
    for (int axis = 0; axis < 3; ++axis) target[axis] = (rng() & 1) ? b.lower[axis] : b.upper[axis];
    const std::uint32_t free_axis = rng() % 4;  // 3: a corner; else a point of the edge along that axis
    if (free_axis < 3) {
      const auto lo = static_cast<std::int32_t>(b.lower[free_axis] * 1024);
      const auto hi = static_cast<std::int32_t>(b.upper[free_axis] * 1024);
      target[free_axis] = static_cast<float>(lo + static_cast<std::int32_t>(rng() % (hi - lo + 1))) / 1024.0f;
    }
    const Vec3f d = target - o;
    for (int axis = 0; axis < 3; ++axis)
      ASSERT_EQ(double{d[axis]}, double{target[axis]} - double{o[axis]}) << "d is not exact, ray " << i;
    const Ray r = ray(o, d);
    slab_misses += !hits<Slab>(r, b);
    robust_misses += !hits<SlabRobust>(r, b);
    robust_ray_misses += !hits<SlabRobustRay>(r, b);
    fused_misses += !hits<SlabFma>(r, b);
    fused_robust_misses += !hits<SlabFmaRobust>(r, b);
  }
  EXPECT_EQ(robust_misses, 0);
  EXPECT_EQ(robust_ray_misses, 0) << "SlabRobustRay, the padding folded into the ray";
  EXPECT_EQ(fused_robust_misses, 0) << "SlabFmaRobust, the fused form with offsets";
  EXPECT_GT(slab_misses, kRays / 100);  // the set is hard: without padding > 1 % are lost
  EXPECT_GT(fused_misses, kRays / 100);
}

// ---------------------------------------------------------------------------
// SlabFmaRobust: the fused form, conservative by offsets set once per ray
// over the extent of the planes (aabb_slab_fma_robust.h). Its entries may
// lie below the exact ones by its margin, so it has its own specification
// here rather than the exact entries of AllBoxTests.

TEST(SlabFmaRobust, HitsTheCornerTheUnpaddedTestMissesByRounding) {
  BoxHit h;
  ASSERT_TRUE(hits<SlabFmaRobust>(kCornerGrazer, kUnit, &h));
  EXPECT_LE(h.t_entry, 1.0f);
  EXPECT_GE(h.t_exit, 1.0f);
}

TEST(SlabFmaRobust, WhereOTimesOneOverDIsExactTheOffsetsMoveEachDistanceByTheMarginAlone) {
  // o = (-1, 0.5, 0.5), d = (1, 1, 1) against [0,2]x[0,1]x[0,1]: on x,
  // o/d = -1 exactly and the planes reach 2, so the margin is
  // (2 + 1) * 2^-21; the near distance 1 falls by it, the far one, 3, rises.
  const BBox b = box({0, 0, 0}, {2, 1, 1});
  const SlabFmaRobust::Offsets o = SlabFmaRobust::offsets(SlabFmaRobust::precompute(ray({-1, 0.5f, 0.5f}, {1, 1, 1})), b);
  EXPECT_EQ(o.near.x, -1.0f + 3 * 0x1p-21f);
  EXPECT_EQ(o.far.x, -1.0f - 3 * 0x1p-21f);
  EXPECT_EQ(o.near.y, 0.5f + 1.5f * 0x1p-21f);  // planes up to 1, |o/d| = 0.5
}

TEST(SlabFmaRobust, ANegativeTnearNeedsNoFallback) {
  // Unlike SlabRobustRay's scaled reciprocals, the offsets hold for
  // distances of either sign: a box behind the origin (t in [-3, -2]),
  // reached by tnear < 0.
  BoxHit h;
  ASSERT_TRUE(hits<SlabFmaRobust>(ray({3, 0.5f, 0.5f}, {1, 0.125f, 0.125f}, -3.0f, -2.0f), kUnit, &h));
  EXPECT_LE(h.t_entry, -3.0f);
  EXPECT_GE(h.t_exit, -2.0f);
  EXPECT_FALSE(hits<SlabFmaRobust>(ray({3, 0.5f, 0.5f}, {1, 0.125f, 0.125f}, -1.0f, 0.0f), kUnit));
}

TEST(SlabFmaRobust, RaysWithAZeroComponentAreTestedAsSlabRobust) {
  expect_answers_of_slab_robust<SlabFmaRobust>(11, [](std::mt19937& rng, auto& u, int i) {
    Vec3f d{u(rng), u(rng), u(rng)};
    d[i % 3] = i % 2 ? 0.0f : -0.0f;
    return ray({u(rng), u(rng), u(rng)}, d, 0.0f, std::fabs(u(rng)));
  }, 500);
}

TEST(SlabFmaRobust, NanAnywhereInTheRayMisses) {
  for (int axis = 0; axis < 3; ++axis) {
    Ray r = ray({-1, 0.5f, 0.5f}, {1, 0.25f, 0.25f});
    r.org[axis] = kNaN;
    EXPECT_FALSE(hits<SlabFmaRobust>(r, kUnit)) << "org " << axis;
    r = ray({-1, 0.5f, 0.5f}, {1, 0.25f, 0.25f});
    r.dir[axis] = kNaN;
    EXPECT_FALSE(hits<SlabFmaRobust>(r, kUnit)) << "dir " << axis;
  }
  EXPECT_FALSE(hits<SlabFmaRobust>(ray({-1, 0.5f, 0.5f}, {1, 0.25f, 0.25f}, kNaN), kUnit));
  EXPECT_FALSE(hits<SlabFmaRobust>(ray({-1, 0.5f, 0.5f}, {1, 0.25f, 0.25f}, 0.0f, kNaN), kUnit));
  EXPECT_FALSE(hits<SlabFmaRobust>(ray({-1, 0.5f, 0.5f}, {1, 0.25f, 0.25f}), BBox{}));  // the empty box
}

TEST(SlabFmaRobust, EntryNeverAboveTheExactEntryNorExitBelowTheExactExitAndBothWithinTheMargin) {
  // Random boxes and rays at several scales and origins up to 10^4 box
  // sizes away, tnear of either sign, tmax finite or not, against distances
  // computed in double (exact to 2^-52). Q = max over axes of
  // (largest |plane| + |o|) / |d| bounds the margin, 8u Q, and the
  // rounding, so the answers may move by at most 2^-20 Q.
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits_seen = 0;
  for (int i = 0; i < 50000; ++i) {
    const float scale = std::ldexp(1.0f, static_cast<int>(rng() % 21) - 10);
    const float away = scale * std::ldexp(1.0f, static_cast<int>(rng() % 14));
    const Vec3f p{u(rng) * scale, u(rng) * scale, u(rng) * scale}, q{u(rng) * scale, u(rng) * scale, u(rng) * scale};
    const BBox b = box(min(p, q), max(p, q));
    const Vec3f o{u(rng) * away, u(rng) * away, u(rng) * away};
    const Vec3f target{u(rng) * scale, u(rng) * scale, u(rng) * scale};
    const float tnear = i % 3 == 0 ? -std::fabs(u(rng)) : 0.0f;
    const float tmax = i % 4 == 0 ? 0.25f + std::fabs(u(rng)) : kInf;
    const Ray r = ray(o, target - o, tnear, tmax);
    double a = tnear, z = tmax, largest = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      const double d = r.dir[axis], lo = b.lower[axis], hi = b.upper[axis];
      ASSERT_NE(d, 0.0);
      const double t_lo = (lo - o[axis]) / d, t_hi = (hi - o[axis]) / d;
      a = std::max(a, std::min(t_lo, t_hi));
      z = std::min(z, std::max(t_lo, t_hi));
      largest = std::max(largest, (std::max(std::fabs(lo), std::fabs(hi)) + std::fabs(o[axis])) / std::fabs(d));
    }
    const double slack = largest * 0x1p-20, roundoff = largest * 0x1p-40;
    BoxHit h;
    const bool hit = hits<SlabFmaRobust>(r, b, &h);
    if (a <= z) {
      ASSERT_TRUE(hit) << "ray " << i << ": the exact ray touches the box";
    }
    if (!hit) continue;
    ++hits_seen;
    EXPECT_LE(h.t_entry, a + roundoff) << "ray " << i;
    EXPECT_GE(h.t_entry, a - slack) << "ray " << i;
    EXPECT_GE(h.t_exit, z - roundoff) << "ray " << i;
    if (z < kInf) {
      EXPECT_LE(h.t_exit, z + slack + std::fabs(z) * 0x1p-20) << "ray " << i;  // the margin, or tmax's pad
    }
  }
  EXPECT_GT(hits_seen, 5000);
}

// ---------------------------------------------------------------------------
// The seed note's bugs (aabb_slab_seed.h), pinned as its documented behaviour;
// each test also shows Slab and SlabRobust getting the same case right.

TEST(SlabSeed, KnownFailure_HitsWithAllNaNDirection) {
  // EXTREMES.md: "the AABB seed hits with an all-NaN direction". Every
  // comparison with NaN is false, so no slab rejects; tmin stays 0.
  const Ray r = ray({0, 0, 0}, {kNaN, kNaN, kNaN});
  const BBox far_away = box({10, 10, 10}, {11, 11, 11});
  BoxHit h;
  ASSERT_TRUE(hits<SlabSeed>(r, far_away, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, kInf);
  EXPECT_FALSE(hits<Slab>(r, far_away));
  EXPECT_FALSE(hits<SlabRobust>(r, far_away));
}

TEST(SlabSeed, KnownFailure_HitsWithNaNOrigin) {
  // On the parallel y and z axes `origin < min || origin > max` is false for
  // NaN; on x the distances are NaN and `if (t1 > tmin)` skips them.
  const Ray r = ray({kNaN, kNaN, kNaN}, {1, 0, 0});
  const BBox far_away = box({10, 10, 10}, {11, 11, 11});
  EXPECT_TRUE(hits<SlabSeed>(r, far_away));
  EXPECT_FALSE(hits<Slab>(r, far_away));
  EXPECT_FALSE(hits<SlabRobust>(r, far_away));
}

TEST(SlabSeed, KnownFailure_HitsTheEmptyBox) {
  // lower = +inf, upper = -inf: t1 = +inf, t2 = -inf, swapped into (-inf, +inf).
  EXPECT_TRUE(hits<SlabSeed>(ray({0, 0, 0}, {1, 1, 1}), BBox{}));
  EXPECT_FALSE(hits<Slab>(ray({0, 0, 0}, {1, 1, 1}), BBox{}));
  EXPECT_FALSE(hits<SlabRobust>(ray({0, 0, 0}, {1, 1, 1}), BBox{}));
}

TEST(SlabSeed, KnownFailure_TreatsSmallDirectionAsParallel) {
  // o = (0,0.5,0.5), d = (1, 5e-7, 0): y leaves [0,1] at t = 1e6, and at
  // x = 2e6, where the box begins, y = 1.5. The note's `|d| < 1e-6` calls
  // the y component parallel and only checks that the origin is in the slab.
  const Ray r = ray({0, 0.5f, 0.5f}, {1, 5e-7f, 0});
  const BBox b = box({2e6f, 0, 0}, {3e6f, 1, 1});
  BoxHit h;
  ASSERT_TRUE(hits<SlabSeed>(r, b, &h));
  EXPECT_EQ(h.t_entry, 2e6f);
  EXPECT_FALSE(hits<Slab>(r, b));
  EXPECT_FALSE(hits<SlabRobust>(r, b));
}

TEST(SlabSeed, KnownFailure_MissesWithAShortDirection) {
  // EXTREMES.md G16: d = (1e-7, 0, 0) reaches the box at t = 1e7; the note
  // sees three parallel components and an origin outside the x slab.
  const Ray r = ray({-1, 0.5f, 0.5f}, {1e-7f, 0, 0});
  EXPECT_FALSE(hits<SlabSeed>(r, kUnit));
  BoxHit h;
  ASSERT_TRUE(hits<Slab>(r, kUnit, &h));
  EXPECT_FLOAT_EQ(h.t_entry, 1e7f);
  ASSERT_TRUE(hits<SlabRobust>(r, kUnit, &h));
  EXPECT_FLOAT_EQ(h.t_entry, 1e7f);
}

TEST(SlabSeed, KnownFailure_IgnoresTnear) {
  // The box is at t in [1, 2], all before tnear = 5; the note starts tmin at 0.
  const Ray r = ray({-1, 0.5f, 0.5f}, {1, 0, 0}, 5.0f);
  BoxHit h;
  ASSERT_TRUE(hits<SlabSeed>(r, kUnit, &h));
  EXPECT_EQ(h.t_entry, 1.0f);
  EXPECT_FALSE(hits<Slab>(r, kUnit));
  EXPECT_FALSE(hits<SlabRobust>(r, kUnit));
}

TEST(SlabSeed, KnownFailure_InfiniteDirectionHitsAtTheOrigin) {
  // d.x = inf: 1/d = 0, so t1 = t2 = 0 whatever the origin; o = (-5,...) is
  // outside the x slab, yet the slab counts as crossed at t = 0.
  const Ray r = ray({-5, 0.5f, 0.5f}, {kInf, 0, 0});
  BoxHit h;
  ASSERT_TRUE(hits<SlabSeed>(r, kUnit, &h));
  EXPECT_EQ(h.t_entry, 0.0f);
  EXPECT_EQ(h.t_exit, 0.0f);
  EXPECT_FALSE(hits<Slab>(r, kUnit));
  EXPECT_FALSE(hits<SlabRobust>(r, kUnit));
}

TEST(SlabSeed, KnownFailure_MissesBoxTheExactRayTouchesByRounding) {
  // Same arithmetic as Slab, same loss (kCornerGrazer above).
  EXPECT_FALSE(hits<SlabSeed>(kCornerGrazer, kUnit));
  EXPECT_TRUE(hits<SlabRobust>(kCornerGrazer, kUnit));
}

TEST(BoxTests, NamesAndAccuracyClasses) {
  EXPECT_EQ(SlabSeed::name, "slab_seed");
  EXPECT_EQ(Slab::name, "slab");
  EXPECT_EQ(SlabRobust::name, "slab_robust");
  EXPECT_EQ(SlabFma::name, "slab_fma");
  EXPECT_EQ(SlabSeed::accuracy, AccuracyClass::kEpsilon);
  EXPECT_EQ(Slab::accuracy, AccuracyClass::kFast);
  EXPECT_EQ(SlabRobust::accuracy, AccuracyClass::kConservative);
  EXPECT_EQ(SlabFma::accuracy, AccuracyClass::kFast);
}

}  // namespace
}  // namespace raybench
