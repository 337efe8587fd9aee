// Specification of scene loading (harness/src/scene.h): what a viewer would
// show, every triangle of the file kept, one documented order.
#include "scene.h"

#include <map>
#include <tuple>

#include "error.h"
#include "procedural.h"
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
