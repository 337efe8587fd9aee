// The plugin backend (backends/plugin_backend.cpp), read as its specification:
// a good plugin is a backend like any other; the in-tree bvh8 plugin traces
// exactly what the built-in bvh8 traces; every bad plugin is one line naming
// it, never a crash; the answer check names what a backend got wrong.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "backends/plugin_library.h"
#include "io/error.h"
#include "rays/screening.h"
#include "measure/agreement.h"
#include "measure/answer_check.h"
#include "measure/trace.h"
#include "rays/rayset.h"
#include "scene/scene.h"
#include "test_util.h"

namespace raybench {
namespace {

std::string test_plugin(const std::string& name) { return std::string(RAYBENCH_TEST_PLUGIN_DIR) + "/" + name + ".so"; }
std::string plugin(const std::string& name, const std::string& options = "") {
  return "plugin:" + test_plugin(name) + (options.empty() ? "" : ":" + options);
}

// The message of whatever f() throws (InputError or another std::exception),
// "" when it throws nothing.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

std::vector<Ray> rays_of(const Scene& scene, RaySetKind kind, std::size_t n) {
  return RayGenerator(scene).generate(RaySetSpec{kind, n, 7, std::nullopt, std::nullopt, std::nullopt});
}

// ---------------------------------------------------------------------------
// Names

TEST(PluginName, PathEndsAtTheFirstColonAfterASharedLibrarySuffix) {
  const auto split = [](const std::string& n) {
    const PluginName p = split_plugin_name(n);
    return p.path + "|" + p.options;
  };
  EXPECT_EQ(split("plugin:build/libmy.so"), "build/libmy.so|");
  EXPECT_EQ(split("plugin:build/libmy.so:fast"), "build/libmy.so|fast");
  EXPECT_EQ(split("plugin:build/libmy.so:a=1:b=2"), "build/libmy.so|a=1:b=2");  // options may hold ':'
  EXPECT_EQ(split("plugin:/my:dir/v1.2/k.so:x"), "/my:dir/v1.2/k.so|x");    // so may folders
  EXPECT_EQ(split("plugin:../k.dylib:x"), "../k.dylib|x");
  EXPECT_EQ(split("plugin:C:/k.dll:x"), "C:/k.dll|x");
  EXPECT_EQ(split("plugin:my.sox:y"), "my.sox:y|");  // no suffix then ':': all of it is the path
  EXPECT_EQ(split("plugin:k.so:"), "k.so|");
  EXPECT_HAS(testing::input_error_of([] { split_plugin_name("plugin:"); }), "names no library");
  EXPECT_EQ(split("plugin::x"), ":x|");  // a file named ":x", which the loader will not find
}

TEST(PluginName, IsListedAsAPlaceholderOfRaybenchBackends) {
  bool listed = false;
  for (const BackendInfo& b : list_backends())
    if (b.name == "plugin:PATH.so[:options]") listed = b.placeholder;
  EXPECT_TRUE(listed);
}

// ---------------------------------------------------------------------------
// A good plugin

TEST(GoodPlugin, IsABackendThatReportsItsOwnNameClassAndProvenance) {
  const auto backend = make_backend(plugin("good_plugin"));
  EXPECT_EQ(backend->name(), plugin("good_plugin"));
  EXPECT_EQ(backend->plugin_name(), "good_brute_force");
  EXPECT_EQ(backend->accuracy_class(), "fast");
  EXPECT_EQ(backend_accuracy_class(plugin("good_plugin")), "fast");
  std::map<std::string, std::string> p;
  for (const auto& [k, v] : backend->provenance()) p[k] = v;
  EXPECT_EQ(p["path"], std::filesystem::canonical(test_plugin("good_plugin")).string());
  EXPECT_EQ(p["sha256"], sha256_of_file(test_plugin("good_plugin")));
  EXPECT_EQ(p["sha256"].size(), 64u);
  EXPECT_EQ(p["name"], "good_brute_force");
  EXPECT_HAS(p["description"], "every ray against every triangle");
  EXPECT_EQ(p["abi_version"], "1");
  EXPECT_EQ(p["options"], "");
}

TEST(GoodPlugin, IsLoadedOncePerFileHoweverItIsNamed) {
  const PluginLibrary& a = load_plugin_library(test_plugin("good_plugin"), "a");
  const std::string relative =
      std::filesystem::relative(test_plugin("good_plugin"), std::filesystem::current_path()).string();
  const PluginLibrary& b = load_plugin_library(relative, "b");
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(a.table, b.table);
}

TEST(GoodPlugin, AgreesWithEmbreeAndBvh2OnEveryRayKind) {
  const Scene scene = load_scene("proc:sphere");
  std::vector<std::unique_ptr<Backend>> backends;
  for (const std::string& name : {std::string("embree"), std::string("bvh2"), plugin("good_plugin")}) {
    backends.push_back(make_backend(name, {2}));
    TraceExecutor(2).run([&] { backends.back()->build(scene); });
  }
  EXPECT_GT(backends[2]->memory_bytes(), scene.triangles.size() * sizeof(Triangle));
  for (RaySetKind kind : {RaySetKind::kPrimary, RaySetKind::kDiffuse, RaySetKind::kUniform}) {
    const std::vector<Ray> rays = rays_of(scene, kind, 3000);
    std::vector<std::vector<Hit>> hits(3, std::vector<Hit>(rays.size()));
    for (int b = 0; b < 3; ++b) TraceExecutor(2).intersect(*backends[b], rays, hits[b]);
    EXPECT_FALSE(check_hits(hits[2], scene.triangles.size()).any());
    for (int b = 0; b < 2; ++b) {
      const Agreement a = compare_hits(hits[2], hits[b], rays, scene.triangles);
      EXPECT_GE(a.agree_hit(), 0.9999) << to_string(kind) << " against " << backends[b]->name();
      EXPECT_GE(a.agree_prim(), 0.999) << to_string(kind) << " against " << backends[b]->name();
      if (kind == RaySetKind::kPrimary) {
        EXPECT_GT(a.hits, 0u);
      }
    }
  }
  const std::vector<Ray> shadow = rays_of(scene, RaySetKind::kShadow, 3000);
  std::vector<std::uint8_t> mine(shadow.size()), embree(shadow.size());
  TraceExecutor(2).occluded(*backends[2], shadow, mine);
  TraceExecutor(2).occluded(*backends[0], shadow, embree);
  EXPECT_GE(compare_occlusion(mine, embree).agree_hit(), 0.9999);
}

TEST(GoodPlugin, RefusesOptionsWhenMadeWithItsOwnMessage) {
  const std::string e = testing::input_error_of([] { make_backend(plugin("good_plugin", "fsat")); });
  EXPECT_HAS(e, "options 'fsat' refused");
  EXPECT_HAS(e, "good_plugin takes no options, not 'fsat'");
  EXPECT_HAS(e, "good_plugin.so");
}

// ---------------------------------------------------------------------------
// The in-tree plugin wrapping bvh8

TEST(Bvh8Plugin, TracesBitIdenticalHitsToTheBuiltInBvh8) {
  const Scene scene = load_scene("proc:terrain_spheres_small");
  const auto builtin = make_backend("bvh8", {2});
  const auto wrapped = make_backend(std::string("plugin:") + RAYBENCH_BVH8_PLUGIN, {2});
  EXPECT_EQ(wrapped->plugin_name(), "bvh8_plugin");
  EXPECT_EQ(wrapped->accuracy_class(), builtin->accuracy_class());
  const TraceExecutor executor(2);
  executor.run([&] { builtin->build(scene); });
  executor.run([&] { wrapped->build(scene); });
  EXPECT_EQ(wrapped->memory_bytes(), builtin->memory_bytes());
  for (RaySetKind kind : {RaySetKind::kPrimary, RaySetKind::kDiffuse, RaySetKind::kUniform, RaySetKind::kGrazing}) {
    std::vector<Ray> rays = rays_of(scene, kind, 20000);
    // and the rays every backend must survive: NaN, infinite, negative tnear
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    rays.push_back({{0, 50, 0}, -5.0f, {0, -1, 0}, inf});
    rays.push_back({{nan, 50, 0}, 0.0f, {0, -1, 0}, inf});
    rays.push_back({{0, 50, 0}, 0.0f, {0, -inf, 0}, inf});
    std::vector<Hit> a(rays.size()), b(rays.size());
    executor.intersect(*builtin, rays, a);
    executor.intersect(*wrapped, rays, b);
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Hit)), 0) << to_string(kind);
    std::vector<std::uint8_t> oa(rays.size()), ob(rays.size());
    executor.occluded(*builtin, rays, oa);
    executor.occluded(*wrapped, rays, ob);
    EXPECT_EQ(oa, ob) << to_string(kind);
  }
}

TEST(Bvh8Plugin, TakesNoOptions) {
  EXPECT_HAS(testing::input_error_of([] { make_backend(std::string("plugin:") + RAYBENCH_BVH8_PLUGIN + ":sbvh"); }),
             "raybench_bvh8_plugin takes no options (got 'sbvh')");
}

// ---------------------------------------------------------------------------
// Bad plugins: one line each, naming the plugin

TEST(BadPlugin, APathThatDoesNotExist) {
  const std::string e = testing::input_error_of([] { make_backend("plugin:/no/such/kernel.so:fast"); });
  EXPECT_HAS(e, "/no/such/kernel.so: backend 'plugin:/no/such/kernel.so:fast': plugin library not found");
}

TEST(BadPlugin, AFileThatIsNotASharedLibrary) {
  const std::string e = testing::input_error_of([] { make_backend(std::string("plugin:") + RAYBENCH_NOT_A_LIBRARY); });
  EXPECT_HAS(e, "not_a_library.so");
  EXPECT_HAS(e, "not a loadable shared library (");  // dlerror's own words follow
  EXPECT_EQ(e.find('\n'), std::string::npos);
  const std::string folder = testing::input_error_of([] { make_backend("plugin:" + std::string(RAYBENCH_TEST_PLUGIN_DIR)); });
  EXPECT_HAS(folder, "a folder, not a plugin library");
}

TEST(BadPlugin, ALibraryWithoutTheEntryPoint) {
  EXPECT_HAS(testing::input_error_of([] { make_backend(plugin("bad_no_entry_plugin")); }),
             "bad_no_entry_plugin.so: backend 'plugin:" + test_plugin("bad_no_entry_plugin") +
                 "': the library has no entry point 'raybench_plugin'");
}

TEST(BadPlugin, AWrongAbiVersionNamesBoth) {
  EXPECT_HAS(testing::input_error_of([] { make_backend(plugin("bad_wrong_abi_plugin")); }),
             "built for plugin ABI version 2, this raybench speaks version 1");
}

TEST(BadPlugin, ATableWithoutANameOrAFunction) {
  EXPECT_HAS(testing::input_error_of([] { make_backend(plugin("bad_null_name_plugin")); }),
             "the plugin's table lacks name (NULL or empty");
  EXPECT_HAS(testing::input_error_of([] { make_backend(plugin("bad_no_intersect_plugin")); }),
             "the plugin's table lacks intersect (NULL or empty");
}

TEST(BadPlugin, AnUnknownAccuracyClass) {
  EXPECT_HAS(testing::input_error_of([] { make_backend(plugin("bad_class_plugin")); }),
             "the plugin reports accuracy class 'approximate'; it must be one of fast, epsilon, watertight, exact");
}

TEST(BadPlugin, ABuildThatFailsNamesTheSceneAndSaysWhy) {
  const auto backend = make_backend(plugin("bad_build_fails_plugin"));
  const Scene scene = load_scene("proc:sphere");
  const std::string e = testing::input_error_of([&] { backend->build(scene); });
  EXPECT_HAS(e, "(bad_plugin): build failed on scene 'sphere': cannot build 2208 triangles (a test plugin that fails)");
  EXPECT_EQ(backend->memory_bytes(), 0u);
  // With after=N it builds scenes of up to N triangles.
  EXPECT_NO_THROW(make_backend(plugin("bad_build_fails_plugin", "after=5000"))->build(scene));
}

TEST(BadPlugin, AThrowingPluginIsCaughtAtTheBoundaryEvenInsideTbb) {
  const Scene scene = load_scene("proc:sphere");
  const std::vector<Ray> rays = rays_of(scene, RaySetKind::kPrimary, 5000);
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint8_t> occ(rays.size());
  const auto build_throws = make_backend(plugin("throwing_plugin", "build"));
  EXPECT_HAS(error_of([&] { TraceExecutor(2).run([&] { build_throws->build(scene); }); }),
             "(throwing_plugin): build threw an exception: throwing_plugin: build throws, as asked on scene 'sphere'");
  const auto intersect_throws = make_backend(plugin("throwing_plugin", "intersect"), {2});
  intersect_throws->build(scene);
  EXPECT_HAS(error_of([&] { TraceExecutor(2).intersect(*intersect_throws, rays, hits); }),
             "intersect threw an exception: throwing_plugin: intersect throws, as asked on scene 'sphere'");
  const auto occluded_throws = make_backend(plugin("throwing_plugin", "occluded"), {2});
  occluded_throws->build(scene);
  EXPECT_HAS(error_of([&] { TraceExecutor(2).occluded(*occluded_throws, rays, occ); }),
             "(throwing_plugin): occluded threw an exception on scene 'sphere'");
}

TEST(BadPlugin, ATraceThatReturnsAnErrorNamesTheCall) {
  const Scene scene = load_scene("proc:sphere");
  const std::vector<Ray> rays = rays_of(scene, RaySetKind::kPrimary, 100);
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint8_t> occ(rays.size());
  const auto backend = make_backend(plugin("bad_trace_error_plugin"));
  backend->build(scene);
  EXPECT_HAS(error_of([&] { backend->intersect(rays, hits); }), "intersect returned error 7 on scene 'sphere'");
  EXPECT_HAS(error_of([&] { backend->occluded(rays, occ); }), "occluded returned error 7 on scene 'sphere'");
}

// ---------------------------------------------------------------------------
// The answer check (measure/answer_check.h), for any backend

TEST(AnswerCheck, CountsEachKindOfImpossibleAnswer) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<Hit> hits{{1.0f, 0, 0, 0},  {inf, kNoHit, 0, 0}, {1.0f, 1000, 0, 0}, {1.0f, -2, 0, 0},
                              {nan, 3, 0, 0},   {nan, kNoHit, 0, 0}, {inf, 4, 0, 0},     {2.0f, 999, 0, 0}};
  const AnswerProblems p = check_hits(hits, 1000);
  EXPECT_EQ(p.prim_outside, 2u);
  EXPECT_EQ(p.nan_t, 2u);
  EXPECT_EQ(p.infinite_hit, 1u);
  EXPECT_EQ(p.describe(), "2 of 8 rays with prim outside [0, 1000), 2 with NaN t and 1 with a hit at infinite t");
  EXPECT_FALSE(check_hits({hits.data(), 2}, 1000).any());
  EXPECT_EQ(check_hits({hits.data(), 2}, 1000).describe(), "");
  const std::vector<std::uint8_t> occ{0, 1, 2, 255};
  EXPECT_EQ(check_occlusion(occ).describe(), "2 of 4 rays with an occlusion flag other than 0 or 1");
}

TEST(AnswerCheck, NamesThePluginItsNameAndWhere) {
  const Scene scene = load_scene("proc:sphere");
  const std::vector<Ray> rays = rays_of(scene, RaySetKind::kPrimary, 2000);
  std::vector<Hit> hits(rays.size());
  for (const char* name : {"bad_prims_plugin", "bad_nan_t_plugin", "bad_inf_hit_plugin"}) {
    const auto backend = make_backend(plugin(name));
    backend->build(scene);
    TraceExecutor(1).intersect(*backend, rays, hits);
    const std::size_t hit = std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.prim != kNoHit; });
    ASSERT_GT(hit, 0u);
    const std::string e = error_of([&] { require_valid_hits(*backend, hits, scene.triangles.size(), "sphere/primary"); });
    EXPECT_HAS(e, "backend '" + plugin(name) + "' (bad_plugin) returned " + std::to_string(hit) + " of 2000 rays with ");
    EXPECT_HAS(e, " on sphere/primary");
    const std::string expected = std::string(name) == "bad_prims_plugin" ? "prim outside [0, 2208)"
                                 : std::string(name) == "bad_nan_t_plugin" ? "NaN t"
                                                                           : "a hit at infinite t";
    EXPECT_HAS(e, expected);
  }
}

// The check holds every built-in backend to the same rules: none breaks them.
TEST(AnswerCheck, EveryBuiltInBackendPassesIt) {
  const Scene scene = load_scene("proc:terrain_spheres_small");
  std::vector<Ray> rays = rays_of(scene, RaySetKind::kUniform, 2000);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  rays.push_back({{nan, 0, 0}, 0.0f, {0, -1, 0}, inf});
  rays.push_back({{0, 50, 0}, 0.0f, {0, -1, 0}, nan});
  const ScreenedRays screened = screen_rays(rays);
  for (const BackendInfo& b : list_backends()) {
    if (b.placeholder) continue;
    const auto backend = make_backend(b.name);
    backend->build(scene);
    std::vector<Hit> hits(rays.size());
    std::vector<std::uint8_t> occ(rays.size());
    backend->intersect(screened.rays, hits);  // screened, as every caller hands rays over (backend.h)
    backend->occluded(screened.rays, occ);
    EXPECT_EQ(check_hits(hits, scene.triangles.size()).describe(), "") << b.name;
    EXPECT_EQ(check_occlusion(occ).describe(), "") << b.name;
  }
}

// A prim outside the scene never indexes the triangles in the tie check.
TEST(AnswerCheck, AgreementNeverIndexesPastTheScene) {
  const Scene scene = load_scene("proc:sphere");
  const std::vector<Ray> rays(2, Ray{{0, 0, -5}, 0.0f, {0, 0, 1}, 100.0f});
  const std::vector<Hit> ref{{4.0f, 0, 0, 0}, {4.0f, 1, 0, 0}};
  const std::vector<Hit> bad{{4.0f, 1 << 30, 0, 0}, {4.5f, -7, 0, 0}};
  const Agreement a = compare_hits(bad, ref, rays, scene.triangles);
  EXPECT_EQ(a.same_prim, 0u);
}

TEST(Sha256, KnownAnswers) {
  EXPECT_EQ(sha256_hex("", 0), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc", 3), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(sha256_hex(two_blocks.data(), two_blocks.size()),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  const std::string million(1000000, 'a');
  EXPECT_EQ(sha256_hex(million.data(), million.size()),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

}  // namespace
}  // namespace raybench
