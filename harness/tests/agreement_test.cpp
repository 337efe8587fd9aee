// Specification of per-ray agreement (harness/src/measure/agreement.h).
#include "measure/agreement.h"

#include <vector>

#include <gtest/gtest.h>

namespace raybench {
namespace {

const Hit kMiss{};

TEST(Agreement, CountsHitMissPrimAndTiesPerRay) {
  const std::vector<Hit> reference{{1.0f, 7, 0, 0}, {2.0f, 3, 0, 0}, kMiss, {4.0f, 1, 0, 0}, {5.0f, 9, 0, 0}};
  const std::vector<Hit> tested{{1.0f, 7, 0, 0},   // same
                                {2.0f, 4, 0, 0},   // another triangle at the same t: a tie
                                {3.0f, 2, 0, 0},   // hit where the reference misses
                                kMiss,             // miss where the reference hits
                                {5.5f, 8, 0, 0}};  // another triangle, farther
  const Agreement a = compare_hits(tested, reference);
  EXPECT_EQ(a.rays, 5u);
  EXPECT_DOUBLE_EQ(a.hit_rate(), 4.0 / 5);
  EXPECT_DOUBLE_EQ(a.agree_hit(), 3.0 / 5);
  EXPECT_EQ(a.both_hit, 3u);
  EXPECT_DOUBLE_EQ(a.agree_prim(), 1.0 / 3);
  EXPECT_EQ(a.prim_ties, 1u);
  EXPECT_EQ(a.disagreements(), 2u + 2u);
  EXPECT_DOUBLE_EQ(a.t_relerr_max, 0.1);  // |5.5 - 5| / 5
  EXPECT_DOUBLE_EQ(a.t_relerr_p999, 0.1);
}

TEST(Agreement, GivenTheGeometryCoincidentTrianglesAtDifferentFloatDistancesTie) {
  // Triangles 0 and 1 lie in the plane z = 0 (1 a copy of 0), triangle 2
  // in z = -1. Both tracers hit the plane at t = 1, but round it apart.
  const std::vector<Triangle> triangles{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                        {{0, 0, -1}, {1, 0, -1}, {0, 1, -1}}};
  const std::vector<Ray> rays(2, Ray{{0.25f, 0.25f, 1}, 0, {0, 0, -1}});
  const std::vector<Hit> reference{{1.0f, 0, 0, 0}, {1.0f, 0, 0, 0}};
  const std::vector<Hit> tested{{0x1.000002p+0f, 1, 0, 0},  // the copy, one ulp off: a tie
                                {2.0f, 2, 0, 0}};           // the plane behind: an error
  const Agreement with_geometry = compare_hits(tested, reference, rays, triangles);
  EXPECT_EQ(with_geometry.prim_ties, 1u);
  EXPECT_EQ(with_geometry.same_prim, 0u);
  // Without it, only equal floats tie.
  EXPECT_EQ(compare_hits(tested, reference).prim_ties, 0u);
  // A ray in the planes' direction crosses neither once: no tie, whatever the floats.
  const std::vector<Ray> grazing(2, Ray{{0.25f, 0.25f, 0}, 0, {1, 0, 0}});
  EXPECT_EQ(compare_hits(tested, reference, grazing, triangles).prim_ties, 0u);
  // A triangle index outside the scene (a backend's bug) is no tie, and no crash.
  const std::vector<Hit> out_of_scene{{0x1.000002p+0f, 3, 0, 0}, {2.0f, 2, 0, 0}};
  EXPECT_EQ(compare_hits(out_of_scene, reference, rays, triangles).prim_ties, 0u);
}

TEST(Agreement, AnAnalyticPrimitiveTiesWhereTheRefereeTiesIt) {
  // Ids: the floor triangle 0 (z = 0), a sphere 1 resting on the box's top
  // (z from 1 to 2), the box 2 resting on the floor ([0, 1]^3).
  const std::vector<Triangle> triangles{{{-5, -5, 0}, {5, -5, 0}, {0, 5, 0}}};
  const std::vector<Sphere> spheres{{{0.25f, 0.25f, 1.5f}, 0.5f}};
  const std::vector<BBox> boxes{{{0, 0, 0}, {1, 1, 1}}};
  const PrimitiveSpans prims{triangles, spheres, boxes, {}};
  const Ray up{{0.25f, 0.25f, -1}, 0, {0, 0, 1}};            // floor and box bottom at t = 1, sphere at t = 2
  const Ray from_inside{{0.25f, 0.25f, 0.5f}, 0, {0, 0, 1}};  // box exit and sphere bottom at t = 0.5
  const std::vector<Ray> rays{up, from_inside, up};
  const std::vector<Hit> reference{{1.0f, 0, 0, 0}, {0.5f, 2, 0, 0}, {1.0f, 0, 0, 0}};
  const std::vector<Hit> tested{{0x1.000002p+0f, 2, 0, 0},   // the box, one float ulp off: a tie
                                {0x1.000002p-1f, 1, 0, 0},   // the sphere touching the box: a tie
                                {2.0f, 1, 0, 0}};            // the sphere, farther: no tie
  const Agreement a = compare_hits(tested, reference, rays, prims);
  EXPECT_EQ(a.both_hit, 3u);
  EXPECT_EQ(a.same_prim, 0u);
  EXPECT_EQ(a.prim_ties, 2u);
  // Given only the triangles, analytic ids are outside the scene: no exact ties.
  EXPECT_EQ(compare_hits(tested, reference, rays, triangles).prim_ties, 0u);
}

TEST(Agreement, PercentileIgnoresTheRareOutlier) {
  std::vector<Hit> reference(2000, Hit{1.0f, 0, 0, 0}), tested = reference;
  tested[5].t = 2.0f;  // one ray in 2000: above the 99.9th percentile
  const Agreement a = compare_hits(tested, reference);
  EXPECT_DOUBLE_EQ(a.t_relerr_max, 1.0);
  EXPECT_DOUBLE_EQ(a.t_relerr_p999, 0.0);
}

TEST(Agreement, IdenticalAnswersAgreeCompletely) {
  const std::vector<Hit> hits{{1.0f, 1, 0.5f, 0.25f}, kMiss};
  const Agreement a = compare_hits(hits, hits);
  EXPECT_DOUBLE_EQ(a.agree_hit(), 1.0);
  EXPECT_DOUBLE_EQ(a.agree_prim(), 1.0);
  EXPECT_EQ(a.disagreements(), 0u);
}

TEST(Agreement, OcclusionComparesFlagsOnly) {
  const std::vector<std::uint8_t> reference{1, 0, 1, 0}, tested{1, 1, 0, 0};
  const Agreement a = compare_occlusion(tested, reference);
  EXPECT_FALSE(a.has_prims);
  EXPECT_DOUBLE_EQ(a.hit_rate(), 0.5);
  EXPECT_DOUBLE_EQ(a.agree_hit(), 0.5);
  EXPECT_EQ(a.disagreements(), 2u);
}

}  // namespace
}  // namespace raybench
