// Specification of the exact box, OBB and sphere referees
// (harness/src/referee/exact_primitives.h): answers worked out by hand on
// inputs whose exact values are known (corners, tangents, origins on the
// surface, powers of two), and consistency with the kernels on random rays
// where the kernels' own guarantees hold.
#include "referee/exact_primitives.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "scene/random.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/prim/sphere_precise.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

Ray make_ray(Vec3f org, Vec3f dir, float tnear = 0.0f, float tfar = kInf) { return Ray{org, tnear, dir, tfar}; }

BBox unit_box() { return BBox{{0, 0, 0}, {1, 1, 1}}; }

// ---------------------------------------------------------------------------
// Box: the closed solid [0,1]^3.

TEST(ExactBox, EntersAtTheNearFace) {
  const ExactPrimitiveHit h = exact_intersect(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}), unit_box());
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 4.0);
  EXPECT_FALSE(h.exit);
  EXPECT_FALSE(exact_intersect(make_ray({-4, 1.5f, 0.5f}, {1, 0, 0}), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {-1, 0, 0}), unit_box()).hit);  // box behind
}

TEST(ExactBox, TIsTheNearestDouble) {
  // Entry at x = 1 with d.x = 3 from x = 0: t = 1/3, which double division rounds correctly.
  const ExactPrimitiveHit h = exact_intersect(make_ray({0, 0.5f, 0.5f}, {3, 0, 0}), BBox{{1, 0, 0}, {2, 1, 1}});
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 1.0 / 3.0);
}

TEST(ExactBox, RayThroughACornerOnlyHitsTheClosedBox) {
  // From (2, 0, 1) along (-1, 1, 0): x in [0,1] for t in [1,2], y for t in
  // [0,1], z = 1 on the upper plane for every t: the corner (1, 1, 1) at t = 1.
  for (const float zero : {0.0f, -0.0f}) {
    const ExactPrimitiveHit h = exact_intersect(make_ray({2, 0, 1}, {-1, 1, zero}), unit_box());
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.t, 1.0);
  }
  // One float step away, in x or in z, the ray misses the corner.
  EXPECT_FALSE(exact_intersect(make_ray({std::nextafter(2.0f, 3.0f), 0, 1}, {-1, 1, 0}), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray({2, 0, std::nextafter(1.0f, 2.0f)}, {-1, 1, 0}), unit_box()).hit);
  // The corner's diagonal: in at (0,0,0), out at (1,1,1).
  const ExactPrimitiveHit d = exact_intersect(make_ray({-1, -1, -1}, {1, 1, 1}), unit_box());
  ASSERT_TRUE(d.hit);
  EXPECT_EQ(d.t, 1.0);
}

TEST(ExactBox, SignOfZeroNeverMatters) {
  // G09: origin on the slab plane y = 1 outside the box, moving along it.
  for (const float zy : {0.0f, -0.0f})
    for (const float zz : {0.0f, -0.0f}) {
      const ExactPrimitiveHit h = exact_intersect(make_ray({-1, 1, 0.5f}, {1, zy, zz}), unit_box());
      ASSERT_TRUE(h.hit);
      EXPECT_EQ(h.t, 1.0);
      EXPECT_FALSE(exact_intersect(make_ray({-1, std::nextafter(1.0f, 2.0f), 0.5f}, {1, zy, zz}), unit_box()).hit);
    }
}

TEST(ExactBox, OriginInsideHitsTheExit) {
  const ExactPrimitiveHit h = exact_intersect(make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}), unit_box());
  ASSERT_TRUE(h.hit);
  EXPECT_TRUE(h.exit);
  EXPECT_EQ(h.t, 0.75);
  // Ending inside: the solid is hit, t is where the segment ends.
  const ExactPrimitiveHit seg = exact_intersect(make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.5f), unit_box());
  ASSERT_TRUE(seg.hit);
  EXPECT_EQ(seg.t, 0.5);
}

TEST(ExactBox, OriginOnTheSurface) {
  // G11. Outward from the face x = 1: only t = 0 touches the box, and the
  // interval (0, tfar] is open there: a miss with start_contact.
  const ExactPrimitiveHit out = exact_intersect(make_ray({1, 0.5f, 0.5f}, {1, 0, 0}), unit_box());
  EXPECT_FALSE(out.hit);
  EXPECT_TRUE(out.start_contact);
  // Inward: through the box, out at the far face.
  const ExactPrimitiveHit in = exact_intersect(make_ray({1, 0.5f, 0.5f}, {-1, 0, 0}), unit_box());
  ASSERT_TRUE(in.hit);
  EXPECT_TRUE(in.exit);
  EXPECT_EQ(in.t, 1.0);
  // Along the face (a zero normal component): in the closed box up to y = 1.
  const ExactPrimitiveHit along = exact_intersect(make_ray({1, 0.5f, 0.5f}, {-0.0f, 1, 0}), unit_box());
  ASSERT_TRUE(along.hit);
  EXPECT_EQ(along.t, 0.5);
  // From a corner, pointing away: touched at t = 0 only.
  const ExactPrimitiveHit corner = exact_intersect(make_ray({1, 1, 1}, {1, 1, 1}), unit_box());
  EXPECT_FALSE(corner.hit);
  EXPECT_TRUE(corner.start_contact);
  // A negative tnear does not reopen the past: the interval is (max(tnear, 0), tfar].
  EXPECT_FALSE(exact_intersect(make_ray({1, 0.5f, 0.5f}, {1, 0, 0}, -5.0f), unit_box()).hit);
}

TEST(ExactBox, IntervalIsOpenAtTnearClosedAtTfar) {
  const Vec3f o{-4, 0.5f, 0.5f}, d{1, 0, 0};
  EXPECT_TRUE(exact_intersect(make_ray(o, d, 0, 4.0f), unit_box()).hit);  // t = tfar counts
  EXPECT_FALSE(exact_intersect(make_ray(o, d, 0, std::nextafter(4.0f, 0.0f)), unit_box()).hit);
  const ExactPrimitiveHit from4 = exact_intersect(make_ray(o, d, 4.0f), unit_box());  // starts on the face
  ASSERT_TRUE(from4.hit);
  EXPECT_EQ(from4.t, 5.0);
  const ExactPrimitiveHit from5 = exact_intersect(make_ray(o, d, 5.0f), unit_box());
  EXPECT_FALSE(from5.hit);
  EXPECT_TRUE(from5.start_contact);
  EXPECT_FALSE(exact_intersect(make_ray(o, d, 5.0f, 4.0f), unit_box()).hit);  // tnear > tfar
  EXPECT_FALSE(exact_intersect(make_ray(o, d, 0, -kInf), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray(o, d, kInf), unit_box()).hit);
}

TEST(ExactBox, HitMissIndependentOfDirectionLength) {
  // G16: t scales as 1/|d|, exactly, for any length the float can hold.
  for (const float s : {0x1p-70f, 0x1p-20f, 0x1p+20f, 0x1p+70f}) {
    const ExactPrimitiveHit h = exact_intersect(make_ray({-4, 0.5f, 0.5f}, {s, 0, 0}), unit_box());
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.t, 4.0 / s);
  }
  const float denormal = 1e-40f;
  const ExactPrimitiveHit h = exact_intersect(make_ray({-4, 0.5f, 0.5f}, {denormal, 0, 0}), unit_box());
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 4.0 / static_cast<double>(denormal));  // correctly rounded double division
  EXPECT_TRUE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {std::numeric_limits<float>::max(), 0, 0}), unit_box()).hit);
}

TEST(ExactBox, InvalidRaysAndBoxes) {
  EXPECT_FALSE(exact_intersect(make_ray({kNaN, 0.5f, 0.5f}, {1, 0, 0}), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {kNaN, kNaN, kNaN}), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {kInf, 0, 0}), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray({0.5f, 0.5f, 0.5f}, {0, -0.0f, 0}), unit_box()).hit);  // no direction
  EXPECT_FALSE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}, kNaN), unit_box()).hit);
  EXPECT_FALSE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}, 0, kNaN), unit_box()).hit);
  EXPECT_FALSE(is_exact_ray(make_ray({0, 0, 0}, {0, 0, 0})));
  EXPECT_TRUE(is_exact_ray(make_ray({0, 0, 0}, {1e-40f, 0, 0})));
  EXPECT_FALSE(exact_intersect(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}), BBox{}).hit);  // the empty box
  EXPECT_THROW(exact_intersect(make_ray({-4, 0, 0}, {1, 0, 0}), BBox{{0, kNaN, 0}, {1, 1, 1}}), std::invalid_argument);
  EXPECT_THROW(exact_intersect(make_ray({-4, 0, 0}, {1, 0, 0}), BBox{{-kInf, 0, 0}, {1, 1, 1}}), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// OBB: { p : |(p - c).a_i| <= h_i } with the axes as given.

OrientedBox obb(Vec3f c, Vec3f a0, Vec3f a1, Vec3f a2, Vec3f h) {
  OrientedBox b;
  b.center = c;
  b.axis[0] = a0;
  b.axis[1] = a1;
  b.axis[2] = a2;
  b.half_extent = h;
  return b;
}

TEST(ExactObb, AxisAlignedAgreesWithTheBox) {
  const OrientedBox b = obb({0.5f, 0.5f, 0.5f}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.5f, 0.5f});
  const Ray rays[] = {make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}), make_ray({2, 0, 1}, {-1, 1, -0.0f}),
                      make_ray({1, 0.5f, 0.5f}, {1, 0, 0}),  make_ray({1, 0.5f, 0.5f}, {-1, 0, 0}),
                      make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}), make_ray({-1, 1.5f, 0.5f}, {1, 0, 0}),
                      make_ray({-1, -1, -1}, {1, 1, 1}), make_ray({1, 1, 1}, {1, 1, 1})};
  for (const Ray& r : rays) {
    const ExactPrimitiveHit a = exact_intersect(r, b), e = exact_intersect(r, unit_box());
    EXPECT_EQ(a.hit, e.hit);
    EXPECT_EQ(a.start_contact, e.start_contact);
    EXPECT_EQ(a.exit, e.exit);
    if (e.hit) {
      EXPECT_EQ(a.t, e.t);
    }
  }
}

TEST(ExactObb, RotatedBoxWithExactAxes) {
  // Axes (3,4,0) and (-4,3,0), unnormalised, with h = 25: the slabs
  // |3x + 4y| <= 25 and |-4x + 3y| <= 25 are those of a square rotated by
  // atan(4/3) with half side 5, whose vertices are the integer points
  // (-1,7), (7,1), (1,-7), (-7,-1).
  const OrientedBox b = obb({0, 0, 0}, {3, 4, 0}, {-4, 3, 0}, {0, 0, 1}, {25, 25, 1});
  // Along the x axis: |3x| <= 25 and |4x| <= 25, so x in [-6.25, 6.25].
  const ExactPrimitiveHit h = exact_intersect(make_ray({-20, 0, 0}, {1, 0, 0}), b);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 13.75);
  const ExactPrimitiveHit inside = exact_intersect(make_ray({0, 0, 0}, {1, 0, 0}), b);
  ASSERT_TRUE(inside.hit);
  EXPECT_TRUE(inside.exit);
  EXPECT_EQ(inside.t, 6.25);
  // The line y = 7 touches the square at the vertex (-1, 7) only: a hit at
  // t = 19; one float step above, a miss; one below, a hit just before it.
  const ExactPrimitiveHit vertex = exact_intersect(make_ray({-20, 7, 0}, {1, 0, 0}), b);
  ASSERT_TRUE(vertex.hit);
  EXPECT_EQ(vertex.t, 19.0);
  EXPECT_FALSE(exact_intersect(make_ray({-20, std::nextafter(7.0f, 8.0f), 0}, {1, 0, 0}), b).hit);
  const ExactPrimitiveHit below = exact_intersect(make_ray({-20, std::nextafter(7.0f, 0.0f), 0}, {1, 0, 0}), b);
  ASSERT_TRUE(below.hit);
  EXPECT_LT(below.t, 19.0);
  EXPECT_GT(below.t, 18.999);
}

TEST(ExactObb, OriginOnAFace) {
  const OrientedBox b = obb({0, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, 0, -1}, {1, 2, 3});  // a signed permutation
  // The face x = 2 (axis 1 = -x, h = 2).
  const ExactPrimitiveHit out = exact_intersect(make_ray({2, 0, 0}, {1, 0.5f, 0}), b);
  EXPECT_FALSE(out.hit);
  EXPECT_TRUE(out.start_contact);
  const ExactPrimitiveHit in = exact_intersect(make_ray({2, 0, 0}, {-1, 0, 0}), b);
  ASSERT_TRUE(in.hit);
  EXPECT_EQ(in.t, 4.0);
  EXPECT_TRUE(in.exit);
}

TEST(ExactObb, AxesAreTakenAsGiven) {
  // An axis of length 2 with h = 1 is the slab |2 (x - c)| <= 1: half width 0.5.
  const OrientedBox b = obb({0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1});
  const ExactPrimitiveHit h = exact_intersect(make_ray({-5, 0, 0}, {1, 0, 0}), b);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 4.5);
  EXPECT_FALSE(exact_intersect(make_ray({-5, 0, 0}, {1, 0, 0}), obb({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, -1, 1})).hit);
}

// ---------------------------------------------------------------------------
// Sphere: the surface |p - c| = r.

const Sphere kUnitAt5{{0, 0, 5}, 1.0f};

TEST(ExactSphere, PythagoreanRootsAreExact) {
  // Offset 0.75 from the axis of a sphere of radius 1.25: half chord 1.
  const ExactPrimitiveHit h = exact_intersect(make_ray({0.75f, 0, 0}, {0, 0, 1}), Sphere{{0, 0, 5}, 1.25f});
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 4.0);
  EXPECT_FALSE(h.exit);
  const ExactPrimitiveHit far = exact_intersect(make_ray({0.75f, 0, 0}, {0, 0, 1}, 4.0f), Sphere{{0, 0, 5}, 1.25f});
  ASSERT_TRUE(far.hit);
  EXPECT_TRUE(far.exit);
  EXPECT_EQ(far.t, 6.0);
}

TEST(ExactSphere, IrrationalRootIsRoundedToNearest) {
  // Roots 2 -/+ sqrt(0.75): compare with long double, good to ~1e-19.
  const ExactPrimitiveHit h = exact_intersect(make_ray({0.5f, 0, -2}, {0, 0, 1}), Sphere{{0, 0, 0}, 1.0f});
  ASSERT_TRUE(h.hit);
  const long double t0 = 2.0L - std::sqrt(0.75L);
  EXPECT_EQ(h.t, static_cast<double>(t0));
}

TEST(ExactSphere, NoCancellationNearTheSurface) {
  // Origin 2^-20 outside the unit sphere on the axis: roots exactly 2^-20
  // and 2 + 2^-20; the textbook (-b - sqrt(D)) / a would cancel.
  const ExactPrimitiveHit h = exact_intersect(make_ray({0, 0, -1.0f - 0x1p-20f}, {0, 0, 1}), Sphere{{0, 0, 0}, 1.0f});
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 0x1p-20);
  // The same with the direction reversed from the other side (b > 0 branch).
  const ExactPrimitiveHit g = exact_intersect(make_ray({0, 0, 1.0f + 0x1p-20f}, {0, 0, -1}), Sphere{{0, 0, 0}, 1.0f});
  ASSERT_TRUE(g.hit);
  EXPECT_EQ(g.t, 0x1p-20);
}

TEST(ExactSphere, TangentRayHits) {
  const ExactPrimitiveHit h = exact_intersect(make_ray({1, 0, 0}, {0, 0, 1}), kUnitAt5);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 5.0);
  EXPECT_FALSE(exact_intersect(make_ray({std::nextafter(1.0f, 2.0f), 0, 0}, {0, 0, 1}), kUnitAt5).hit);
  EXPECT_TRUE(exact_intersect(make_ray({std::nextafter(1.0f, 0.0f), 0, 0}, {0, 0, 1}), kUnitAt5).hit);
}

TEST(ExactSphere, OriginInsideHitsTheFarSide) {
  // G10, centre behind the origin (the seed's failure) and ahead.
  const ExactPrimitiveHit behind = exact_intersect(make_ray({0, 0, 5.5f}, {0, 0, 1}), kUnitAt5);
  ASSERT_TRUE(behind.hit);
  EXPECT_TRUE(behind.exit);
  EXPECT_EQ(behind.t, 0.5);
  const ExactPrimitiveHit ahead = exact_intersect(make_ray({0, 0, 4.5f}, {0, 0, 1}), kUnitAt5);
  ASSERT_TRUE(ahead.hit);
  EXPECT_EQ(ahead.t, 1.5);
  // A segment ending inside crosses no surface.
  EXPECT_FALSE(exact_intersect(make_ray({0, 0, 4.5f}, {0, 0, 1}, 0, 1.0f), kUnitAt5).hit);
}

TEST(ExactSphere, OriginOnTheSurface) {
  const ExactPrimitiveHit out = exact_intersect(make_ray({0, 0, 6}, {0, 0, 1}), kUnitAt5);  // roots -2 and 0
  EXPECT_FALSE(out.hit);
  EXPECT_TRUE(out.start_contact);
  const ExactPrimitiveHit in = exact_intersect(make_ray({0, 0, 6}, {0, 0, -1}), kUnitAt5);  // roots 0 and 2
  ASSERT_TRUE(in.hit);
  EXPECT_TRUE(in.exit);
  EXPECT_EQ(in.t, 2.0);
  const ExactPrimitiveHit tangent = exact_intersect(make_ray({0, 1, 5}, {0, 0, 1}), kUnitAt5);  // double root 0
  EXPECT_FALSE(tangent.hit);
  EXPECT_TRUE(tangent.start_contact);
}

TEST(ExactSphere, IntervalAndDirectionLength) {
  EXPECT_TRUE(exact_intersect(make_ray({0, 0, 0}, {0, 0, 1}, 0, 4.0f), kUnitAt5).hit);
  EXPECT_FALSE(exact_intersect(make_ray({0, 0, 0}, {0, 0, 1}, 0, std::nextafter(4.0f, 0.0f)), kUnitAt5).hit);
  EXPECT_FALSE(exact_intersect(make_ray({0, 0, 10}, {0, 0, 1}), kUnitAt5).hit);  // behind
  for (const float s : {0x1p-70f, 0x1p+70f}) {
    const ExactPrimitiveHit h = exact_intersect(make_ray({0, 0, 0}, {0, 0, s}), kUnitAt5);
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.t, 4.0 / s);
  }
  EXPECT_FALSE(exact_intersect(make_ray({0, 0, 0}, {0, kNaN, 1}), kUnitAt5).hit);
  EXPECT_FALSE(exact_intersect(make_ray({0, 0, 0}, {0, 0, 0}), kUnitAt5).hit);
  EXPECT_THROW(exact_intersect(make_ray({0, 0, 0}, {0, 0, 1}), Sphere{{0, 0, 5}, kNaN}), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Random rays: what the kernels guarantee must hold against the referee.

Vec3f random_point(Rng& rng, float half) {
  return {static_cast<float>((2 * rng.next_double() - 1) * half), static_cast<float>((2 * rng.next_double() - 1) * half),
          static_cast<float>((2 * rng.next_double() - 1) * half)};
}

TEST(ExactBox, SlabRobustNeverMissesWhatTheRefereeHits) {
  // SlabRobust is conservative (prim/aabb_slab_robust.h): every exact hit must
  // be one of its hits, and its padded [entry, exit] must contain t.
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    Rng rng(7, 1, i);
    BBox b;
    b.extend(random_point(rng, 1));
    b.extend(random_point(rng, 1));
    const Vec3f o = random_point(rng, 3), target = random_point(rng, 1.2f);
    const Ray r = make_ray(o, target - o);
    const ExactPrimitiveHit e = exact_intersect(r, b);
    BoxHit k{};
    const bool kernel = SlabRobust::intersect(SlabRobust::precompute(r), b, r.tfar, k);
    if (!e.hit) continue;
    ++hits;
    ASSERT_TRUE(kernel) << "ray " << i;
    const double t_kernel = e.exit ? k.t_exit : k.t_entry;
    EXPECT_NEAR(t_kernel, e.t, 1e-5 * std::max(1.0, std::fabs(e.t))) << "ray " << i;
  }
  EXPECT_GT(hits, 2000);  // the test must exercise hits (2,791 of these rays do)
}

TEST(ExactSphere, AgreesWithLongDoubleAwayFromTangency) {
  // Where the line passes well inside or outside the sphere, long double
  // decides hit/miss correctly and its roots are good to ~1e-15.
  int compared = 0;
  for (int i = 0; i < 20000; ++i) {
    Rng rng(7, 2, i);
    const Sphere s{random_point(rng, 1), static_cast<float>(0.1 + 0.9 * rng.next_double())};
    const Vec3f o = random_point(rng, 3), target = random_point(rng, 1.5f);
    const Ray r = make_ray(o, target - o);
    using L = long double;
    const L fx = L(o.x) - s.center.x, fy = L(o.y) - s.center.y, fz = L(o.z) - s.center.z;
    const L a = L(r.dir.x) * r.dir.x + L(r.dir.y) * r.dir.y + L(r.dir.z) * r.dir.z;
    const L b = fx * r.dir.x + fy * r.dir.y + fz * r.dir.z;
    const L c = fx * fx + fy * fy + fz * fz - L(s.radius) * s.radius;
    const L D = b * b - a * c;
    if (std::fabs(D) < 1e-6L * b * b) continue;  // near tangent: leave it to the exact test
    const L t0 = (-b - std::sqrt(std::max(D, L(0)))) / a, t1 = (-b + std::sqrt(std::max(D, L(0)))) / a;
    if (std::fabs(t0) < 1e-6L || std::fabs(t1) < 1e-6L) continue;  // origin near the surface
    const bool hit = D >= 0 && t1 > 0;
    const ExactPrimitiveHit e = exact_intersect(r, s);
    ASSERT_EQ(e.hit, hit) << "ray " << i;
    if (hit) {
      EXPECT_NEAR(e.t, static_cast<double>(t0 > 0 ? t0 : t1), 1e-12) << "ray " << i;
      SphereHit k;
      EXPECT_TRUE(SpherePrecise::intersect(r, r.tfar, s, k));
    }
    ++compared;
  }
  EXPECT_GT(compared, 15000);
}


// ---------------------------------------------------------------------------
// Surface semantics (exact_intersect_surface): the analytic primitives of a
// scene are crossed, not filled (prim/analytic_hit.h).

TEST(ExactSurface, BoxEnteredFromOutsideAsTheSolid) {
  const ExactPrimitiveHit h = exact_intersect_surface(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}), unit_box());
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 4.0);
  EXPECT_FALSE(h.exit);
  EXPECT_FALSE(h.start_contact);
  // Entry beyond tfar: no crossing in the interval.
  EXPECT_FALSE(exact_intersect_surface(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 3.5f), unit_box()).hit);
  // tfar exactly at the entry: closed there.
  EXPECT_TRUE(exact_intersect_surface(make_ray({-4, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 4.0f), unit_box()).hit);
}

TEST(ExactSurface, FromInsideTheExitOrNothing) {
  const ExactPrimitiveHit h = exact_intersect_surface(make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}), unit_box());
  ASSERT_TRUE(h.hit);
  EXPECT_TRUE(h.exit);
  EXPECT_EQ(h.t, 0.75);
  // Ending inside: the solid is hit (t = tfar), the surface is not crossed.
  EXPECT_TRUE(exact_intersect(make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.5f), unit_box()).hit);
  EXPECT_FALSE(exact_intersect_surface(make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.5f), unit_box()).hit);
  EXPECT_TRUE(exact_intersect_surface(make_ray({0.25f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.75f), unit_box()).hit);
  // The same for an oriented box (a signed permutation of the axes: exact).
  const OrientedBox b = obb({0, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, 0, -1}, {1, 2, 3});
  const ExactPrimitiveHit o = exact_intersect_surface(make_ray({0, 0, 0}, {1, 0, 0}), b);
  ASSERT_TRUE(o.hit);
  EXPECT_TRUE(o.exit);
  EXPECT_EQ(o.t, 2.0);
  EXPECT_FALSE(exact_intersect_surface(make_ray({0, 0, 0}, {1, 0, 0}, 0.0f, 1.5f), b).hit);
}

TEST(ExactSurface, OriginOnTheSurfaceIsAContactHitOrMiss) {
  // Inward from the face x = 1: the exit at x = 0, and the origin touches the surface.
  const ExactPrimitiveHit in = exact_intersect_surface(make_ray({1, 0.5f, 0.5f}, {-1, 0, 0}), unit_box());
  ASSERT_TRUE(in.hit);
  EXPECT_TRUE(in.exit);
  EXPECT_EQ(in.t, 1.0);
  EXPECT_TRUE(in.start_contact);
  const ExactPrimitiveHit out = exact_intersect_surface(make_ray({1, 0.5f, 0.5f}, {1, 0, 0}), unit_box());
  EXPECT_FALSE(out.hit);
  EXPECT_TRUE(out.start_contact);
  // Sphere: roots 0 and 2 from the surface inward; solid-style exact_intersect
  // reports no contact for the hit, the surface referee does.
  EXPECT_FALSE(exact_intersect(make_ray({0, 0, 6}, {0, 0, -1}), kUnitAt5).start_contact);
  const ExactPrimitiveHit s = exact_intersect_surface(make_ray({0, 0, 6}, {0, 0, -1}), kUnitAt5);
  ASSERT_TRUE(s.hit);
  EXPECT_TRUE(s.exit);
  EXPECT_EQ(s.t, 2.0);
  EXPECT_TRUE(s.start_contact);
  EXPECT_FALSE(exact_intersect_surface(make_ray({0, 0, 7}, {0, 0, -1}), kUnitAt5).start_contact);
}

TEST(ExactSurface, AgreesWithTheSolidReadAsTwoCrossings) {
  // The plan's reading: the solid asked with tfar = inf gives the first
  // crossing after lo; it counts when it is <= tfar. Random rays with
  // random intervals through random boxes, both ways.
  int hits = 0, ends_inside = 0;
  for (std::uint64_t i = 0; i < 4000; ++i) {
    Rng rng(3, 0, i);
    const auto u = [&] { return static_cast<float>(rng.next_double() * 4.0 - 2.0); };
    const BBox box{{-1, -0.5f, -0.25f}, {1, 0.5f, 0.25f}};
    // Origins around the box, often inside it; intervals often ending inside.
    const Vec3f org{0.75f * u(), 0.375f * u(), 0.2f * u()};
    Ray r = make_ray(org, {u(), u(), u()}, 0.0f, static_cast<float>(rng.next_double()));
    Ray unbounded = r;
    unbounded.tfar = kInf;
    const ExactPrimitiveHit solid = exact_intersect(unbounded, box);
    const bool expected = solid.hit && solid.t <= r.tfar;
    const ExactPrimitiveHit surface = exact_intersect_surface(r, box);
    ASSERT_EQ(surface.hit, expected) << i;
    if (expected) {
      EXPECT_EQ(surface.t, solid.t) << i;
      EXPECT_EQ(surface.exit, solid.exit) << i;
    }
    hits += expected;
    ends_inside += exact_intersect(r, box).hit && !expected;
  }
  EXPECT_GT(hits, 200);
  EXPECT_GT(ends_inside, 50) << "segments inside the solid, which the surface reading misses";
}

}  // namespace
}  // namespace raybench
