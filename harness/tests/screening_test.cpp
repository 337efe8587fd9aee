// Specification of screening (harness/src/rays/screening.h): what every
// backend is given to trace, and that screening changes no built-in
// backend's answer on any ray set, the extreme ones included.
#include "rays/screening.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "rays/rayset.h"
#include "scene/scene.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

bool same_bits(const Ray& a, const Ray& b) { return std::memcmp(&a, &b, sizeof(Ray)) == 0; }

Ray good() { return Ray{{0.5f, 0.25f, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, kInf}; }

TEST(Screening, EveryKindOfUntraceableRayBecomesTheEmptyRay) {
  std::vector<Ray> rays;
  for (const float bad : {kNaN, kInf, -kInf, 2e18f, -1e30f}) {  // NaN, Inf, beyond Embree's 1.844e18
    for (int axis = 0; axis < 3; ++axis) {
      Ray o = good();
      o.org[axis] = bad;
      rays.push_back(o);
      Ray d = good();
      d.dir[axis] = bad;
      rays.push_back(d);
    }
  }
  Ray r = good();
  r.tnear = kNaN;
  rays.push_back(r);
  r = good();
  r.tfar = kNaN;
  rays.push_back(r);
  const ScreenedRays s = screen_rays(rays);
  ASSERT_EQ(s.rays.size(), rays.size());
  ASSERT_EQ(s.screened.size(), rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(s.screened[i], i);
    EXPECT_TRUE(same_bits(s.rays[i], kEmptyRay)) << "ray " << i;
  }
  EXPECT_EQ(s.raised_tnear, 0u);
}

TEST(Screening, TheEmptyRayIsOriginZeroDirectionXAndTheEmptyIntervalFromOneToZero) {
  EXPECT_EQ(kEmptyRay.org.x, 0.0f);
  EXPECT_EQ(kEmptyRay.org.y, 0.0f);
  EXPECT_EQ(kEmptyRay.org.z, 0.0f);
  EXPECT_EQ(kEmptyRay.dir.x, 1.0f);
  EXPECT_EQ(kEmptyRay.dir.y, 0.0f);
  EXPECT_EQ(kEmptyRay.dir.z, 0.0f);
  EXPECT_EQ(kEmptyRay.tnear, 1.0f);
  EXPECT_EQ(kEmptyRay.tfar, 0.0f);
  EXPECT_TRUE(is_traceable(kEmptyRay));
}

TEST(Screening, ANegativeTnearBecomesZeroAndEveryOtherTraceableRayIsKeptBitForBit) {
  std::vector<Ray> rays(7, good());
  rays[0].tnear = -1.0f;
  rays[1].tnear = -kInf;
  rays[2].tnear = -0.0f;   // not negative, but written as +0 like every tnear <= 0
  rays[3].tnear = 2.0f;
  rays[4].tnear = kInf;    // traceable; its interval is empty
  rays[5].tfar = -3.0f;    // traceable; its interval is empty
  rays[6].dir = {0, 0, 0};  // traceable; it can hit nothing
  const ScreenedRays s = screen_rays(rays);
  EXPECT_TRUE(s.screened.empty());
  EXPECT_EQ(s.raised_tnear, 2u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(s.rays[i].tnear, 0.0f) << "ray " << i;
    EXPECT_FALSE(std::signbit(s.rays[i].tnear)) << "ray " << i;
    Ray expected = rays[i];
    expected.tnear = 0.0f;
    EXPECT_TRUE(same_bits(s.rays[i], expected)) << "ray " << i;
  }
  for (std::size_t i = 3; i < rays.size(); ++i) EXPECT_TRUE(same_bits(s.rays[i], rays[i])) << "ray " << i;
}

TEST(Screening, TheAnswersOfScreenedRaysAreForcedToMissesAndNoOtherAnswerChanges) {
  std::vector<Ray> rays(4, good());
  rays[1].org.y = kNaN;
  rays[3].tfar = kNaN;
  const ScreenedRays s = screen_rays(rays);
  // Whatever a backend answered, even a hit for the empty ray:
  const Hit some_hit{0.5f, 7, 0.25f, 0.25f};
  std::vector<Hit> hits(rays.size(), some_hit);
  std::vector<std::uint8_t> occluded(rays.size(), 1);
  force_misses(s, hits);
  force_misses(s, occluded);
  for (const std::size_t i : {1u, 3u}) {
    EXPECT_FALSE(hits[i].hit());
    EXPECT_EQ(hits[i].t, kInf);
    EXPECT_EQ(hits[i].prim, kNoHit);
    EXPECT_EQ(occluded[i], 0);
  }
  for (const std::size_t i : {0u, 2u}) {
    EXPECT_EQ(hits[i].prim, 7);
    EXPECT_EQ(hits[i].t, 0.5f);
    EXPECT_EQ(occluded[i], 1);
  }
  std::vector<Hit> wrong_size(2);
  EXPECT_THROW(force_misses(s, wrong_size), std::logic_error);
}

// Screening is outside the backends: every built-in backend answers the
// screened-out rays (kEmptyRay) as misses itself, on every ray set that needs
// no inside ball, the extreme ones (NaN and Inf, behind the origin,
// axis-parallel, huge and tiny directions, far origins) included. Backends
// trace screened rays only (backend.h: Embree aborts on NaN, Inf and a
// negative tnear; our timed loops trace each ray as given, doing no more
// per-ray work than Embree's); our own are also handed the rays as stored,
// which must not crash them (the sanitized build checks that), whatever
// they answer.
class EveryBuiltInBackend : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryBuiltInBackend, AnswersTheScreenedOutRaysAsMisses) {
  const Scene scene = load_scene("proc:sphere");
  const auto backend = make_backend(GetParam());
  backend->build(scene);
  const RayGenerator generator(scene);
  int untraceable = 0;
  for (const std::string& name : rayset_kind_names()) {
    const RaySetKind kind = parse_rayset_kind(name);
    if (is_must_hit(kind)) continue;
    const std::vector<Ray> rays = generator.generate(RaySetSpec{kind, 600, 7, std::nullopt, std::nullopt, std::nullopt});
    const ScreenedRays s = screen_rays(rays);
    untraceable += static_cast<int>(s.screened.size());
    std::vector<Hit> screened(rays.size());
    std::vector<std::uint8_t> screened_occ(rays.size());
    backend->intersect(s.rays, screened);
    backend->occluded(s.rays, screened_occ);
    for (const std::size_t i : s.screened) {
      ASSERT_FALSE(screened[i].hit() || screened_occ[i]) << name << " ray " << i << ", screened out";
    }
    if (GetParam().rfind("embree", 0) == 0) continue;  // screened rays only
    std::vector<Hit> stored(rays.size());
    std::vector<std::uint8_t> stored_occ(rays.size());
    backend->intersect(rays, stored);
    backend->occluded(rays, stored_occ);
  }
  EXPECT_GT(untraceable, 0) << "the invalid ray set (G15) has NaN and Inf rays";
}

std::vector<std::string> built_in_backends() {
  std::vector<std::string> names;
  for (const BackendInfo& b : list_backends())
    if (!b.placeholder) names.push_back(b.name);  // not "plugin:PATH.so[:options]"
  return names;
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryBuiltInBackend, ::testing::ValuesIn(built_in_backends()),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n) if (c == ':') c = '_';
                           return n;
                         });

}  // namespace
}  // namespace raybench
