// The exact referee, specified by hand-worked cases (every expected answer
// below follows from exact arithmetic on the given floats) and by the
// properties the accuracy report relies on: it never leaks through a closed
// mesh, and the BVH never hides a candidate from it.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "scene/random.h"
#include "rays/rayset.h"
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

}  // namespace
}  // namespace raybench
