// Specification of the backend interface (harness/src/backend.h), for every
// backend alike: known answers, untraceable rays, threads, and names.
#include "backend.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.h"
#include "scene.h"
#include "test_util.h"
#include "trace.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Two triangles forming the unit square in z = 0, then one at z = -1.
Scene square_scene() {
  Scene s;
  s.name = "square";
  s.triangles = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, -1}, {1, 0, -1}, {0, 1, -1}}};
  return s;
}

Ray down(float x, float y, float tfar = kInf) { return Ray{{x, y, 1}, 0.0f, {0, 0, -1}, tfar}; }

// Every backend except the seed-faithful ones, whose documented failures
// (e.g. hits behind the origin) are pinned below instead.
std::vector<std::string> every_correct_backend() {
  std::vector<std::string> names;
  for (const BackendInfo& b : list_backends())
    if (b.accuracy != "epsilon") names.push_back(b.name);
  return names;
}

class EveryBackend : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    backend_ = make_backend(GetParam());
    backend_->build(scene_);
  }
  Scene scene_ = square_scene();
  std::unique_ptr<Backend> backend_;
};

TEST_P(EveryBackend, FindsTheClosestTriangleWithItsBarycentrics) {
  const std::vector<Ray> rays{down(0.75f, 0.25f), down(0.25f, 0.5f), down(2, 2)};
  std::vector<Hit> hits(rays.size());
  backend_->intersect(rays, hits);
  EXPECT_EQ(hits[0].prim, 0);
  EXPECT_FLOAT_EQ(hits[0].t, 1.0f);
  EXPECT_FLOAT_EQ(hits[0].u, 0.5f);   // p = 0.25 v0 + 0.5 v1 + 0.25 v2
  EXPECT_FLOAT_EQ(hits[0].v, 0.25f);
  EXPECT_EQ(hits[1].prim, 1);
  EXPECT_FALSE(hits[2].hit());
  EXPECT_EQ(hits[2].t, kInf);
}

TEST_P(EveryBackend, OcclusionRespectsTheInterval) {
  const std::vector<Ray> rays{down(0.75f, 0.25f), down(0.75f, 0.25f, 0.5f), down(2, 2)};
  std::vector<std::uint8_t> occ(rays.size());
  backend_->occluded(rays, occ);
  EXPECT_EQ(occ, (std::vector<std::uint8_t>{1, 0, 0}));
}

TEST_P(EveryBackend, NegativeTnearIsRaisedToZero) {
  // The origin is between the two layers; the triangle behind it must not
  // count. (0.2, 0.1) is strictly inside triangle 0, off the shared diagonal.
  Ray r{{0.2f, 0.1f, -0.5f}, -10.0f, {0, 0, 1}, kInf};
  std::vector<Hit> hits(1);
  backend_->intersect({&r, 1}, hits);
  EXPECT_EQ(hits[0].prim, 0);
  EXPECT_FLOAT_EQ(hits[0].t, 0.5f);
}

TEST_P(EveryBackend, UntraceableRaysAreMissesAndDoNotCrash) {
  // Debian's Embree asserts on these: the backend must screen them first.
  std::vector<Ray> rays;
  for (float bad : {kNaN, kInf, -kInf, 1e30f}) {
    Ray r = down(0.5f, 0.25f);
    r.org.x = bad;
    rays.push_back(r);
    r = down(0.5f, 0.25f);
    r.dir.z = bad;
    rays.push_back(r);
  }
  Ray r = down(0.5f, 0.25f);
  r.tnear = kNaN;
  rays.push_back(r);
  r = down(0.5f, 0.25f);
  r.tfar = kNaN;
  rays.push_back(r);
  r = down(0.5f, 0.25f);
  r.dir = {0, 0, 0};  // traceable, but can hit nothing
  rays.push_back(r);
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint8_t> occ(rays.size(), 7);
  backend_->intersect(rays, hits);
  backend_->occluded(rays, occ);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_FALSE(hits[i].hit()) << "ray " << i;
    EXPECT_EQ(occ[i], 0) << "ray " << i;
  }
}

TEST_P(EveryBackend, ReportsItsMemory) { EXPECT_GT(backend_->memory_bytes(), 0u); }

TEST_P(EveryBackend, TwoThreadsGiveTheSameAnswersAsOne) {
  const Scene scene = load_scene("proc:terrain_spheres_small");
  backend_->build(scene);
  std::vector<Ray> rays;
  for (int i = 0; i < 10000; ++i) {
    const float x = -90.0f + 180.0f * static_cast<float>(i % 100) / 100.0f;
    const float z = -90.0f + 180.0f * static_cast<float>(i / 100) / 100.0f;
    rays.push_back({{x, 50, z}, 0.0f, normalize(Vec3f{0.1f, -1, 0.05f}), kInf});
  }
  std::vector<Hit> one(rays.size()), two(rays.size());
  TraceExecutor(1).intersect(*backend_, rays, one);
  TraceExecutor(2).intersect(*backend_, rays, two);
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(one[i].prim, two[i].prim);
    EXPECT_EQ(one[i].t, two[i].t);
    hits += one[i].hit();
  }
  EXPECT_EQ(hits, 10000);  // straight down onto the terrain
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryBackend, ::testing::ValuesIn(every_correct_backend()), [](const auto& info) {
  std::string n = info.param;
  for (char& c : n) if (c == ':') c = '_';
  return n;
});

TEST(SeedFaithfulBackend, KnownFailure_ReportsATriangleBehindTheOrigin) {
  // A tilted triangle whose box reaches in front of the origin (so traversal
  // visits it) while the ray's line crosses it behind the origin, at
  // z = -0.8, t = -0.3. seed 002's test never checks t >= 0 and reports it.
  Scene tilted;
  tilted.triangles = {{{0, 0, -1}, {1, 0, -1}, {0, 1, 1}}};
  const Ray r{{0.1f, 0.1f, -0.5f}, 0.0f, {0, 0, 1}, kInf};
  std::vector<Hit> hits(1);
  const auto seed = make_backend("bvh2:mt_seed");
  seed->build(tilted);
  seed->intersect({&r, 1}, hits);
  EXPECT_EQ(hits[0].prim, 0);
  EXPECT_NEAR(hits[0].t, -0.3f, 1e-6f);
  const auto fixed = make_backend("bvh2:mt");
  fixed->build(tilted);
  fixed->intersect({&r, 1}, hits);
  EXPECT_FALSE(hits[0].hit());
}

TEST(RobustTraversal, WatertightThroughTheTreeNoRayLeaksFromInsideAClosedMesh) {
  // The closed sphere, rays from its centre aimed exactly at every vertex and
  // edge midpoint: the watertight test with conservative traversal lets none
  // through (the brute-force version of this is in triangle_variants_test).
  Scene sphere = load_scene("proc:sphere");
  std::vector<Ray> rays;
  for (const Triangle& t : sphere.triangles)
    for (Vec3f target : {t.v0, (t.v0 + t.v1) * 0.5f, (t.v1 + t.v2) * 0.5f, (t.v2 + t.v0) * 0.5f})
      rays.push_back({{0, 0, 0}, 0.0f, target, kInf});
  const auto backend = make_backend("bvh2:watertight:robust");
  backend->build(sphere);
  std::vector<Hit> hits(rays.size());
  backend->intersect(rays, hits);
  std::size_t leaks = 0;
  for (const Hit& h : hits) leaks += !h.hit();
  EXPECT_EQ(leaks, 0u);
}

TEST(BackendNames, EveryTriangleTestIsABvh2Backend) {
  std::vector<std::string> names;
  for (const BackendInfo& b : list_backends()) names.push_back(b.name);
  for (const char* n : {"bvh2:mt", "bvh2:mt_seed", "bvh2:watertight", "bvh2:baldwin_weber", "bvh2:mt_double",
                        "bvh2:watertight:robust"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(BackendNames, UnknownFamiliesAndOptionsAreErrorsThatSaySo) {
  const auto error_of = [](const std::string& name) { return testing::input_error_of([&] { make_backend(name); }); };
  EXPECT_NE(error_of("optix").find("unknown backend 'optix'"), std::string::npos);
  EXPECT_NE(error_of("embree:ultra").find("unknown embree option 'ultra'"), std::string::npos);
  EXPECT_NE(error_of("bvh2:magic").find("unknown triangle test 'magic'"), std::string::npos);
  EXPECT_NO_THROW(make_backend("embree:high:robust"));
  EXPECT_NO_THROW(make_backend("bvh2:robust"));  // the default triangle test, robust traversal
  EXPECT_NE(error_of("bvh2:mt:watertight").find("bvh2 takes a triangle test"), std::string::npos);
}

}  // namespace
}  // namespace raybench
