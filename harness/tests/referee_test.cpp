// The exact referee, specified by hand-worked cases (every expected answer
// below follows from exact arithmetic on the given floats) and by the
// properties the accuracy report relies on: it never leaks through a closed
// mesh, and the BVH never hides a candidate from it.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/analytic_hit.h"
#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/sphere_precise.h"
#include "raybench/prim/triangle_watertight.h"
#include "scene/random.h"
#include "rays/rayset.h"
#include "referee/exact_primitives.h"
#include "referee/exact_triangle.h"
#include "referee/referee.h"
#include "scene/scene.h"

namespace raybench {
namespace {

const Triangle kUnit{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // in z = 0, legs along x and y

Ray down_from(float x, float y, float z = 1.0f, float dz = -1.0f) {
  Ray r;
  r.org = {x, y, z};
  r.dir = {0, 0, dz};
  return r;
}

TEST(ExactTriangle, InteriorHitHasTheExactT) {
  const ExactTriangleHit h = exact_intersect(down_from(0.25f, 0.25f), kUnit);
  EXPECT_TRUE(h.hit);
  EXPECT_FALSE(h.on_boundary);
  EXPECT_EQ(h.t, 1.0);
}

TEST(ExactTriangle, TIsTheDoubleNearestTheRationalT) {
  // From z = 1 with dz = -3 the plane is reached at t = 1/3 exactly.
  const ExactTriangleHit h = exact_intersect(down_from(0.25f, 0.25f, 1.0f, -3.0f), kUnit);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 1.0 / 3.0);
  EXPECT_LE(h.t_lower, 1.0 / 3.0);
  EXPECT_GE(h.t_upper, 1.0 / 3.0);
}

TEST(ExactTriangle, EdgesAndVerticesBelongToTheClosedTriangle) {
  for (const Ray& r : {down_from(0.5f, 0.0f), down_from(0.0f, 0.5f), down_from(0.5f, 0.5f), down_from(0, 0),
                       down_from(1, 0), down_from(0, 1)}) {
    const ExactTriangleHit h = exact_intersect(r, kUnit);
    EXPECT_TRUE(h.hit) << r.org.x << " " << r.org.y;
    EXPECT_TRUE(h.on_boundary) << r.org.x << " " << r.org.y;
  }
}

TEST(ExactTriangle, TheSmallestStepOutsideMisses) {
  const float outside = -std::numeric_limits<float>::denorm_min();
  EXPECT_FALSE(exact_intersect(down_from(outside, 0.5f), kUnit).hit);
  EXPECT_FALSE(exact_intersect(down_from(0.5f, outside), kUnit).hit);
  // Just beyond the hypotenuse x + y = 1.
  EXPECT_FALSE(exact_intersect(down_from(0.5f, std::nextafter(0.5f, 1.0f)), kUnit).hit);
}

TEST(ExactTriangle, DegenerateAndCoplanarNeverHit) {
  // G08 (a): exactly collinear integer vertices, 1.777 times each other.
  const Triangle collinear{{0, 0, 0}, {3000, 5000, 7000}, {5331, 8885, 12439}};
  Ray r;
  r.org = {1000, -1000, 3000};
  r.dir = Vec3f{2665.5f, 4442.5f, 6219.5f} - r.org;  // at the middle of the long side
  EXPECT_FALSE(exact_intersect(r, collinear).hit);
  // G08 (b): a repeated vertex.
  EXPECT_FALSE(exact_intersect(down_from(0.25f, 0.0f), Triangle{{0, 0, 0}, {1, 0, 0}, {1, 0, 0}}).hit);
  // G19: a ray in the triangle's plane, crossing it.
  Ray in_plane;
  in_plane.org = {-1.0f, 0.25f, 0.0f};
  in_plane.dir = {1, 0, 0};
  EXPECT_FALSE(exact_intersect(in_plane, kUnit).hit);
}

TEST(ExactTriangle, TheIntervalIsOpenAtTnearAndClosedAtTfar) {
  Ray r = down_from(0.25f, 0.25f);  // t = 1
  r.tnear = 1.0f;
  EXPECT_FALSE(exact_intersect(r, kUnit).hit);
  r.tnear = std::nextafter(1.0f, 0.0f);
  EXPECT_TRUE(exact_intersect(r, kUnit).hit);
  r.tnear = 0.0f;
  r.tfar = 1.0f;
  EXPECT_TRUE(exact_intersect(r, kUnit).hit);
  r.tfar = std::nextafter(1.0f, 0.0f);
  EXPECT_FALSE(exact_intersect(r, kUnit).hit);
}

TEST(ExactTriangle, BehindTheOriginMissesEvenWithANegativeTnear) {
  Ray r = down_from(0.25f, 0.25f, -1.0f);  // the plane is at t = -1 (G14)
  EXPECT_FALSE(exact_intersect(r, kUnit).hit);
  r.tnear = -5.0f;  // the interval is (max(tnear, 0), tfar]
  EXPECT_FALSE(exact_intersect(r, kUnit).hit);
}

TEST(ExactTriangle, UntraceableRaysMiss) {
  Ray r = down_from(0.25f, 0.25f);
  r.dir.z = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(exact_intersect(r, kUnit).hit);
  r = down_from(0.25f, 0.25f);
  r.org.x = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(exact_intersect(r, kUnit).hit);
}

TEST(ExactTriangle, DecidesWhereDoubleArithmeticCannot) {
  // A far origin aimed at a float point of the edge x = 0 of a tiny
  // triangle: the answer hangs on cancellations far below a double ulp of
  // the origin. Exactly on the edge is a hit on the boundary.
  const Triangle tiny{{0, 0, 0}, {1e-7f, 0, 0}, {0, 1e-7f, 0}};
  Ray r;
  r.org = {148376.0f, 1234.0f, -223423.0f};
  r.dir = Vec3f{0.0f, 3.0e-8f, 0.0f} - r.org;
  const ExactTriangleHit h = exact_intersect(r, tiny);
  EXPECT_TRUE(h.hit);
  EXPECT_TRUE(h.on_boundary);
}

Scene two_triangles_sharing_an_edge() {
  Scene s;
  s.name = "pair";
  s.triangles = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},   // prim 0
                 {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}},   // prim 1, sharing the edge (1,0)-(0,1)
                 {{0, 0, -1}, {2, 0, -1}, {0, 2, -1}}};  // prim 2, behind both
  return s;
}

TEST(Referee, ARayThroughASharedEdgeIsATieWithBothAnswersRight) {
  const Scene s = two_triangles_sharing_an_edge();
  const Referee referee(s);
  const Ray r = down_from(0.5f, 0.5f);
  const RefereeVerdict v = referee.judge(r);
  EXPECT_TRUE(v.hit());
  EXPECT_TRUE(v.tie);
  EXPECT_TRUE(v.ambiguous);
  EXPECT_EQ(v.prim, 0);  // the lowest id of the tied triangles
  EXPECT_EQ(v.t, 1.0);
  EXPECT_TRUE(referee.accepts(r, v, 0));
  EXPECT_TRUE(referee.accepts(r, v, 1));
  EXPECT_FALSE(referee.accepts(r, v, 2));  // hit too, but farther
}

TEST(Referee, TheNearestTriangleWinsAndInteriorHitsAreUnambiguous) {
  const Scene s = two_triangles_sharing_an_edge();
  const Referee referee(s);
  const Ray r = down_from(0.75f, 0.6f);  // inside prim 1 only, prim 2 behind it
  const RefereeVerdict v = referee.judge(r);
  EXPECT_EQ(v.prim, 1);
  EXPECT_FALSE(v.tie);
  EXPECT_FALSE(v.ambiguous);
  EXPECT_FALSE(referee.accepts(r, v, 0));
  EXPECT_FALSE(referee.accepts(r, v, 2));
  const RefereeVerdict below = referee.judge(down_from(1.5f, 0.25f));  // misses 0 and 1, hits 2 at t = 2
  EXPECT_EQ(below.prim, 2);
  EXPECT_EQ(below.t, 2.0);
}

TEST(Referee, NeverLeaksThroughAClosedMeshFromInside) {
  const Scene sphere = load_scene("proc:sphere");
  const Referee referee(sphere);
  const RayGenerator generator(sphere);
  for (RaySetKind kind : {RaySetKind::kClosedInsideRandom, RaySetKind::kSharedEdgeAimed, RaySetKind::kVertexAimed}) {
    RaySetSpec spec;
    spec.kind = kind;
    spec.count = 4000;
    spec.inside = InsideBall{{0, 0, 0}, 0.9f};
    const std::vector<Ray> rays = generator.generate(spec);
    std::size_t misses = 0, ties = 0, ambiguous = 0;
    for (const Ray& r : rays) {
      const RefereeVerdict v = referee.judge(r);
      misses += !v.hit();
      ties += v.tie;
      ambiguous += v.ambiguous;
    }
    EXPECT_EQ(misses, 0u) << to_string(kind);
    // d = target - o is rounded, so an aimed ray passes exactly through its
    // vertex or edge only sometimes, and within rounding of it always.
    if (kind == RaySetKind::kVertexAimed) {
      EXPECT_GT(ties, 0u) << "some pass exactly through the vertex";
    }
    if (kind != RaySetKind::kClosedInsideRandom) {
      EXPECT_GT(ambiguous, rays.size() * 9 / 10) << to_string(kind);
    } else {
      EXPECT_LT(ambiguous, rays.size() / 100) << "random directions rarely pass within 1e-5 of an edge";
    }
  }
}

TEST(Referee, TheConservativeBvhHidesNoCandidate) {
  // The same verdicts as judging every triangle exactly, with no tree.
  const Scene mesh = load_scene("proc:terrain_spheres_small");
  const Referee referee(mesh);
  const RayGenerator generator(mesh);
  for (RaySetKind kind : {RaySetKind::kUniform, RaySetKind::kDiffuse}) {
    RaySetSpec spec;
    spec.kind = kind;
    spec.count = 300;
    for (const Ray& r : generator.generate(spec)) {
      const RefereeVerdict v = referee.judge(r);
      std::int32_t nearest = kNoHit;
      double nearest_t = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        const ExactTriangleHit h = exact_intersect(r, mesh.triangles[i]);
        if (h.hit && (h.t < nearest_t || (h.t == nearest_t && compare_exact_t(r, mesh.triangles[i], mesh.triangles[nearest]) < 0))) {
          nearest_t = h.t;
          nearest = static_cast<std::int32_t>(i);
        }
      }
      ASSERT_EQ(v.hit(), nearest != kNoHit) << to_string(kind);
      if (nearest != kNoHit) {
        EXPECT_TRUE(referee.accepts(r, v, nearest)) << to_string(kind);
        EXPECT_NEAR(v.t, nearest_t, 4e-16 * nearest_t);
      }
    }
  }
}


// ---------------------------------------------------------------------------
// Scenes with analytic primitives (issue 31): spheres, boxes and oriented
// boxes are surfaces, ids after the triangles.

// An oriented box rotated by `angle` about the unit axis (x, y, z), axes
// rounded to float (so only approximately orthonormal, as a file gives them).
OrientedBox rotated_box(Vec3f center, Vec3f half, double angle, double x, double y, double z) {
  const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
  const double m[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                          {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                          {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
  OrientedBox b;
  b.center = center;
  b.half_extent = half;
  for (int i = 0; i < 3; ++i)
    b.axis[i] = {static_cast<float>(m[0][i]), static_cast<float>(m[1][i]), static_cast<float>(m[2][i])};
  return b;
}

// A floor of two triangles at y = 0, and on and above it spheres (nested,
// overlapping, tiny, one huge below the floor), boxes (one resting on the
// floor, overlapping ones, a flat one) and rotated boxes; all moved by `offset`.
Scene mixed_scene(Vec3f offset = {0, 0, 0}) {
  Scene s;
  s.name = "mixed";
  const auto at = [&](float x, float y, float z) { return Vec3f{x, y, z} + offset; };
  s.triangles = {{at(-10, 0, -10), at(10, 0, -10), at(10, 0, 10)}, {at(-10, 0, -10), at(10, 0, 10), at(-10, 0, 10)}};
  s.spheres = {{at(0, 1, 0), 1.0f},      {at(0, 1, 0), 0.5f},  // nested
               {at(1.2f, 1, 0), 0.8f},   {at(-3, 1, 2), 1e-4f},  // overlapping; tiny
               {at(4, 3, -4), 2.5f},     {at(0, -1e4f - 1, 0), 1e4f}};  // huge, under the floor
  s.boxes = {{at(-5, 0, -5), at(-3, 2, -3)},   // resting on the floor
             {at(-4, 1, -4), at(-2, 3, -2)},   // overlapping it
             {at(4, 1, 4), at(6, 1, 6)}};      // flat (zero thickness in y)
  s.obbs = {rotated_box(at(5, 2, 0), {1.0f, 0.5f, 0.25f}, 0.7, 0.0, 1.0, 0.0),
            rotated_box(at(-6, 1.5f, 5), {0.5f, 1.5f, 0.75f}, 1.1, 0.48, 0.6, 0.64)};
  return s;
}

// Brute force, independent of the referee's tree and of its surface reading:
// every primitive judged exactly; an analytic one as the plan defines the
// surface, from the solid asked with tfar = inf (the first crossing after
// lo, if it is <= tfar). Returns the nearest (lowest id among equal t) and its t.
std::pair<std::int32_t, double> brute_force(const Scene& s, const Ray& r) {
  const PrimitiveSpans prims = s.primitives();
  std::int32_t nearest = kNoHit;
  double nearest_t = std::numeric_limits<double>::infinity();
  Ray unbounded = r;
  unbounded.tfar = std::numeric_limits<float>::infinity();
  for (std::size_t id = 0; id < prims.size(); ++id) {
    const std::size_t i = prims.local(id);
    ExactPrimitiveHit h;
    switch (prims.kind(id)) {
      case PrimitiveKind::kTriangle: {
        const ExactTriangleHit th = exact_intersect(r, prims.triangles[i]);
        h.hit = th.hit;
        h.t = th.t;
        break;
      }
      case PrimitiveKind::kSphere: h = exact_intersect(unbounded, prims.spheres[i]); break;
      case PrimitiveKind::kBox: h = exact_intersect(unbounded, prims.boxes[i]); break;
      case PrimitiveKind::kOrientedBox: h = exact_intersect(unbounded, prims.obbs[i]); break;
    }
    if (h.hit && h.t <= r.tfar && h.t < nearest_t) {
      nearest_t = h.t;
      nearest = static_cast<std::int32_t>(id);
    }
  }
  return {nearest, nearest_t};
}

Ray ray_from(Vec3f org, Vec3f dir, float tfar = std::numeric_limits<float>::infinity()) {
  Ray r;
  r.org = org;
  r.dir = dir;
  r.tfar = tfar;
  return r;
}

TEST(RefereeAnalytic, IdsFollowTheTrianglesAndTheNearestSurfaceWins) {
  const Scene s = mixed_scene();
  const Referee referee(s);
  // Straight down at the nested spheres: the outer one (id 2) at y = 2, t = 8.
  RefereeVerdict v = referee.judge(ray_from({0, 10, 0}, {0, -1, 0}));
  EXPECT_EQ(v.prim, 2);
  EXPECT_EQ(v.t, 8.0);
  EXPECT_FALSE(v.ambiguous);
  // From between the spheres (inside the outer, outside the inner), down: the inner one at y = 1.5.
  v = referee.judge(ray_from({0, 1.75f, 0}, {0, -1, 0}));
  EXPECT_EQ(v.prim, 3);
  EXPECT_EQ(v.t, 0.25);
  // From the centre: inside both, the inner one's far side first (an exit hit).
  v = referee.judge(ray_from({0, 1, 0}, {0, 1, 0}));
  EXPECT_EQ(v.prim, 3);
  EXPECT_EQ(v.t, 0.5);
  // Down onto the box resting on the floor (first box: id 2 + 6 = 8), its top at y = 2.
  v = referee.judge(ray_from({-4.5f, 10, -4.5f}, {0, -1, 0}));
  EXPECT_EQ(v.prim, 8);
  EXPECT_EQ(v.t, 8.0);
  EXPECT_FALSE(v.ambiguous);
  // The flat box (id 10) is hit from above and from below at y = 1.
  EXPECT_EQ(referee.judge(ray_from({5, 10, 5}, {0, -1, 0})).prim, 10);
  v = referee.judge(ray_from({5, 0.5f, 5}, {0, 1, 0}));
  EXPECT_EQ(v.prim, 10);
  EXPECT_EQ(v.t, 0.5);
}

TEST(RefereeAnalytic, FromInsideABoxTheExitOrNothingWithinTfar) {
  const Scene s = mixed_scene();
  const Referee referee(s);
  // Inside the resting box, not in the overlapping one: out through x = -3 at t = 0.5.
  RefereeVerdict v = referee.judge(ray_from({-3.5f, 0.5f, -4.5f}, {1, 0, 0}));
  EXPECT_EQ(v.prim, 8);
  EXPECT_EQ(v.t, 0.5);
  // A segment ending inside crosses no surface (a solid would be hit).
  EXPECT_FALSE(referee.judge(ray_from({-3.5f, 0.5f, -4.5f}, {1, 0, 0}, 0.25f)).hit());
  // Inside both boxes: the overlapping box's far side (y = 3) is beyond the resting box's top (y = 2).
  v = referee.judge(ray_from({-3.5f, 1.5f, -3.5f}, {0, 1, 0}));
  EXPECT_EQ(v.prim, 8);
  EXPECT_EQ(v.t, 0.5);
}

TEST(RefereeAnalytic, ABoxOnTheFloorTiesWithItFromBelow) {
  // From under the floor, up into the resting box: the floor triangle 0 and
  // the box's bottom face are both at y = 0, t = 1: a tie, both right.
  const Scene s = mixed_scene();
  const Referee referee(s);
  const Ray r = ray_from({-3.5f, -1, -3.8f}, {0, 1, 0});
  const RefereeVerdict v = referee.judge(r);
  ASSERT_TRUE(v.hit());
  EXPECT_TRUE(v.tie);
  EXPECT_TRUE(v.ambiguous);
  EXPECT_EQ(v.prim, 0);  // the lowest id of the tied ones
  EXPECT_EQ(v.t, 1.0);
  EXPECT_TRUE(referee.accepts(r, v, 0));
  EXPECT_TRUE(referee.accepts(r, v, 8));
  EXPECT_FALSE(referee.accepts(r, v, 1));  // the other floor triangle: missed
  EXPECT_FALSE(referee.accepts(r, v, 9));  // the overlapping box: hit too, at y = 1
  EXPECT_FALSE(referee.accepts(r, v, 99));  // no such primitive
}

TEST(RefereeAnalytic, TangentEdgeAndContactRaysAreAmbiguous) {
  const Scene s = mixed_scene();
  const Referee referee(s);
  // Tangent to the sphere at (4, 3, -4) r = 2.5, touching its top (4, 5.5, -4).
  RefereeVerdict v = referee.judge(ray_from({-20, 5.5f, -4}, {1, 0, 0}));
  EXPECT_EQ(v.prim, 6);
  EXPECT_EQ(v.t, 24.0);
  EXPECT_TRUE(v.ambiguous);
  // One float step above the top: a miss, within the band.
  v = referee.judge(ray_from({-20, std::nextafter(5.5f, 6.0f), -4}, {1, 0, 0}));
  EXPECT_FALSE(v.hit());
  EXPECT_TRUE(v.ambiguous);
  // Along the top edge of the overlapping box (y = 3, z = -2): a hit on the edge.
  v = referee.judge(ray_from({-20, 3, -2}, {1, 0, 0}));
  EXPECT_EQ(v.prim, 9);
  EXPECT_EQ(v.t, 16.0);
  EXPECT_TRUE(v.ambiguous);
  // Through the middle of the same face: not ambiguous.
  v = referee.judge(ray_from({-20, 2.5f, -3}, {1, 0, 0}));
  EXPECT_EQ(v.prim, 9);
  EXPECT_FALSE(v.ambiguous);
  // From the box's top face (y = 3), pointing up and out: touches it at t = 0 only.
  v = referee.judge(ray_from({-2.5f, 3, -2.5f}, {0, 1, 0}));
  EXPECT_FALSE(v.hit());
  EXPECT_TRUE(v.ambiguous);
  // The same origin pointing in: through the box to its bottom face (y = 1)
  // at t = 2, an exit hit from an origin on the surface.
  v = referee.judge(ray_from({-2.5f, 3, -2.5f}, {0, -1, 0}));
  EXPECT_EQ(v.prim, 9);
  EXPECT_EQ(v.t, 2.0);
  EXPECT_TRUE(v.ambiguous);
}

TEST(RefereeAnalytic, InvalidRaysMiss) {
  const Scene s = mixed_scene();
  const Referee referee(s);
  Ray r = ray_from({0, 10, 0}, {0, -1, 0});
  r.dir.y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(referee.judge(r).hit());
  r = ray_from({0, 10, 0}, {0, -1, 0});
  r.org.x = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(referee.judge(r).hit());
  EXPECT_FALSE(referee.judge(ray_from({0, 10, 0}, {0, 0, 0})).hit());
}

// Random and hard rays on the mixed scene at several offsets: the referee's
// verdict is the brute-force loop's (its nearest is accepted, t agrees).
// Near the origin the near-tangent rays stay within the band; far from it,
// float coordinates (ulp 1/64 at 1.5e5) move them off by more than it.
void expect_brute_force_agreement(const Scene& s, std::uint64_t seed, bool tangent_rays_stay_tangent) {
  const Referee referee(s);
  const Vec3f offset = s.triangles[0].v0 - Vec3f{-10, 0, -10};
  const PrimitiveSpans prims = s.primitives();
  std::size_t hits = 0, analytic_hits = 0, inside_starts = 0, ambiguous = 0;
  for (std::uint64_t i = 0; i < 3000; ++i) {
    Rng rng(seed, 0, i);
    const auto in = [&](float lo, float hi) { return lo + static_cast<float>(rng.next_double()) * (hi - lo); };
    const auto direction = [&] {
      const double z = 2.0 * rng.next_double() - 1.0, phi = 6.283185307179586 * rng.next_double();
      const double q = std::sqrt(1.0 - z * z);
      return Vec3f{static_cast<float>(q * std::cos(phi)), static_cast<float>(z), static_cast<float>(q * std::sin(phi))};
    };
    Ray r;
    switch (i % 4) {
      case 0:  // origin anywhere in the scene (often inside a primitive), random direction
        r = ray_from(Vec3f{in(-7, 7), in(-1, 6), in(-7, 7)} + offset, direction());
        break;
      case 1: {  // from outside at a random point of a random analytic primitive's box (not the huge sphere's)
        std::size_t id = prims.first_sphere() + rng.next_u64() % (prims.size() - prims.first_sphere());
        if (id == prims.first_box() - 1) id = prims.first_sphere();
        const BBox b = prims.bounds(id);
        const Vec3f target{in(b.lower.x, b.upper.x), in(b.lower.y, b.upper.y), in(b.lower.z, b.upper.z)};
        const Vec3f org = target - direction() * 30.0f;
        r = ray_from(org, target - org);
        break;
      }
      case 2: {  // near-tangent to a sphere: at distance r (1 +- 1e-6) from its centre
        const Sphere& sp = s.spheres[rng.next_u64() % (s.spheres.size() - 1)];
        const Vec3f d = direction();
        Vec3f side = cross(d, Vec3f{0.36f, 0.48f, 0.8f});
        side = side * (1.0f / length(side));
        const float h = sp.radius * static_cast<float>(1.0 + (rng.next_double() - 0.5) * 2e-6);
        r = ray_from(sp.center + side * h - d * 20.0f, d);
        break;
      }
      default:  // a random segment (finite tfar) from inside the bounds
        r = ray_from(Vec3f{in(-7, 7), in(-1, 6), in(-7, 7)} + offset, direction(), in(0.01f, 5.0f));
        break;
    }
    const RefereeVerdict v = referee.judge(r);
    const auto [nearest, nearest_t] = brute_force(s, r);
    ASSERT_EQ(v.hit(), nearest != kNoHit) << "ray " << i;
    ambiguous += v.ambiguous;
    if (nearest == kNoHit) continue;
    ++hits;
    analytic_hits += prims.kind(static_cast<std::size_t>(v.prim)) != PrimitiveKind::kTriangle;
    EXPECT_TRUE(referee.accepts(r, v, nearest)) << "ray " << i << ": " << v.prim << " vs " << nearest;
    EXPECT_NEAR(v.t, nearest_t, 1e-15 * nearest_t) << "ray " << i;
    const auto winner = static_cast<std::size_t>(v.prim);
    switch (prims.kind(winner)) {
      case PrimitiveKind::kSphere: inside_starts += exact_intersect_surface(r, s.spheres[prims.local(winner)]).exit; break;
      case PrimitiveKind::kBox: inside_starts += exact_intersect_surface(r, s.boxes[prims.local(winner)]).exit; break;
      case PrimitiveKind::kOrientedBox: inside_starts += exact_intersect_surface(r, s.obbs[prims.local(winner)]).exit; break;
      default: break;
    }
  }
  EXPECT_GT(hits, 1500u);
  EXPECT_GT(analytic_hits, 1000u);
  EXPECT_GT(inside_starts, 100u) << "rays from inside spheres and boxes";
  if (tangent_rays_stay_tangent) {
    EXPECT_GT(ambiguous, 100u) << "the near-tangent rays";
  }
  EXPECT_LT(ambiguous, 1500u);
}

TEST(RefereeAnalytic, AgreesWithBruteForceOnAMixedScene) { expect_brute_force_agreement(mixed_scene(), 1, true); }

TEST(RefereeAnalytic, AgreesWithBruteForceFarFromTheOrigin) {
  // EXTREMES.md's far test position, and 1e6 away: coordinates quantised in
  // float, the tiny sphere (1e-4) then smaller than a coordinate step.
  expect_brute_force_agreement(mixed_scene({148376, 1234, -223423}), 2, false);
  expect_brute_force_agreement(mixed_scene({1e6f, -1e6f, 1e6f}), 3, false);
}

TEST(RefereeAnalytic, HugeAndTinySpheres) {
  Scene s;
  s.name = "radii";
  s.spheres = {{{0, 0, 0}, 1e7f}, {{3e7f, 0, 0}, 1e-7f}, {{0, 5e7f, 0}, 1e-3f}};
  const Referee referee(s);
  // Inside the huge one: its far side, 1e7 away (an exit).
  RefereeVerdict v = referee.judge(ray_from({0, 0, 0}, {0, 0, 1}));
  EXPECT_EQ(v.prim, 0);
  EXPECT_EQ(v.t, 1e7);
  // At the tiny one from 2e7 away (outside the huge one): entering at 1e-7 before its centre.
  v = referee.judge(ray_from({1e7f + 1e6f, 0, 0}, {1, 0, 0}));
  EXPECT_EQ(v.prim, 1);
  EXPECT_NEAR(v.t, 2e7 - 1e6 - 1e-7, 1e-6);
  EXPECT_FALSE(v.ambiguous);
  // Aimed 2e-7 to the side of it: a miss (not within 1e-5 of its radius: unambiguous).
  v = referee.judge(ray_from({1.1e7f, 2e-7f, 0}, {1, 0, 0}));
  EXPECT_FALSE(v.hit());
  EXPECT_FALSE(v.ambiguous);
  // The 1e-3 sphere from 4e7 away, through its centre, from an origin on the
  // huge sphere's surface pointing out (touching it at t = 0 only: ambiguous).
  v = referee.judge(ray_from({0, 1e7f, 0}, {0, 1, 0}));
  EXPECT_EQ(v.prim, 2);
  EXPECT_NEAR(v.t, 4e7 - 1e-3, 1e-6);
  EXPECT_TRUE(v.ambiguous);
}

TEST(RefereeAnalytic, AnalyticOnlySceneAndTheReferenceBackend) {
  Scene s = mixed_scene();
  s.triangles.clear();
  const std::unique_ptr<Backend> reference = make_backend("reference");
  const Capabilities c = reference->capabilities();
  EXPECT_TRUE(c.triangles && c.spheres && c.boxes && c.oriented_boxes);
  reference->build(s);
  const std::vector<Ray> rays = {ray_from({0, 10, 0}, {0, -1, 0}), ray_from({-4.5f, 10, -4.5f}, {0, -1, 0}),
                                 ray_from({0, 10, 0}, {0, 1, 0})};
  std::vector<Hit> hits(rays.size());
  reference->intersect(rays, hits);
  EXPECT_EQ(hits[0].prim, 0);  // the outer sphere, now id 0
  EXPECT_EQ(hits[0].t, 8.0f);
  EXPECT_EQ(hits[0].u, 0.0f);
  EXPECT_EQ(hits[0].v, 0.0f);
  EXPECT_EQ(hits[1].prim, 6);  // the resting box
  EXPECT_EQ(hits[1].t, 8.0f);
  EXPECT_FALSE(hits[2].hit());
  std::vector<std::uint8_t> occluded(rays.size());
  reference->occluded(rays, occluded);
  EXPECT_EQ(occluded, (std::vector<std::uint8_t>{1, 1, 0}));
}


TEST(RefereeAnalytic, OurSurfaceTestsAgreeWithItOnEveryUnambiguousRay) {
  // The referee's semantics are the kernels' (prim/analytic_hit.h): brute
  // force with the float tests (watertight triangles, SpherePrecise, Slab,
  // Obb) answers every unambiguous ray as the referee does.
  const Scene s = mixed_scene();
  const Referee referee(s);
  const PrimitiveSpans prims = s.primitives();
  std::size_t unambiguous = 0, hit_disagree = 0, prim_disagree = 0;
  for (std::uint64_t i = 0; i < 4000; ++i) {
    Rng rng(11, 0, i);
    const auto in = [&](float lo, float hi) { return lo + static_cast<float>(rng.next_double()) * (hi - lo); };
    const double z = 2.0 * rng.next_double() - 1.0, phi = 6.283185307179586 * rng.next_double(), q = std::sqrt(1.0 - z * z);
    const Ray r = ray_from({in(-7, 7), in(-1, 6), in(-7, 7)},
                           {static_cast<float>(q * std::cos(phi)), static_cast<float>(z), static_cast<float>(q * std::sin(phi))});
    const Slab::Precomputed slab = Slab::precompute(r);
    float tmax = r.tfar;
    std::int32_t prim = kNoHit;
    for (std::size_t id = 0; id < prims.size(); ++id) {
      const std::size_t k = prims.local(id);
      float t = 0.0f;
      bool found = false;
      switch (prims.kind(id)) {
        case PrimitiveKind::kTriangle: {
          TriangleHit th;
          found = WatertightTriangle::intersect(r, tmax, s.triangles[k], th);
          t = th.t;
          break;
        }
        case PrimitiveKind::kSphere: found = intersect_sphere_surface<SpherePrecise>(r, tmax, s.spheres[k], t); break;
        case PrimitiveKind::kBox: found = intersect_box_surface<Slab>(slab, r, tmax, s.boxes[k], t); break;
        case PrimitiveKind::kOrientedBox: found = intersect_obb_surface<Obb>(r, tmax, s.obbs[k], t); break;
      }
      if (found) {
        tmax = t;
        prim = static_cast<std::int32_t>(id);
      }
    }
    const RefereeVerdict v = referee.judge(r);
    if (v.ambiguous) continue;
    ++unambiguous;
    hit_disagree += v.hit() != (prim != kNoHit);
    prim_disagree += v.hit() && prim != kNoHit && !referee.accepts(r, v, prim);
  }
  EXPECT_GT(unambiguous, 3900u);
  EXPECT_EQ(hit_disagree, 0u);
  EXPECT_EQ(prim_disagree, 0u);
}

}  // namespace
}  // namespace raybench
