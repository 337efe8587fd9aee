// Where an installed raybench and one in its build tree look for their files
// (io/default_paths.h): the build tree keeps the source tree's files, any
// other binary names no path of the machine it was built on.
#include "io/default_paths.h"

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <gtest/gtest.h>

namespace raybench {
namespace {
namespace fs = std::filesystem;

// A source tree, its build tree and an install prefix in a fresh folder.
struct Trees {
  fs::path root = fs::temp_directory_path() / ("default_paths_test." + std::to_string(::getpid()));
  fs::path src = root / "src", build = root / "build", prefix = root / "prefix";
  Trees() {
    fs::create_directories(src);
    fs::create_directories(build / "harness" / "tests");
    fs::create_directories(prefix / "bin");
    fs::create_directories(prefix / "share" / "raybench" / "suites");
    std::ofstream(src / "CMakeLists.txt") << "project(raybench)\n";
  }
  ~Trees() { fs::remove_all(root); }
  DefaultPathsInputs inputs(const fs::path& exe) const {
    return {exe.string(), src.string(), build.string(), "/xdg", "/home/u"};
  }
};

TEST(DefaultPaths, TheBuildTreeKeepsTheSourceTreesFiles) {
  Trees t;
  for (const fs::path& exe : {t.build / "raybench", t.build / "harness" / "tests" / "cli_test"}) {
    const DefaultPaths d = default_paths_for(t.inputs(exe));
    EXPECT_TRUE(d.build_tree) << exe;
    EXPECT_EQ(d.suite, t.src.string() + "/meshes/default.toml");
    EXPECT_EQ(d.out_csv, t.src.string() + "/results/latest.csv");
    EXPECT_EQ(d.rays_dir, t.src.string() + "/results/rays");
    EXPECT_EQ(d.gate_config, t.src.string() + "/results/gate.toml");
    EXPECT_EQ(d.kernels_csv, t.src.string() + "/results/kernels.csv");
    EXPECT_EQ(d.accuracy_kernels_csv, t.src.string() + "/results/accuracy-kernels.csv");
  }
}

TEST(DefaultPaths, AnInstalledBinaryUsesItsShareFolderTheCurrentDirectoryAndTheCache) {
  Trees t;
  const DefaultPaths d = default_paths_for(t.inputs(t.prefix / "bin" / "raybench"));
  EXPECT_FALSE(d.build_tree);
  EXPECT_EQ(d.suite, (t.prefix / "share/raybench/suites/procedural.toml").string());
  EXPECT_EQ(d.gate_config, (t.prefix / "share/raybench/gate.toml").string());
  EXPECT_EQ(d.out_csv, "raybench-results.csv");
  EXPECT_EQ(d.kernels_csv, "raybench-kernels.csv");
  EXPECT_EQ(d.kernels_json, "raybench-kernels.json");
  EXPECT_EQ(d.accuracy_kernels_csv, "raybench-accuracy-kernels.csv");
  EXPECT_EQ(d.rays_dir, "/xdg/raybench/rays");
}

TEST(DefaultPaths, AnInstallIntoTheBuildTreeIsAnInstall) {
  Trees t;
  const fs::path prefix = t.build / "prefix";
  fs::create_directories(prefix / "bin");
  fs::create_directories(prefix / "share" / "raybench");
  EXPECT_FALSE(default_paths_for(t.inputs(prefix / "bin" / "raybench")).build_tree);
}

TEST(DefaultPaths, ABuildTreeWhoseSourcesAreGoneIsTreatedAsInstalled) {
  Trees t;
  fs::remove(t.src / "CMakeLists.txt");
  const DefaultPaths d = default_paths_for(t.inputs(t.build / "raybench"));
  EXPECT_FALSE(d.build_tree);
  EXPECT_EQ(d.out_csv, "raybench-results.csv");
}

TEST(DefaultPaths, RaysGoToTheXdgCacheThenHomeThenTheCurrentDirectory) {
  Trees t;
  DefaultPathsInputs in = t.inputs(t.prefix / "bin" / "raybench");
  in.xdg_cache_home = "relative/cache";  // the XDG rule: a relative path is ignored
  EXPECT_EQ(default_paths_for(in).rays_dir, "/home/u/.cache/raybench/rays");
  in.xdg_cache_home = "";
  EXPECT_EQ(default_paths_for(in).rays_dir, "/home/u/.cache/raybench/rays");
  in.home = "";
  EXPECT_EQ(default_paths_for(in).rays_dir, "raybench-rays");
}

}  // namespace
}  // namespace raybench
