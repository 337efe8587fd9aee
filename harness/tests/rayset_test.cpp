// Specification of ray-set generation (harness/src/rayset.h).
#include "rayset.h"

#include <cmath>
#include <cstring>

#include "error.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "scene.h"
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

TEST_P(RaySets, HaveUnitDirectionsAndValidIntervals) {
  const std::vector<Ray> rays = RayGenerator(test_scene()).generate({GetParam(), 3000, 1, std::nullopt, std::nullopt});
  for (const Ray& r : rays) {
    ASSERT_TRUE(is_traceable(r));
    EXPECT_NEAR(length(r.dir), 1.0f, 1e-5f);
    EXPECT_EQ(r.tnear, 0.0f);
    EXPECT_GT(r.tfar, 0.0f);
  }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, RaySets,
                         ::testing::Values(RaySetKind::kPrimary, RaySetKind::kDiffuse, RaySetKind::kShadow,
                                           RaySetKind::kUniform),
                         [](const auto& info) { return to_string(info.param); });

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
