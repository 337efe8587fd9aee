// Specification of suite manifests (harness/src/suite.h).
#include "suite.h"

#include <algorithm>

#include "build_info.h"
#include "error.h"
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

}  // namespace
}  // namespace raybench
