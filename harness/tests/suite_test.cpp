// Specification of suite manifests (harness/src/suite/suite.h).
#include "suite/suite.h"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>
#include <sys/stat.h>

#include "build_info.h"
#include "io/error.h"
#include "io/npy.h"
#include "raybench/variants.h"
#include "suite/results_table.h"
#include "suite/scene_selection.h"
#include "suite/settings_rules.h"
#include "suite/suite_run.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::TempDir;

std::string error_of(const std::string& path) {
  return testing::input_error_of([&] { load_suite(path); });
}

TEST(Suite, TheDefaultSuiteParsesAndIncludesTheMillionTriangleProceduralScene) {
  const Suite s = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/default.toml");
  ASSERT_NE(s.find("terrain_spheres"), nullptr);
  EXPECT_TRUE(s.find("terrain_spheres")->available());
  for (const char* interior : {"sponza", "conference", "sibenik", "sponza_dabrovic"}) {
    ASSERT_NE(s.find(interior), nullptr) << interior;
    EXPECT_TRUE(s.find(interior)->camera.has_value()) << interior << " needs its camera inside";
  }
  EXPECT_EQ(s.settings.backends, (std::vector<std::string>{"embree", "bvh2", "bvh8"}));
}

TEST(Suite, PathsAreResolvedAgainstTheManifestsFolder) {
  TempDir dir;
  const auto path = dir.write("s.toml", "[[scene]]\nname = \"m\"\npath = \"sub/m.obj\"\n");
  EXPECT_EQ(load_suite(path).scenes[0].path, dir.file("sub/m.obj"));
}

TEST(Suite, CamerasAndLightsAreRead) {
  TempDir dir;
  const auto path = dir.write("s.toml",
                              "[defaults]\nrays = 1000\nthreads = [1, 2]\n"
                              "[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n"
                              "camera = { position = [0, 0, 5], look_at = [0, 0, 0], fov = 40 }\nlight = [1, 2, 3]\n");
  const Suite s = load_suite(path);
  EXPECT_EQ(s.settings.rays, 1000u);
  EXPECT_EQ(s.settings.threads, (std::vector<int>{1, 2}));
  ASSERT_TRUE(s.scenes[0].camera);
  EXPECT_EQ(s.scenes[0].camera->position.z, 5.0f);
  EXPECT_EQ(s.scenes[0].camera->fov_degrees, 40.0f);
  EXPECT_EQ(s.scenes[0].light->y, 2.0f);
}

TEST(Suite, AClosedSceneDeclaresItsInsideBallAndItsOwnRaySets) {
  TempDir dir;
  const auto path = dir.write("s.toml",
                              "[[scene]]\nname = \"ball\"\npath = \"proc:sphere\"\n"
                              "inside = { center = [0, 0, 0], radius = 0.5 }\nraysets = [\"vertex-aimed\"]\n");
  const Suite s = load_suite(path);
  ASSERT_TRUE(s.scenes[0].inside);
  EXPECT_EQ(s.scenes[0].inside->radius, 0.5f);
  EXPECT_EQ(s.scenes[0].raysets, (std::vector<std::string>{"vertex-aimed"}));
  const Suite defaults = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/default.toml");
  ASSERT_NE(defaults.find("sphere"), nullptr);
  EXPECT_TRUE(defaults.find("sphere")->inside.has_value());
}

TEST(Suite, ASweepMakesOneSceneperScaleAndOffsetThatFloatCanRepresent) {
  TempDir dir;
  const auto path = dir.write("s.toml",
                              "[[scene]]\nname = \"ball\"\npath = \"proc:sphere\"\n"
                              "inside = { center = [0, 0, 0], radius = 0.5 }\n"
                              "sweep = { scales = [1e-3, 1.0, 1e4], offsets = [[0, 0, 0], [1e7, 0, 0]] }\n");
  const Suite s = load_suite(path);
  // At 1e7 floats are 1 apart: only the 1e4 scale keeps its shape there.
  std::vector<std::string> names;
  for (const SuiteScene& e : s.scenes) names.push_back(e.name);
  EXPECT_EQ(names, (std::vector<std::string>{"ball@s0.001", "ball@s1", "ball@s10000", "ball@s10000@o1e+07_0_0"}));
  const SuiteScene& far = s.scenes.back();
  EXPECT_EQ(far.scale, 1e4);
  EXPECT_EQ(far.offset[0], 1e7);
  ASSERT_TRUE(far.inside);
  EXPECT_EQ(far.inside->center.x, 1e7f);
  EXPECT_EQ(far.inside->radius, 5000.0f);
  const Scene scene = load_suite_scene(far);
  EXPECT_EQ(scene.name, far.name);
  EXPECT_NEAR(scene.bounds().center().x, 1e7f, 1.0f);
  EXPECT_NEAR(scene.bounds().extent().y, 2e4f, 1.0f);
}

TEST(Suite, AScaleAndOffsetMoveTheSceneAndItsCamera) {
  TempDir dir;
  const auto path = dir.write("s.toml",
                              "[[scene]]\nname = \"b\"\npath = \"proc:sphere\"\nscale = 2.0\noffset = [10, 0, 0]\n"
                              "camera = { position = [0, 0, 5], look_at = [0, 0, 0] }\n");
  const Suite s = load_suite(path);
  EXPECT_TRUE(s.scenes[0].transformed());
  EXPECT_EQ(s.scenes[0].camera->position.x, 10.0f);
  EXPECT_EQ(s.scenes[0].camera->position.z, 10.0f);
  EXPECT_NEAR(load_suite_scene(s.scenes[0]).bounds().upper.x, 12.0f, 1e-5f);
}

TEST(Suite, TheAccuracySuiteSweepsFromAMillionthToAMillionUnits) {
  const Suite s = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/accuracy.toml");
  ASSERT_NE(s.find("sphere@s1e-06"), nullptr);
  ASSERT_NE(s.find("sphere@s1e+06@o1e+07_1e+07_1e+07"), nullptr);
  ASSERT_NE(s.find("sphere"), nullptr);
  EXPECT_NE(std::find(s.settings.backends.begin(), s.settings.backends.end(), "reference"), s.settings.backends.end());
  EXPECT_NE(std::find(s.settings.backends.begin(), s.settings.backends.end(), "embree:robust"), s.settings.backends.end());
}

// meshes/accuracy.toml names "bvh2:*", not the triangle tests one by one:
// every test in raybench/variants.h is judged, one added tomorrow too.
TEST(Suite, TheAccuracySuiteJudgesBvh2WithEveryTriangleTest) {
  const Suite s = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/accuracy.toml");
  const std::vector<std::string>& b = s.settings.backends;
  std::size_t variants = 0;
  for_each_variant<TriangleTests>([&](auto test) {
    const std::string name = "bvh2:" + std::string(decltype(test)::name);
    EXPECT_EQ(std::count(b.begin(), b.end(), name), 1) << name;
    ++variants;
  });
  EXPECT_EQ(variants, std::tuple_size_v<TriangleTests>);
  EXPECT_EQ(std::count(b.begin(), b.end(), "bvh2:*"), 0);  // expanded when read
}

TEST(Suite, MistakesNameTheFileAndTheKey) {
  TempDir dir;
  const struct {
    const char* text;
    const char* problem;
  } cases[] = {
      {"[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\ncolour = 1\n", "scene[0].colour': unknown key"},
      {"[defaults]\nrays = \"many\"\n[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n", "defaults.rays"},
      {"[defaults]\nraysets = [\"specular\"]\n[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n", "specular"},
      {"[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n[[scene]]\nname = \"a\"\npath = \"x.obj\"\n", "duplicate"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\ncamera = { position = [0, 0] , look_at = [0,0,0] }\n", "camera.position"},
      {"[[scene]]\nname = \"a\"\n", "needs a name and a path"},
      {"[defaults\n", "line 1"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\ninside = { center = [0, 0, 0], radius = 0 }\n", "inside.radius"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\ninside = { radius = 1 }\n", "scene[0].inside"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\nraysets = [\"edge\"]\n", "scene[0].raysets"},
      {"[defaults]\n", "no [[scene]]"},
      {"[defaults]\nbackends = [\"bvh8:*\"]\n[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n",
       "defaults.backends': backend pattern 'bvh8:*'"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\nscale = -1\n", "scene[0].scale"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\nsweep = { scales = [] }\n", "scene[0].sweep.scales"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\nsweep = { scales = [1.0], offsets = [[1, 2]] }\n", "sweep.offsets"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const auto path = dir.write("bad" + std::to_string(i++) + ".toml", c.text);
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << "expected '" << c.problem << "' in: " << error;
  }
}

// Issue 31: the tessellation study's resolutions, for every scene or one.
TEST(Suite, TessellateIsReadFromTheDefaultsAndEachSceneAndSweepCopiesKeepIt) {
  TempDir dir;
  const Suite suite = load_suite(dir.write("t.toml", R"(
[defaults]
tessellate = ["8x4", "32x16"]
[[scene]]
name = "inherits"
path = "proc:sphere"
[[scene]]
name = "own"
path = "proc:sphere"
tessellate = ["256x128"]
[[scene]]
name = "none"
path = "proc:sphere"
tessellate = []
[[scene]]
name = "swept"
path = "proc:sphere"
tessellate = ["16x8"]
sweep = { scales = [1.0, 2.0] }
)"));
  EXPECT_EQ(suite.settings.tessellate, (std::vector<Tessellation>{{8, 4}, {32, 16}}));
  EXPECT_FALSE(suite.find("inherits")->tessellate.has_value()) << "unset: the defaults apply";
  EXPECT_EQ(*suite.find("own")->tessellate, (std::vector<Tessellation>{{256, 128}}));
  EXPECT_TRUE(suite.find("none")->tessellate->empty());
  EXPECT_EQ(*suite.find("swept@s2")->tessellate, (std::vector<Tessellation>{{16, 8}}));
  EXPECT_TRUE(load_suite(dir.write("d.toml", "[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n")).settings.tessellate.empty())
      << "no stand-ins unless asked for";
  const struct {
    const char* text;
    const char* problem;
  } cases[] = {
      {"[defaults]\ntessellate = [\"16\"]\n[[scene]]\nname = \"a\"\npath = \"p\"\n",
       "'defaults.tessellate': must be SxR"},
      {"[defaults]\ntessellate = \"8x4\"\n[[scene]]\nname = \"a\"\npath = \"p\"\n",
       "'defaults.tessellate': expected an array of strings"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\ntessellate = [\"8x4\", \"2x2\"]\n", "'scene[0].tessellate': must be SxR"},
      {"[[scene]]\nname = \"a\"\npath = \"p\"\ntessellate = [\"8x4\", \"8x4\"]\n",
       "'scene[0].tessellate': 8x4 is given twice"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const auto path = dir.write("bad" + std::to_string(i++) + ".toml", c.text);
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ": " + c.problem), std::string::npos) << "expected '" << c.problem << "' in: " << error;
  }
}

// Issue 28: a manifest's numbers were not validated as the command line's
// were (threads = 3000000000 wrapped to a negative count, min_time = 0 or NaN
// aborted inside Google Benchmark, warmup = inf warmed up forever), and the
// run-time check blamed a flag that was not given ("--reps must be at least 1").
TEST(Suite, NumericSettingsAreRefusedNamingTheFileAndKeyNeverAFlag) {
  TempDir dir;
  const struct {
    const char* defaults;
    const char* key;
  } cases[] = {
      {"threads = [3000000000]", "'defaults.threads'"},
      {"threads = [1, 0]", "'defaults.threads'"},
      {"threads = [-2]", "'defaults.threads'"},
      {"min_time = 0", "'defaults.min_time'"},
      {"min_time = -1.0", "'defaults.min_time'"},
      {"min_time = nan", "'defaults.min_time'"},
      {"min_time = inf", "'defaults.min_time'"},
      {"warmup = -1.0", "'defaults.warmup'"},
      {"warmup = nan", "'defaults.warmup'"},
      {"warmup = inf", "'defaults.warmup'"},
      {"repetitions = 0", "'defaults.repetitions'"},
      {"repetitions = 3000000000", "'defaults.repetitions'"},
      {"build_repetitions = 0", "'defaults.build_repetitions'"},
      {"rays = 0", "'defaults.rays'"},
      {"rays = -5", "'defaults.rays'"},
      {"rays = 1e5", "'defaults.rays'"},
      {"rays = \"many\"", "'defaults.rays'"},
      {"seed = -1", "'defaults.seed'"},
      {"huge_pages = \"yes\"", "'defaults.huge_pages'"},
      {"huge_pages = true", "'defaults.huge_pages'"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const auto path = dir.write("bad" + std::to_string(i++) + ".toml",
                                std::string("[defaults]\n") + c.defaults + "\n[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n");
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ": " + c.key + ": must be"), std::string::npos) << c.defaults << ": " << error;
    EXPECT_EQ(error.find("--"), std::string::npos) << c.defaults << ": " << error;
  }
}

TEST(Suite, NumericSettingsWithinTheRulesAreRead) {
  TempDir dir;
  const auto path = dir.write("s.toml",
                              "[defaults]\nrays = 268435456\nthreads = [1, 1024]\nrepetitions = 1000\nbuild_repetitions = 1\n"
                              "seed = 0\nmin_time = 3600\nwarmup = 0\n[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n");
  const SuiteSettings s = load_suite(path).settings;
  EXPECT_EQ(s.rays, 268435456u);
  EXPECT_EQ(s.threads, (std::vector<int>{1, 1024}));
  EXPECT_EQ(s.repetitions, 1000);
  EXPECT_EQ(s.build_repetitions, 1);
  EXPECT_EQ(s.seed, 0u);
  EXPECT_EQ(s.min_time, 3600.0);
  EXPECT_EQ(s.warmup, 0.0);
}

// The memory policy is on unless the manifest says "off" ([defaults]
// huge_pages; --huge-pages overrides it).
TEST(Suite, TheMemoryPolicyIsHugePagesUnlessTheDefaultsSayOff) {
  TempDir dir;
  const std::string scene = "[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n";
  EXPECT_TRUE(load_suite(dir.write("none.toml", scene)).settings.huge_pages);
  EXPECT_TRUE(load_suite(dir.write("on.toml", "[defaults]\nhuge_pages = \"on\"\n" + scene)).settings.huge_pages);
  EXPECT_FALSE(load_suite(dir.write("off.toml", "[defaults]\nhuge_pages = \"off\"\n" + scene)).settings.huge_pages);
}

// A camera at NaN, at its own look-at point, or with `up` along the view
// direction made all-NaN rays and a "successful" run (issue 28).
TEST(Suite, ACameraLightAndBallMustBeFiniteAndACameraMustLookSomewhere) {
  TempDir dir;
  const std::string scene = "[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n";
  const struct {
    const char* text;
    const char* key;
    const char* problem;
  } cases[] = {
      {"camera = { position = [nan, 0, 0], look_at = [0, 0, 0] }", "scene[0].camera.position", "finite"},
      {"camera = { position = [0, inf, 5], look_at = [0, 0, 0] }", "scene[0].camera.position", "finite"},
      {"camera = { position = [0, 0, 5], look_at = [0, 0, -inf] }", "scene[0].camera.look_at", "finite"},
      {"camera = { position = [0, 0, 5], look_at = [0, 0, 0], up = [0, nan, 0] }", "scene[0].camera.up", "finite"},
      {"camera = { position = [0, 0, 1e39], look_at = [0, 0, 0] }", "scene[0].camera.position", "finite"},
      {"camera = { position = [0, 0, 1e19], look_at = [0, 0, 0] }", "scene[0].camera.position", "within"},
      {"camera = { position = [1, 2, 3], look_at = [1, 2, 3] }", "scene[0].camera.look_at", "looks nowhere"},
      {"camera = { position = [0, 5, 0], look_at = [0, 0, 0] }", "scene[0].camera.up", "parallel"},
      {"camera = { position = [0, 0, 5], look_at = [0, 0, 0], up = [0, 0, -2] }", "scene[0].camera.up", "parallel"},
      {"camera = { position = [0, 0, 5], look_at = [0, 0, 0], up = [0, 0, 0] }", "scene[0].camera.up", "[0, 0, 0]"},
      {"camera = { position = [0, 0, 5], look_at = [0, 0, 0], fov = nan }", "scene[0].camera.fov", "(0, 180)"},
      // float(1e7 + 1e-3) == float(1e7): the offset merges the camera with its target.
      {"camera = { position = [0, 0, 1e-3], look_at = [0, 0, 0] }\noffset = [0, 0, 1e7]", "scene[0].camera.look_at",
       "offset"},
      {"light = [nan, 0, 0]", "scene[0].light", "finite"},
      {"light = [0, inf, 0]", "scene[0].light", "finite"},
      {"inside = { center = [0, nan, 0], radius = 0.5 }", "scene[0].inside.center", "finite"},
      {"inside = { center = [0, 0, 0], radius = inf }", "scene[0].inside.radius", "finite"},
      {"inside = { center = [0, 0, 0], radius = nan }", "scene[0].inside.radius", "> 0"},
      {"sweep = { scales = [inf] }", "scene[0].sweep.scales", "finite"},
      {"sweep = { scales = [1.0], max_quantisation = nan }", "scene[0].sweep.max_quantisation", "finite"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const auto path = dir.write("cam" + std::to_string(i++) + ".toml", scene + c.text + "\n");
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ": '" + c.key + "'"), std::string::npos) << c.text << ": " << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << c.text << ": " << error;
  }
}

// A scene's name goes into ray file names under --rays-dir and into the
// results CSV: "../evil" wrote outside --rays-dir, a newline made a CSV
// raybench could not read back (issue 28).
TEST(Suite, SceneNamesThatWouldEscapeTheRaysDirOrBreakTheCsvAreRefused) {
  TempDir dir;
  int i = 0;
  for (const char* name : {"../evil", "a/b", "/abs", "a\\\\b", "a\\nb", "a\\rb", "tab\\there", "a\\u007fb", "a,b"}) {
    const auto path =
        dir.write("name" + std::to_string(i++) + ".toml", fmt::format("[[scene]]\nname = \"{}\"\npath = \"proc:sphere\"\n", name));
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ": 'scene[0].name': a scene name must not contain"), std::string::npos) << name << ": " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << name << ": the message must stay one line";
  }
  const auto fine = dir.write("fine.toml", "[[scene]]\nname = \"Sponza v2 (crytek)@s1e-06\"\npath = \"proc:sphere\"\n");
  EXPECT_EQ(load_suite(fine).scenes[0].name, "Sponza v2 (crytek)@s1e-06");
}

TEST(Suite, AManifestThatIsNotARegularFileIsRefusedWithoutOpeningIt) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("folder.toml"));
  EXPECT_NE(error_of(dir.file("folder.toml")).find("is a directory"), std::string::npos);
  ASSERT_EQ(::mkfifo(dir.file("fifo.toml").c_str(), 0600), 0);
  EXPECT_NE(error_of(dir.file("fifo.toml")).find("is a FIFO"), std::string::npos);  // would block forever on open
  EXPECT_NE(error_of(dir.file("absent.toml")).find("no such file"), std::string::npos);
}

// The rules themselves (settings_rules.h), as the command line feeds them.
GivenValue flag(const std::string& text) { return GivenValue::from_flag("--x", text); }
template <typename Rule>
std::string refusal(Rule rule, const std::string& text) {
  return testing::input_error_of([&] { rule(flag(text)); });
}

TEST(SettingsRules, IntegersAreWholeDecimalNumbersWithinTheirRange) {
  EXPECT_EQ(rays_setting(flag("1")), 1u);
  EXPECT_EQ(rays_setting(flag("268435456")), 268435456u);
  EXPECT_EQ(threads_setting(flag("1024")), 1024);
  EXPECT_EQ(pairs_setting(flag("8")), 8u);
  for (const char* bad : {"0", "-5", "268435457", "99999999999999999999999", "1e5", "1.0", "", " 1", "1 ", "0x10", "abc", "nan"})
    EXPECT_EQ(refusal(rays_setting, bad), fmt::format("--x: must be an integer from 1 to 268435456, got {}",
                                                      *bad ? bad : "nothing"));
  EXPECT_EQ(refusal(threads_setting, "3000000000"), "--x: must be an integer from 1 to 1024, got 3000000000");
  EXPECT_EQ(refusal(pairs_setting, "-1"), "--x: must be an integer from 8 to 16777216, got -1");
  EXPECT_EQ(refusal(repetitions_setting, "0"), "--x: must be an integer from 1 to 1000, got 0");
  EXPECT_EQ(refusal(build_repetitions_setting, "1001"), "--x: must be an integer from 1 to 1000, got 1001");
  EXPECT_EQ(refusal(kernel_rays_setting, "16777217"), "--x: must be an integer from 1 to 16777216, got 16777217");
}

TEST(SettingsRules, SeedsTakeEveryUnsigned64BitValue) {
  EXPECT_EQ(seed_setting(flag("0")), 0u);
  EXPECT_EQ(seed_setting(flag("18446744073709551615")), 18446744073709551615u);
  for (const char* bad : {"-1", "18446744073709551616", "1.5", "x"})
    EXPECT_NE(refusal(seed_setting, bad).find("must be an integer from 0 to 18446744073709551615"), std::string::npos) << bad;
}

TEST(SettingsRules, SecondsAreFiniteAndNeverTheAbortsOfGoogleBenchmark) {
  EXPECT_EQ(min_time_setting(flag("0.01")), 0.01);
  EXPECT_EQ(min_time_setting(flag("3600")), 3600.0);
  EXPECT_EQ(warmup_setting(flag("0")), 0.0);
  for (const char* bad : {"0", "-1", "nan", "inf", "-inf", "3601", "1e309", "soon"})
    EXPECT_EQ(refusal(min_time_setting, bad), std::string("--x: must be a finite number of seconds in (0, 3600], got ") + bad);
  for (const char* bad : {"-1", "-0.001", "nan", "inf", "3601"})
    EXPECT_EQ(refusal(warmup_setting, bad), std::string("--x: must be a finite number of seconds in [0, 3600], got ") + bad);
  EXPECT_EQ(refusal(alpha_setting, "nan"), "--x: must be a significance level in (0, 1), got nan");
  EXPECT_EQ(refusal(alpha_setting, "1"), "--x: must be a significance level in (0, 1), got 1");
  EXPECT_EQ(refusal(min_effect_setting, "-1"), "--x: must be a relative change in [0, 10], got -1");
}

TEST(SettingsRules, AManifestValueIsNamedByItsFileAndKey) {
  const GivenValue v = GivenValue::from_manifest("m.toml", "defaults.threads", "3000000000", 3000000000, 3e9);
  EXPECT_EQ(testing::input_error_of([&] { threads_setting(v); }),
            "m.toml: 'defaults.threads': must be an integer from 1 to 1024, got 3000000000");
}

TEST(SettingsRules, SceneNames) {
  EXPECT_EQ(scene_name_problem("sponza_dabrovic"), "");
  EXPECT_EQ(scene_name_problem("sphere@s1e+06@o1e+07_1e+07_1e+07"), "");
  for (const char* bad : {"", "../x", "a/b", "a\\b", "a\nb", "a\x01", "a\x7f", "a,b"})
    EXPECT_NE(scene_name_problem(bad), "") << bad;
  EXPECT_EQ(printable("a\nb\x7f"), "a\\x0ab\\x7f");
}


// --- Scene selection (suite/scene_selection.h): one name per scene in a run.

std::string selection_error(const std::vector<std::string>& args, const Suite& suite) {
  return testing::input_error_of([&] { choose_scenes(args, suite); });
}

TEST(Suite, ASceneGivenByNameAndAPathWithTheSameStemIsRefusedNamingBoth) {
  TempDir dir;
  const Suite suite = load_suite(dir.write("s.toml", "[[scene]]\nname = \"spider\"\npath = \"proc:sphere\"\n"));
  const std::string mesh = dir.write("spider.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(selection_error({"spider", mesh}, suite),
            fmt::format("--scene: spider and {0} both name the scene 'spider' (their rows and ray files would collide): "
                        "name one of them, e.g. --scene spider_2={0}", mesh));
  EXPECT_EQ(selection_error({"spider", "spider"}, suite),
            "--scene: spider and spider both name the scene 'spider' (their rows and ray files would collide): "
            "give each scene once");
}

TEST(Suite, APathSceneCanBeNamedOnTheCommandLine) {
  TempDir dir;
  const Suite suite = load_suite(dir.write("s.toml", "[[scene]]\nname = \"spider\"\npath = \"proc:sphere\"\n"));
  const std::string mesh = dir.write("spider.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::vector<SceneChoice> chosen = choose_scenes({"spider", "big_spider=" + mesh, "ball=proc:sphere"}, suite);
  ASSERT_EQ(chosen.size(), 3u);
  EXPECT_EQ(chosen[0].name, "spider");
  EXPECT_NE(chosen[0].entry, nullptr);
  EXPECT_EQ(chosen[1].name, "big_spider");
  EXPECT_EQ(chosen[1].path, mesh);
  EXPECT_EQ(chosen[1].entry, nullptr);
  EXPECT_EQ(load_chosen_scene(chosen[1]).name, "big_spider");
  EXPECT_EQ(load_chosen_scene(chosen[2]).name, "ball");
  // A file whose name holds '=' is a path, not NAME=PATH.
  const std::string odd = dir.write("a=b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(choose_scene(odd, suite).name, "a=b");
  EXPECT_EQ(choose_scene(odd, suite).path, odd);
}

TEST(Suite, ANameGivenOnTheCommandLineObeysTheSceneNameRule) {
  const Suite suite;
  EXPECT_EQ(selection_error({"bad\nname=proc:sphere"}, suite),
            "--scene: bad\\x0aname=proc:sphere is read as NAME=PATH (no file has that name), but the name "
            "'bad\\x0aname' is refused: a scene name must not contain control characters (found 0x0a): it is a field "
            "of the results CSV");
  EXPECT_EQ(selection_error({"ball="}, suite), "--scene: ball=: NAME=PATH names no path");
  EXPECT_EQ(selection_error({"ball=proc:sphere", "ball=proc:terrain_spheres_small"}, suite),
            "--scene: ball=proc:sphere and ball=proc:terrain_spheres_small both name the scene 'ball' (their rows and "
            "ray files would collide): name one of them, e.g. --scene ball_2=proc:terrain_spheres_small");
}

// --- Analytic primitives (issue 31): spheres, boxes, obbs = "FILE.npy".

// A float64 .npy of the given rows under `dir`.
std::string primitive_file(const TempDir& dir, const std::string& name, const std::vector<double>& values,
                           std::size_t columns) {
  std::filesystem::create_directories(std::filesystem::path(dir.file(name)).parent_path());
  write_npy_f64(dir.file(name), values, values.size() / columns, columns);
  return dir.file(name);
}

const std::vector<double> kOneObb{5, 0, 0, 0, 0, 1, 0, 1, 0, -1, 0, 0, 1, 2, 3};  // axes (z, y, -x)

TEST(Suite, PrimitiveFilesAreResolvedAgainstTheManifestAndFollowTheMeshInPrimIds) {
  TempDir dir;
  primitive_file(dir, "prims/s.npy", {0, 0, 0, 1, 3, 0, 0, 0.5}, 4);
  primitive_file(dir, "prims/b.npy", {0, 0, 0, 1, 1, 1}, 6);
  primitive_file(dir, "prims/o.npy", kOneObb, 15);
  const Suite s = load_suite(dir.write("s.toml", "[[scene]]\nname = \"mix\"\npath = \"proc:sphere\"\n"
                                                 "spheres = \"prims/s.npy\"\nboxes = \"prims/b.npy\"\n"
                                                 "obbs = \"prims/o.npy\"\n"
                                                 "[[scene]]\nname = \"balls\"\nspheres = \"prims/s.npy\"\n"));
  const SuiteScene& mix = s.scenes[0];
  EXPECT_EQ(mix.spheres, dir.file("prims/s.npy"));
  EXPECT_EQ(mix.boxes, dir.file("prims/b.npy"));
  EXPECT_EQ(mix.obbs, dir.file("prims/o.npy"));
  EXPECT_TRUE(mix.available());
  EXPECT_EQ(mix.sources(), fmt::format("proc:sphere + spheres {} + boxes {} + obbs {}", mix.spheres, mix.boxes, mix.obbs));
  const Scene scene = load_suite_scene(mix);
  EXPECT_EQ(scene.name, "mix");
  EXPECT_EQ(scene.triangles.size(), 2208u);  // proc:sphere's
  ASSERT_EQ(scene.spheres.size(), 2u);
  EXPECT_EQ(scene.spheres[1].center.x, 3.0f);
  ASSERT_EQ(scene.boxes.size(), 1u);
  ASSERT_EQ(scene.obbs.size(), 1u);
  EXPECT_EQ(scene.obbs[0].axis[2].x, -1.0f);
  const PrimitiveSpans all = scene.primitives();
  EXPECT_EQ(all.kind(2208), PrimitiveKind::kSphere);
  EXPECT_EQ(all.kind(2210), PrimitiveKind::kBox);
  EXPECT_EQ(all.kind(2211), PrimitiveKind::kOrientedBox);
  EXPECT_EQ(describe_primitives(scene), "2208 triangles, 2 spheres, 1 box, 1 oriented box");
  // A scene of primitive files alone: no path, no triangles.
  const Scene balls = load_suite_scene(s.scenes[1]);
  EXPECT_EQ(balls.triangles.size(), 0u);
  EXPECT_EQ(balls.spheres.size(), 2u);
  EXPECT_EQ(s.scenes[1].path, "");
  EXPECT_EQ(s.scenes[1].sources(), "spheres " + dir.file("prims/s.npy"));
}

TEST(Suite, AScaleAndOffsetMoveAnalyticPrimitivesAndScaleTheirSizes) {
  TempDir dir;
  primitive_file(dir, "s.npy", {1, 2, 3, 0.5}, 4);
  primitive_file(dir, "b.npy", {-1, -1, -1, 1, 2, 3}, 6);
  primitive_file(dir, "o.npy", kOneObb, 15);
  const Suite s = load_suite(dir.write("s.toml", "[[scene]]\nname = \"m\"\nspheres = \"s.npy\"\nboxes = \"b.npy\"\n"
                                                 "obbs = \"o.npy\"\nscale = 2.0\noffset = [10, 0, -1]\n"));
  const Scene scene = load_suite_scene(s.scenes[0]);
  EXPECT_EQ(scene.spheres[0].center.x, 12.0f);
  EXPECT_EQ(scene.spheres[0].center.z, 5.0f);
  EXPECT_EQ(scene.spheres[0].radius, 1.0f);
  EXPECT_EQ(scene.boxes[0].lower.x, 8.0f);
  EXPECT_EQ(scene.boxes[0].upper.z, 5.0f);
  EXPECT_EQ(scene.obbs[0].center.x, 20.0f);
  EXPECT_EQ(scene.obbs[0].half_extent.z, 6.0f);
  EXPECT_EQ(scene.obbs[0].axis[0].z, 1.0f);  // axes are directions: kept
}

TEST(Suite, AnAnalyticPrimitiveMovedBeyondTheCoordinateLimitIsRefusedNamingTheSceneAndThePrimitive) {
  TempDir dir;
  primitive_file(dir, "s.npy", {0, 0, 0, 1, 0, 0, 0, 4}, 4);
  const Suite s = load_suite(dir.write("s.toml", "[[scene]]\nname = \"m\"\nspheres = \"s.npy\"\nscale = 3e17\n"));
  const std::string error = testing::input_error_of([&] { load_suite_scene(s.scenes[0]); });
  EXPECT_NE(error.find("scene 'm' (spheres " + dir.file("s.npy") + " with the manifest's scale and offset): sphere 1 "
                       "(prim 1) reaches a coordinate of -1.2e+18"), std::string::npos) << error;
}

TEST(Suite, AMalformedPrimitiveFileIsRefusedWhenTheSceneLoadsNamingTheFileAndTheRow) {
  TempDir dir;
  const std::string file = primitive_file(dir, "s.npy", {0, 0, 0, 1, 0, 0, 0, -2}, 4);
  const Suite s = load_suite(dir.write("s.toml", "[[scene]]\nname = \"m\"\npath = \"proc:sphere\"\nspheres = \"s.npy\"\n"));
  EXPECT_EQ(testing::input_error_of([&] { load_suite_scene(s.scenes[0]); }), file + ": row 1: radius is -2: it must be >= 0");
}

TEST(Suite, ASceneOfEmptyPrimitiveFilesHoldsNothingToTraceAndIsRefused) {
  TempDir dir;
  primitive_file(dir, "s.npy", {}, 4);
  const Suite s = load_suite(dir.write("s.toml", "[[scene]]\nname = \"m\"\nspheres = \"s.npy\"\n"));
  EXPECT_EQ(testing::input_error_of([&] { load_suite_scene(s.scenes[0]); }),
            "scene 'm' (spheres " + dir.file("s.npy") + "): holds no primitives (its files have 0 rows): nothing to trace");
}

TEST(Suite, AMissingPrimitiveFileMakesTheSceneUnavailableAndIsNamed) {
  TempDir dir;
  primitive_file(dir, "s.npy", {0, 0, 0, 1}, 4);
  const Suite s = load_suite(dir.write("s.toml", "[[scene]]\nname = \"m\"\npath = \"proc:sphere\"\nspheres = \"s.npy\"\n"
                                                 "boxes = \"absent.npy\"\noptional = true\n"));
  EXPECT_FALSE(s.scenes[0].available());
  EXPECT_EQ(s.scenes[0].missing(), dir.file("absent.npy"));
}

TEST(Suite, PrimitiveKeysAreStringsNamingNpyFiles) {
  TempDir dir;
  const struct {
    const char* text;
    const char* problem;
  } cases[] = {
      {"[[scene]]\nname = \"a\"\nspheres = 3\n", "'scene[0].spheres': expected a string"},
      {"[[scene]]\nname = \"a\"\nboxes = \"\"\n", "'scene[0].boxes': is empty"},
      {"[[scene]]\nname = \"a\"\nobbs = \"proc:sphere\"\n",
       "'scene[0].obbs': 'proc:sphere' is a procedural scene's name; obbs names a .npy file"},
      {"[[scene]]\nname = \"a\"\ncones = \"c.npy\"\n", "'scene[0].cones': unknown key"},
      {"[[scene]]\nname = \"a\"\n", "needs a name and a path (a mesh or proc:<name>), or analytic primitives"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const auto path = dir.write("bad" + std::to_string(i++) + ".toml", c.text);
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << "expected '" << c.problem << "' in: " << error;
  }
}

// Issue 31: "The default suite and the accuracy suite include an analytic scene."
TEST(Suite, TheDefaultProceduralAndAccuracySuitesIncludeAnalyticScenes) {
  const auto analytic = [](const char* manifest, const char* name) {
    const Suite s = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/" + manifest);
    const SuiteScene* entry = s.find(name);
    return entry && entry->available() && load_suite_scene(*entry).has_analytic();
  };
  EXPECT_TRUE(analytic("default.toml", "terrain_spheres_analytic"));
  EXPECT_TRUE(analytic("procedural.toml", "terrain_spheres_analytic"));
  EXPECT_TRUE(analytic("procedural.toml", "terrain_spheres_analytic_small"));
  EXPECT_TRUE(analytic("accuracy.toml", "analytic_mix"));
  EXPECT_TRUE(analytic("accuracy.toml", "sphere_field"));
  // The tessellated terrain stays beside its analytic twin, for comparison.
  EXPECT_FALSE(analytic("default.toml", "terrain_spheres"));
}

// A camera or light inside a sphere would see (or be shadowed by) its inside only.
TEST(Suite, TheAnalyticScenesCamerasAndLightsStandOutsideEveryPrimitive) {
  const Suite s = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/accuracy.toml");
  const SuiteScene* entry = s.find("sphere_field");
  ASSERT_TRUE(entry && entry->camera && entry->light);
  for (const Sphere& b : load_suite_scene(*entry).spheres) {
    EXPECT_GT(length(entry->camera->position - b.center), b.radius);
    EXPECT_GT(length(*entry->light - b.center), b.radius);
  }
  // The mix's camera and light stand above all of it.
  const SuiteScene* mix = s.find("analytic_mix");
  ASSERT_TRUE(mix && mix->camera && mix->light);
  const float top = load_suite_scene(*mix).bounds().upper.y;
  EXPECT_GT(mix->camera->position.y, top);
  EXPECT_GT(mix->light->y, top);
}

// --- The results table (suite/results_table.h).

ResultRow timed_row(double min, double median, double max) {
  ResultRow r;
  r.scene = "bunny";
  r.triangles = 100;
  r.rayset = "primary";
  r.query = "intersect";
  r.rays = 1000;
  r.backend = "bvh2";
  r.mrays_s_min = min;
  r.mrays_s = median;
  r.mrays_s_max = max;
  r.ratio_to_embree = 0.5;
  r.hit_rate = 0.9;
  r.agree_hit = 1.0;
  r.agree_prim = 1.0;
  return r;
}

TEST(Suite, TheTableMarksARowWhoseRepetitionsSpreadWidelyAndSaysWhatItMeans) {
  const std::string table = format_results_table({timed_row(10.0, 14.0, 15.5)});
  EXPECT_NE(table.find("[10.00 - 15.50]!"), std::string::npos) << table;
  EXPECT_NE(table.find("! repetitions spread widely (fastest / slowest > 1.5)"), std::string::npos) << table;
}

TEST(Suite, ARowWithinTheSpreadLimitGetsNoMarkAndNoNote) {
  for (const ResultRow& row : {timed_row(10.0, 12.0, 15.0), timed_row(0.0, 0.0, 0.0)}) {
    const std::string table = format_results_table({row});
    EXPECT_EQ(table.find('!'), std::string::npos) << table;
    EXPECT_EQ(table.find("spread"), std::string::npos) << table;
  }
}

TEST(Suite, TheTableWarnsWhenACameraSeesLittleOfItsScene) {
  const CameraCoverage little{"bunny", 0.087, "scripts/preview_camera bunny --suite s.toml"};
  EXPECT_EQ(camera_warning(little), "camera sees little of the scene: 8.7 % of primary rays hit; check it with "
                                    "scripts/preview_camera bunny --suite s.toml");
  const std::string table = format_results_table({timed_row(10, 11, 12)}, {little});
  EXPECT_NE(table.find("  warning: " + camera_warning(little)), std::string::npos) << table;
  EXPECT_EQ(format_results_table({timed_row(10, 11, 12)}, {{"bunny", 0.25, "x"}}).find("warning"), std::string::npos);
  EXPECT_EQ(format_results_table({timed_row(10, 11, 12)}, {{"other", 0.0, "x"}}).find("warning"), std::string::npos);
}

TEST(Suite, TheAccuracyTableShowsTheRefereesVerdictsAsRayCounts) {
  const AccuracyRow r{.scene = "tiny", .rayset = "diffuse", .query = "intersect", .backend = "bvh2:mt_seed",
                      .accuracy_class = "epsilon", .rays = 2000, .truth_hits = 0.5, .false_miss = 0.25,
                      .false_hit = 0.001, .wrong_prim = 0.0015, .self_hits = 0.002, .ulp_p50 = 0.5, .ulp_max = 1024};
  AccuracyRow occlusion = r;
  occlusion.rayset = "shadow";
  occlusion.query = "occluded";
  occlusion.self_hits = occlusion.ulp_p50 = occlusion.ulp_max = NAN;
  const std::string table = format_accuracy_table({r, occlusion});
  EXPECT_NE(table.find("tiny: the exact referee's verdicts (rays)"), std::string::npos) << table;
  const auto line_of = [&](const std::string& start) {
    const std::size_t at = table.find(start);
    return at == std::string::npos ? std::string() : table.substr(at, table.find('\n', at) - at);
  };
  EXPECT_EQ(line_of("  rayset"), "  rayset  backend      class      rays    hits  ambig  f_miss  f_hit  wrong   self  "
                                 "ulp p50  ulp max");
  EXPECT_EQ(line_of("  diffuse"), "  diffuse bvh2:mt_seed epsilon    2000    1000      0     500      2      3      4  "
                                  "    0.5     1024");
  EXPECT_EQ(line_of("  shadow"), "  shadow  bvh2:mt_seed epsilon    2000    1000      0     500      2      -      -  "
                                 "      -        -");
  for (const std::string& line : {line_of("  rayset"), line_of("  diffuse")}) EXPECT_LE(line.size(), 100u);
}

TEST(Suite, TheTimingReferenceIsReadFromTheDefaultsAndRecordsWhereItWasGiven) {
  TempDir dir;
  const std::string scene = "[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n";
  const Suite s =
      load_suite(dir.write("s.toml", "[defaults]\nbackends = [\"embree\", \"bvh2\"]\nreference = \"bvh2\"\n" + scene));
  EXPECT_EQ(s.settings.reference, "bvh2");
  EXPECT_EQ(s.settings.reference_given, dir.file("s.toml") + ": 'defaults.reference'");
  EXPECT_EQ(timing_reference(s.settings), "bvh2");
  EXPECT_EQ(load_suite(dir.write("t.toml", "[defaults]\nrays = 10\n" + scene)).settings.reference, "");
}

TEST(Suite, AManifestsTimingReferenceMustBeOneNameAndOneOfTheRunsBackends) {
  TempDir dir;
  const auto path = [&](const std::string& reference) {
    return dir.write("s.toml", "[defaults]\nbackends = [\"embree\", \"bvh2\"]\nreference = " + reference +
                                   "\n[[scene]]\nname = \"a\"\npath = \"proc:sphere\"\n");
  };
  EXPECT_NE(error_of(path("3")).find("'defaults.reference': expected a string"), std::string::npos);
  EXPECT_NE(error_of(path("\"\"")).find("'defaults.reference': must be one of the run's backend names"),
            std::string::npos);
  EXPECT_NE(error_of(path("\"embree,bvh2\"")).find("'defaults.reference': must be one of the run's backend names"),
            std::string::npos);
  const Suite s = load_suite(path("\"bvh8\""));  // a backend name, but not one of the run's
  const std::string error = testing::input_error_of([&] { timing_reference(s.settings); });
  EXPECT_NE(error.find(dir.file("s.toml") + ": 'defaults.reference': bvh8 is not one of the run's backends (embree, "
                                            "bvh2)"),
            std::string::npos)
      << error;
}

TEST(Suite, WithoutAReferenceTheTimingReferenceIsEmbreeWhenTheRunHasItAndNoneOtherwise) {
  SuiteSettings s;
  s.backends = {"bvh2", "embree"};
  EXPECT_EQ(timing_reference(s), "embree");
  s.backends = {"bvh2", "bvh8"};
  EXPECT_EQ(timing_reference(s), "");
  s.reference = "bvh8";
  EXPECT_EQ(timing_reference(s), "bvh8");
  s.reference = "embree";
  EXPECT_EQ(testing::input_error_of([&] { timing_reference(s); }),
            "--reference: embree is not one of the run's backends (bvh2, bvh8): add it to --backend or name one of them");
}

TEST(SettingsRules, AReferenceIsOneBackendName) {
  EXPECT_EQ(reference_setting(GivenValue::from_flag("--reference", "plugin:build/libmy.so:fast")),
            "plugin:build/libmy.so:fast");
  for (const char* bad : {"", "embree,bvh2", "a\nb"})
    EXPECT_NE(testing::input_error_of([&] { reference_setting(GivenValue::from_flag("--reference", bad)); })
                  .find("--reference: must be one of the run's backend names"),
              std::string::npos)
        << bad;
}

TEST(Suite, TheTableShowsTheRatioToTheTimingReferenceAndNamesItInTheHeader) {
  ResultRow old_plugin = timed_row(10, 11, 12), new_plugin = timed_row(10, 13, 14), embree = timed_row(5, 6, 7);
  old_plugin.backend = "plugin:old.so";
  old_plugin.plugin = "my_bvh";
  new_plugin.backend = "plugin:build/libnew.so:fast";
  new_plugin.plugin = "my_bvh";
  embree.backend = "embree";
  for (ResultRow* r : {&old_plugin, &new_plugin, &embree}) r->reference = "plugin:old.so";
  old_plugin.ratio_to_reference = 1.0;
  new_plugin.ratio_to_reference = 1.25;
  embree.ratio_to_reference = 0.5;
  new_plugin.ratio_to_embree = 2.0;  // not what the table shows
  const std::string table = format_results_table({old_plugin, new_plugin, embree});
  const auto line_of = [&](const std::string& part) {
    const std::size_t at = table.find(part);
    if (at == std::string::npos) return std::string();
    const std::size_t begin = table.rfind('\n', at) + 1;
    return table.substr(begin, table.find('\n', at) - begin);
  };
  EXPECT_NE(line_of("x plugin:old.so").find("backend"), std::string::npos) << table;
  EXPECT_NE(line_of("my_bvh (plugin:old.so)").find(" 1.00 "), std::string::npos) << table;
  EXPECT_NE(line_of("my_bvh (plugin:build/libnew.so:fast)").find(" 1.25 "), std::string::npos) << table;
  EXPECT_EQ(line_of("my_bvh (plugin:build/libnew.so:fast)").find("2.00"), std::string::npos) << table;
  EXPECT_NE(line_of("  primary embree ").find(" 0.50 "), std::string::npos) << table;
  // The ratio column sits under its header, right-aligned.
  const std::string header = line_of("x plugin:old.so");
  const std::size_t end = header.find("x plugin:old.so") + std::string("x plugin:old.so").size();
  EXPECT_EQ(line_of("my_bvh (plugin:old.so)").substr(end - 4, 4), "1.00") << table;
}

TEST(Suite, ARunWithoutATimingReferenceShowsNoRatio) {
  ResultRow r = timed_row(10, 11, 12);
  r.ratio_to_embree = 0;
  const std::string table = format_results_table({r});
  EXPECT_NE(table.find("x ref"), std::string::npos) << table;
}

}  // namespace
}  // namespace raybench
