// Specification of scene loading (harness/src/scene/scene.h): what a viewer would
// show, every triangle of the file kept, one documented order.
#include "scene/scene.h"

#include <cstdlib>
#include <map>
#include <tuple>

#include <sys/stat.h>

#include "io/error.h"
#include "scene/ply_precheck.h"
#include "scene/procedural.h"
#include "suite/suite.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::TempDir;

std::string error_of(const std::string& spec) {
  return testing::input_error_of([&] { load_scene(spec); });
}

bool same(Vec3f a, Vec3f b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

TEST(SceneLoading, PolygonsAreTriangulatedAndPointsAndLinesCounted) {
  TempDir dir;
  const auto path = dir.write("mixed.obj",
                              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                              "f 1 2 3 4\n"   // a quad: two triangles
                              "f 1 2 5\n"     // a triangle
                              "l 1 5\n"       // a line: skipped, counted
                              "p 3\n");       // a point: skipped, counted
  const Scene s = load_scene(path);
  EXPECT_EQ(s.name, "mixed");
  EXPECT_EQ(s.triangles.size(), 3u);
  EXPECT_EQ(s.skipped_lines, 1u);
  EXPECT_EQ(s.skipped_points, 1u);
}

TEST(SceneLoading, NodeTransformsAreApplied) {
  // glTF: a parent node translated by (10, 0, 0) holds a child scaled by 2
  // whose mesh is the unit right triangle.
  TempDir dir;
  const auto path = dir.write("nested.gltf", R"({
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"children": [1], "translation": [10, 0, 0]}, {"mesh": 0, "scale": [2, 2, 2]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]
  })");
  const Scene s = load_scene(path);
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_TRUE(same(s.triangles[0].v0, {10, 0, 0}));
  EXPECT_TRUE(same(s.triangles[0].v1, {12, 0, 0}));
  EXPECT_TRUE(same(s.triangles[0].v2, {10, 2, 0}));
}

TEST(SceneLoading, DegenerateTrianglesAreKeptInFileOrder) {
  // Triangle 1 has two bit-identical vertices: assimp's FindDegenerates would
  // turn it into a line; raybench must keep it.
  TempDir dir;
  const auto path = dir.write("degenerate.ply",
                              "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 3\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n1 0 0\n3 0 1 2\n3 0 1 3\n3 2 1 0\n");
  const Scene s = load_scene(path);
  ASSERT_EQ(s.triangles.size(), 3u);
  EXPECT_TRUE(same(s.triangles[0].v2, {0, 1, 0}));
  EXPECT_TRUE(same(s.triangles[1].v1, s.triangles[1].v2));
  EXPECT_TRUE(same(s.triangles[2].v0, {0, 1, 0}));
}

TEST(SceneLoading, ConferenceKeepsAllItsCoincidentVertexTriangles) {
  const std::string path = testing::shared_mesh("conference.ply");
  if (!testing::exists(path)) GTEST_SKIP() << path << " absent (the shared meshes live beside the repository)";
  EXPECT_EQ(load_scene(path).triangles.size(), 331179u);  // MANIFEST.md; assimp's defaults would drop 52,670
}

TEST(SceneLoading, RealTestModelsLoad) {
  const std::string path = testing::assimp_model("PLY/Wuson.ply");
  ASSERT_TRUE(testing::exists(path)) << "assimp-testmodels is not installed (scripts/test installs it)";
  const Scene s = load_scene(path);
  EXPECT_EQ(s.triangles.size(), 3732u);
  EXPECT_FALSE(s.bounds().empty());
}

TEST(SceneLoading, BadFilesAreOneLineErrorsNamingTheFile) {
  TempDir dir;
  const std::string empty = dir.write("empty.obj", "");
  const std::string garbage = dir.write("garbage.ply", std::string("ply\nformat binary_little_endian 1.0\nelement vertex 99\n"));
  const std::string no_faces = dir.write("points.obj", "v 0 0 0\nv 1 0 0\n");
  const struct {
    std::string path;
    const char* problem;
  } cases[] = {
      {dir.file("absent.obj"), "no such file"},
      {dir.file(""), "is a directory"},
      {empty, ""},
      {garbage, "header never ends"},
      {no_faces, "no triangles"},
      {testing::assimp_model("PLY/pond.0.ply"), "no triangles"},  // a point cloud
  };
  for (const auto& c : cases) {
    const std::string error = error_of(c.path);
    EXPECT_NE(error.find(c.path), std::string::npos) << c.path << ": '" << error << "'";
    EXPECT_NE(error.find(c.problem), std::string::npos) << c.path << ": '" << error << "'";
    EXPECT_EQ(error.find('\n'), std::string::npos) << "multi-line error: " << error;
  }
}

// One error line naming the file and saying `problem`, for each case.
void expect_errors(const std::vector<std::pair<std::string, std::string>>& cases) {
  for (const auto& [path, problem] : cases) {
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << path << ": '" << error << "'";
    EXPECT_NE(error.find(problem), std::string::npos) << path << ": '" << error << "'";
    EXPECT_EQ(error.find('\n'), std::string::npos) << "multi-line error: " << error;
  }
}

// The ASCII PLY of a unit square, as a header and its vertex lines.
const std::string kSquarePlyHeader =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kSquareVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

// Issue 28: Debian's assimp asserts in its triangulation step on these
// (SIGABRT); the import runs in a child process, so its crash is an error.
TEST(SceneLoading, AMeshCutMidFileIsAnErrorNamingTheFileNotACrash) {
  TempDir dir;
  expect_errors({
      // The square's PLY cut inside its vertex list.
      {dir.write("cut.ply", kSquarePlyHeader + "0 0 0\n1 0 0\n1 1 0\n0 1"), "assimp crashed (SIGABRT)"},
      // assimp-testmodels' OFF/Cube.off cut after 202 of its 298 bytes.
      {dir.write("cut.off",
                 "OFF\n8 6 0\n-0.500000 -0.500000 0.500000\n0.500000 -0.500000 0.500000\n"
                 "-0.500000 0.500000 0.500000\n0.500000 0.500000 0.500000\n-0.500000 0.500000 -0.500000\n"
                 "0.500000 0.500000 -0.500000\n-0.500000 -0.500000 -0."),
       "assimp crashed (SIGABRT)"},
  });
}

// assimp passes a PLY's face indices through unchecked; collecting the
// triangles read far out of bounds.
TEST(SceneLoading, FaceIndicesOutOfRangeOrNegativeAreErrorsNamingTheFile) {
  TempDir dir;
  expect_errors({
      {dir.write("beyond.ply", kSquarePlyHeader + kSquareVertices + "3 0 1 2\n3 0 2 9\n"),
       "face 1 of mesh 0 uses vertex 9"},
      {dir.write("negative.ply", kSquarePlyHeader + kSquareVertices + "3 0 1 2\n3 0 2 -1\n"),
       "face 1 of mesh 0 uses vertex -1"},
  });
}

TEST(SceneLoading, PlyHeadsAssimpReadsWithoutEndHeaderAreRefusedBeforeAssimpLoopsOnThem) {
  TempDir dir;
  const std::string rest = "format ascii 1.0\nelement vertex 3\n";
  expect_errors({
      {dir.write("space.ply", "ply \n" + rest), "header never ends"},
      {dir.write("tab.ply", "ply\t\n" + rest), "header never ends"},
      {dir.write("upper.ply", "PLY\n" + rest), "header never ends"},
  });
}

TEST(SceneLoading, NonRegularMeshFilesAreRefusedBeforeTheyAreOpened) {
  TempDir dir;
  const std::string fifo = dir.file("mesh.ply");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_errors({{fifo, "FIFO"}, {dir.file(""), "is a directory"}});
}

// Box areas overflow float beyond about 3.7e18 (scene.h): the wide BVH's
// collapse segfaulted on these. Refused at load, naming the file.
TEST(SceneLoading, CoordinatesBeyondTheBoundOrNotFiniteAreRefused) {
  TempDir dir;
  expect_errors({
      {dir.write("1e19.obj", "v 1e19 0 0\nv -1e19 0 0\nv 0 1e19 0\nf 1 2 3\n"), "within +-1e18"},
      {dir.write("3e38.obj", "v 3e38 0 0\nv -3e38 0 0\nv 0 -3e38 0\nf 1 2 3\n"), "within +-1e18"},
      {dir.write("inf.obj", "v inf 0 0\nv 0 0 0\nv 0 1 0\nf 1 2 3\n"), "not a finite float"},
  });
  // The bound itself is allowed.
  EXPECT_EQ(load_scene(dir.write("1e18.obj", "v 1e18 0 0\nv -1e18 0 0\nv 0 -1e18 0\nf 1 2 3\n")).triangles.size(), 1u);
}

// The bound holds for the scene as traced: after the manifest's transform.
TEST(SceneLoading, AManifestScaleThatTakesAProceduralSceneBeyondTheBoundIsRefused) {
  SuiteScene entry;
  entry.name = "huge";
  entry.path = "proc:sphere";
  entry.scale = 1e20;
  const std::string error = testing::input_error_of([&] { load_suite_scene(entry); });
  EXPECT_NE(error.find("scene 'huge'"), std::string::npos) << error;
  EXPECT_NE(error.find("proc:sphere"), std::string::npos) << error;
  EXPECT_NE(error.find("within +-1e18"), std::string::npos) << error;
  entry.scale = 1e17;  // the unit sphere's radius 1e17: within the bound
  EXPECT_EQ(load_suite_scene(entry).triangles.size(), 2208u);
}

// Sets an environment variable for the scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) { ::setenv(name, value, 1); }
  ~ScopedEnv() { ::unsetenv(name_); }

 private:
  const char* name_;
};

// Wuson.ply, 915 kB of ASCII, takes assimp tens of milliseconds: far more
// than the 1 ms given, so the child is killed at its deadline.
TEST(SceneLoading, ALoaderStillRunningAtItsDeadlineIsKilledAndNamed) {
  const std::string path = testing::assimp_model("PLY/Wuson.ply");
  ASSERT_TRUE(testing::exists(path)) << "assimp-testmodels is not installed (scripts/test installs it)";
  {
    ScopedEnv timeout("RAYBENCH_LOAD_TIMEOUT", "0.001");
    expect_errors({{path, "assimp did not finish reading it within 0.001 s"}});
  }
  EXPECT_EQ(load_scene(path).triangles.size(), 3732u);  // the same file, with the default deadline
}

TEST(SceneLoading, ALoadTimeoutThatIsNotAPositiveNumberIsRefused) {
  const std::string path = testing::assimp_model("PLY/Wuson.ply");
  for (const char* bad : {"0", "-1", "nan", "inf", "1e9", "5s", ""}) {
    ScopedEnv timeout("RAYBENCH_LOAD_TIMEOUT", bad);
    const std::string error = error_of(path);
    EXPECT_NE(error.find("RAYBENCH_LOAD_TIMEOUT"), std::string::npos) << "'" << bad << "': " << error;
  }
}

TEST(PlyPrecheck, RefusesEveryHeadAssimpReadsAsAPlyHeaderThatNeverEnds) {
  for (const char* head : {"ply \nformat ascii 1.0\nelement vertex 3\n", "ply\t\nformat ascii 1.0\n", "PLY\n",
                           "pLy\nformat ascii 1.0\n", "plyx\nformat ascii 1.0\n", "ply", "\nply\nformat ascii 1.0\n",
                           "\r\nPLY\r\nformat ascii 1.0\r\n",
                           "ply\nformat ascii 1.0\nend_header",          // no line end after it: assimp reads stale memory there
                           "ply\nformat ascii 1.0\nend_headerx\n",        // another token
                           "ply\nformat ascii 1.0\ncomment end_header\n", // a comment
                           "ply\nformat ascii 1.0\r\rend_header\n"}) {    // "\r\r" skips to the next '\n'
    EXPECT_NE(ply_header_problem(head), "") << "'" << head << "'";
  }
}

TEST(PlyPrecheck, AcceptsCompleteHeadersAndFilesAssimpDoesNotReadAsPly) {
  for (const char* head : {"ply\nformat ascii 1.0\nelement vertex 0\nend_header\n",
                           "PLY\r\nformat ascii 1.0\r\nend_header\r\n", "ply \nformat ascii 1.0\n  end_header \n",
                           "ply\rformat ascii 1.0\rend_header\r", "ply\nformat binary_little_endian 1.0\nend_header\n\x01",
                           "", "pl\n", "v 0 0 0\nf 1 1 1\n", "OFF\n3 1 0\n", "# ply\n", " ply\n"}) {
    EXPECT_EQ(ply_header_problem(head), "") << "'" << head << "'";
  }
}

TEST(ProceduralScenes, AreDeterministicAndOfTheDocumentedSize) {
  const Scene a = load_scene("proc:terrain_spheres_small");
  const Scene b = load_scene("proc:terrain_spheres_small");
  EXPECT_EQ(a.triangles.size(), 7808u);
  EXPECT_EQ(a.content_hash(), b.content_hash());
  EXPECT_EQ(a.name, "terrain_spheres_small");
  EXPECT_EQ(load_scene("proc:sphere").triangles.size(), 2208u);
}

TEST(ProceduralScenes, TheLargeSceneHasAboutAMillionTriangles) {
  EXPECT_EQ(load_scene("proc:terrain_spheres").triangles.size(), 1000448u);
}

TEST(ProceduralScenes, TheSphereIsClosed) {
  // Every edge is shared by exactly two triangles, with bit-identical vertices.
  const Scene s = load_scene("proc:sphere");
  using Key = std::tuple<float, float, float>;
  std::map<std::pair<Key, Key>, int> edges;
  const auto key = [](Vec3f v) { return Key{v.x, v.y, v.z}; };
  for (const Triangle& t : s.triangles) {
    const Vec3f v[3] = {t.v0, t.v1, t.v2};
    for (int i = 0; i < 3; ++i) {
      Key a = key(v[i]), b = key(v[(i + 1) % 3]);
      if (b < a) std::swap(a, b);
      ++edges[{a, b}];
    }
  }
  for (const auto& [edge, count] : edges) EXPECT_EQ(count, 2);
}

TEST(ProceduralScenes, UnknownNamesListTheKnownOnes) {
  const std::string error = error_of("proc:teapot");
  EXPECT_NE(error.find("proc:teapot"), std::string::npos);
  EXPECT_NE(error.find("proc:terrain_spheres"), std::string::npos);
}

}  // namespace
}  // namespace raybench
