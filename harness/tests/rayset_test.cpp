// Specification of ray-set generation (harness/src/rays/rayset.h).
#include "rays/rayset.h"

#include <cmath>
#include <algorithm>
#include <array>
#include <cstring>
#include <set>

#include "io/error.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "scene/scene.h"
#include "test_util.h"

namespace raybench {
namespace {

const Scene& test_scene() {
  static const Scene scene = load_scene("proc:terrain_spheres_small");
  return scene;
}

bool identical(const std::vector<Ray>& a, const std::vector<Ray>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Ray)) == 0;
}

class RaySets : public ::testing::TestWithParam<RaySetKind> {};

TEST_P(RaySets, AreDeterministicForTheSameSpecAndDifferForAnotherSeed) {
  const RayGenerator gen(test_scene());
  const RaySetSpec spec{GetParam(), 5000, 7, std::nullopt, std::nullopt};
  const std::vector<Ray> a = gen.generate(spec);
  EXPECT_EQ(a.size(), 5000u);
  EXPECT_TRUE(identical(a, RayGenerator(test_scene()).generate(spec)));
  RaySetSpec other = spec;
  other.seed = 8;
  EXPECT_FALSE(identical(a, gen.generate(other)));
  EXPECT_NE(gen.key(spec), gen.key(other));
}

INSTANTIATE_TEST_SUITE_P(AllButMustHit, RaySets,
                         ::testing::Values(RaySetKind::kPrimary, RaySetKind::kDiffuse, RaySetKind::kShadow,
                                           RaySetKind::kUniform, RaySetKind::kTinyTriangles, RaySetKind::kGrazing, RaySetKind::kDegenerateTriangles,
                                           RaySetKind::kAxisParallel, RaySetKind::kBehindOrigin, RaySetKind::kInvalid,
                                           RaySetKind::kDirectionScaling, RaySetKind::kBvhConservative,
                                           RaySetKind::kReintersection, RaySetKind::kControlRandom, RaySetKind::kFarOrigin),
                         [](const auto& info) {
                           std::string name = to_string(info.param);
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// The ordinary kinds: what a renderer would trace.
class OrdinaryRaySets : public ::testing::TestWithParam<RaySetKind> {};

TEST_P(OrdinaryRaySets, HaveUnitDirectionsAndValidIntervals) {
  const std::vector<Ray> rays = RayGenerator(test_scene()).generate({GetParam(), 3000, 1, std::nullopt, std::nullopt});
  for (const Ray& r : rays) {
    ASSERT_TRUE(is_traceable(r));
    EXPECT_NEAR(length(r.dir), 1.0f, 1e-5f);
    EXPECT_EQ(r.tnear, 0.0f);
    EXPECT_GT(r.tfar, 0.0f);
  }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, OrdinaryRaySets,
                         ::testing::Values(RaySetKind::kPrimary, RaySetKind::kDiffuse, RaySetKind::kShadow,
                                           RaySetKind::kUniform),
                         [](const auto& info) { return to_string(info.param); });

TEST(ExtremeRaySets, AxisParallelRaysHaveSignedZerosAndOriginsOnTheTargetsSlabPlanes) {
  const Scene boxes = load_scene("proc:axis_boxes");
  const std::vector<Ray> rays = RayGenerator(boxes).generate({RaySetKind::kAxisParallel, 2600, 1, std::nullopt, std::nullopt});
  std::size_t negative_zero = 0, positive_zero = 0, patterns = 0;
  std::set<std::array<int, 3>> seen;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    std::array<int, 3> pattern{};
    for (int a = 0; a < 3; ++a) {
      pattern[a] = r.dir[a] > 0 ? 1 : r.dir[a] < 0 ? -1 : 0;
      if (r.dir[a] != 0.0f) continue;
      (std::signbit(r.dir[a]) ? negative_zero : positive_zero)++;
      // Every third ray aims at a vertex of the grid: along a zero component
      // its origin then lies exactly on that vertex's (integer) slab plane.
      if (i % 3 == 0) {
        EXPECT_EQ(r.org[a], std::round(r.org[a])) << "ray " << i;
      }
    }
    ASSERT_NE(pattern, (std::array<int, 3>{0, 0, 0}));
    patterns += seen.insert(pattern).second;
  }
  EXPECT_EQ(patterns, 26u);
  EXPECT_GT(negative_zero, 1000u);
  EXPECT_GT(positive_zero, 1000u);
}

TEST(ExtremeRaySets, InvalidRaysCoverEveryCorruptionAndMostAreUntraceable) {
  const std::vector<Ray> rays = RayGenerator(test_scene()).generate({RaySetKind::kInvalid, 2400, 1, std::nullopt, std::nullopt});
  std::size_t untraceable = 0, nan_dir = 0, inf_org = 0, empty = 0, zero_dir = 0;
  for (const Ray& r : rays) {
    untraceable += !is_traceable(r);
    nan_dir += std::isnan(r.dir.x) || std::isnan(r.dir.y) || std::isnan(r.dir.z);
    inf_org += std::isinf(r.org.x) || std::isinf(r.org.y) || std::isinf(r.org.z);
    empty += r.tnear > r.tfar;
    zero_dir += r.dir.x == 0 && r.dir.y == 0 && r.dir.z == 0;
  }
  EXPECT_EQ(untraceable, 2400u * 21 / 24);  // all but the empty interval and the two zero directions
  EXPECT_EQ(nan_dir, 300u);
  EXPECT_EQ(inf_org, 600u);
  EXPECT_EQ(empty, 100u);
  EXPECT_EQ(zero_dir, 200u);
}

TEST(ExtremeRaySets, DirectionScalingCyclesThroughTwentyOrdersOfMagnitudeEachWay) {
  const std::vector<Ray> rays = RayGenerator(test_scene()).generate({RaySetKind::kDirectionScaling, 10, 1, std::nullopt, std::nullopt});
  const double expected[5] = {1e-20, 1e-7, 1, 1e7, 1e20};
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    const double l = std::sqrt(double(r.dir.x) * r.dir.x + double(r.dir.y) * r.dir.y + double(r.dir.z) * r.dir.z);
    EXPECT_NEAR(std::log10(l), std::log10(expected[i % 5]), 1e-5) << i;
  }
}

TEST(ExtremeRaySets, BehindOriginRaysPointAwayFromTheirTriangle) {
  // One triangle: every ray starts in front of it and points away, so the
  // triangle is only at negative t (G14).
  Scene one;
  one.name = "one";
  one.triangles = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  for (const Ray& r : RayGenerator(one).generate({RaySetKind::kBehindOrigin, 500, 1, std::nullopt, std::nullopt})) {
    // The plane z = 0 is crossed at t = -oz / dz, which must be negative (or never).
    if (r.dir.z != 0.0f) {
      EXPECT_LT(-r.org.z / r.dir.z, 0.0f);
    }
  }
}

TEST(ExtremeRaySets, SecondaryRaysReportTheTriangleTheyStartFrom) {
  const RayGenerator gen(test_scene());
  std::vector<std::int32_t> sources;
  const std::vector<Ray> rays = gen.generate({RaySetKind::kReintersection, 1000, 1, std::nullopt, std::nullopt}, &sources);
  ASSERT_EQ(sources.size(), rays.size());
  EXPECT_TRUE(identical(rays, gen.generate({RaySetKind::kReintersection, 1000, 1, std::nullopt, std::nullopt})));
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_GE(sources[i], 0);
    // The origin lies on the plane of its source triangle, but for the
    // offset of a few float spacings of its coordinates (up to ~100 here).
    const Triangle& t = test_scene().triangles[sources[i]];
    const Vec3f n = cross(t.v1 - t.v0, t.v2 - t.v0);
    EXPECT_LT(std::fabs(dot(n, rays[i].org - t.v0)) / length(n), 1e-2f);
  }
}

TEST(RaySets, PrimaryRaysStartAtTheNamedCamera) {
  Camera c;
  c.position = {1, 2, 3};
  c.look_at = {0, 0, 0};
  const std::vector<Ray> rays = RayGenerator(test_scene()).generate({RaySetKind::kPrimary, 100, 1, c, std::nullopt});
  for (const Ray& r : rays) {
    EXPECT_EQ(r.org.x, 1.0f);
    EXPECT_EQ(r.org.y, 2.0f);
    EXPECT_EQ(r.org.z, 3.0f);
    EXPECT_LT(dot(r.dir, normalize(Vec3f{-1, -2, -3})), 1.0f + 1e-6f);
    EXPECT_GT(dot(r.dir, normalize(Vec3f{-1, -2, -3})), std::cos(0.6f));  // within the 50-degree frustum
  }
}

TEST(RaySets, ShadowRaysEndAtTheLight) {
  const Vec3f light{5, 50, -5};
  const std::vector<Ray> rays =
      RayGenerator(test_scene()).generate({RaySetKind::kShadow, 500, 1, std::nullopt, light});
  for (const Ray& r : rays) {
    const Vec3f end = r.org + r.dir * r.tfar;
    EXPECT_NEAR(end.x, light.x, 1e-3f);
    EXPECT_NEAR(end.y, light.y, 1e-3f);
    EXPECT_NEAR(end.z, light.z, 1e-3f);
  }
}

TEST(RaySets, DiffuseRaysDoNotHitTheSurfaceTheyLeave) {
  // The offset origin (Ray Tracing Gems ch. 6) keeps secondary rays off
  // their own triangle: none hits at a distance that is mere rounding.
  const Scene& scene = test_scene();
  const Bvh2 bvh = build_bvh2_binned_sah(scene.triangles);
  std::vector<MollerTrumbore::Prepared> prepared;
  for (std::uint32_t id : bvh.prim_ids) prepared.push_back(MollerTrumbore::prepare(scene.triangles[id]));
  const std::vector<Ray> rays = RayGenerator(scene).generate({RaySetKind::kDiffuse, 5000, 3, std::nullopt, std::nullopt});
  int self_hits = 0;
  for (const Ray& r : rays) {
    const Hit h = intersect_bvh2<MollerTrumbore>(bvh, prepared, r);
    self_hits += h.hit() && h.t < 1e-4f;
  }
  EXPECT_EQ(self_hits, 0);
}

TEST(RaySets, UniformRaysStartOutsideTheScene) {
  const Scene& scene = test_scene();
  const BBox b = scene.bounds();
  for (const Ray& r : RayGenerator(scene).generate({RaySetKind::kUniform, 1000, 1, std::nullopt, std::nullopt})) {
    const bool inside = r.org.x >= b.lower.x && r.org.x <= b.upper.x && r.org.y >= b.lower.y && r.org.y <= b.upper.y &&
                        r.org.z >= b.lower.z && r.org.z <= b.upper.z;
    EXPECT_FALSE(inside);
  }
}

TEST(RaySets, ACameraThatSeesNothingIsAnErrorNotAnEndlessLoop) {
  Camera away;
  away.position = {0, 1000, 0};
  away.look_at = {0, 2000, 0};
  away.up = {1, 0, 0};
  EXPECT_THROW(RayGenerator(test_scene()).generate({RaySetKind::kDiffuse, 100, 1, away, std::nullopt}), InputError);
}

TEST(MustHitRaySets, StartInsideTheDeclaredBallAndAimAtTheMesh) {
  const Scene sphere = load_scene("proc:sphere");
  const InsideBall ball{{0, 0, 0}, 0.5f};
  const RayGenerator gen(sphere);
  for (RaySetKind kind : {RaySetKind::kClosedInsideRandom, RaySetKind::kSharedEdgeAimed, RaySetKind::kVertexAimed}) {
    EXPECT_TRUE(is_must_hit(kind));
    const std::vector<Ray> rays = gen.generate({kind, 2000, 1, std::nullopt, std::nullopt, ball});
    ASSERT_EQ(rays.size(), 2000u);
    for (const Ray& r : rays) {
      EXPECT_LE(length(r.org), 0.5f * (1 + 1e-6f));
      if (kind == RaySetKind::kClosedInsideRandom) continue;
      // Aimed at the mesh: org + dir lands on the unit sphere's surface (a vertex or an edge point).
      EXPECT_NEAR(length(r.org + r.dir), 1.0f, 0.02f);
    }
  }
  EXPECT_FALSE(is_must_hit(RaySetKind::kUniform));
}

TEST(MustHitRaySets, NeedADeclaredBall) {
  EXPECT_THROW(RayGenerator(load_scene("proc:sphere")).generate({RaySetKind::kVertexAimed, 10, 1, std::nullopt, std::nullopt}),
               InputError);
}

TEST(RaySets, KindNamesRoundTripAndUnknownNamesAreErrors) {
  for (const std::string& name : rayset_kind_names()) EXPECT_EQ(to_string(parse_rayset_kind(name)), name);
  EXPECT_THROW(parse_rayset_kind("specular"), InputError);
  EXPECT_EQ(query_of(RaySetKind::kShadow), Query::kOccluded);
  EXPECT_EQ(query_of(RaySetKind::kDiffuse), Query::kIntersect);
}

}  // namespace
}  // namespace raybench
