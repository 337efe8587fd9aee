// Triangle stand-ins for analytic scenes (scene/tessellate.h): the
// resolutions a user may ask for, the triangles each primitive becomes, the
// map back to the prim it stands for, and hits on a stand-in read as hits on
// the analytic scene.
#include "scene/tessellate.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <tuple>

#include "accuracy/accuracy_csv.h"
#include "backends/backend.h"
#include "io/error.h"
#include "measure/trace.h"
#include "results/metadata.h"
#include "results/results_csv.h"
#include "suite/suite_run.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::input_error_of;

TEST(Tessellate, AResolutionIsSegmentsByRings) {
  const Tessellation t = parse_tessellation("16x8", "--tessellate");
  EXPECT_EQ(t.segments, 16);
  EXPECT_EQ(t.rings, 8);
  EXPECT_EQ(t.name(), "uv16x8");
  EXPECT_EQ(parse_tessellation("3x2", "k").name(), "uv3x2");
  EXPECT_EQ(parse_tessellation("4096x4096", "k").name(), "uv4096x4096");
}

TEST(Tessellate, AnythingButSxRWithinTheBoundsIsRefusedNamingWhereAndWhat) {
  for (const char* bad : {"", "16", "x8", "16x", "2x8", "16x1", "4097x8", "16x4097", "16X8", "+16x8", " 16x8",
                          "16x8x2", "-3x4", "16x 8", "uv16x8", "16.0x8", "0x0", "99999999999x8"}) {
    const std::string message = input_error_of([&] { parse_tessellation(bad, "m.toml: 'scene[0].tessellate'"); });
    EXPECT_NE(message.find("m.toml: 'scene[0].tessellate': must be SxR"), std::string::npos) << bad << ": " << message;
    EXPECT_NE(message.find(std::string("got '") + bad + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("e.g. 16x8"), std::string::npos) << message;
  }
}

TEST(Tessellate, AListIsEveryResolutionOnceAndMayBeEmpty) {
  const std::vector<Tessellation> list = parse_tessellations({"8x4", "32x16"}, "--tessellate");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1], (Tessellation{32, 16}));
  EXPECT_TRUE(parse_tessellations({}, "--tessellate").empty());
  EXPECT_EQ(input_error_of([] { parse_tessellations({"8x4", "16x8", "8x4"}, "--tessellate"); }),
            "--tessellate: 8x4 is given twice");
}

// Two triangles, two spheres, a box and an oriented box turned about two
// axes: every type, in the order of global prim ids.
Scene mixed_scene() {
  Scene s;
  s.name = "mix";
  s.source = "test";
  s.triangles = {{{-10, -1, -10}, {10, -1, -10}, {10, -1, 10}}, {{-10, -1, -10}, {10, -1, 10}, {-10, -1, 10}}};
  s.spheres = {{{0, 1, 0}, 1.0f}, {{4, 2, 0}, 0.5f}};
  BBox box;
  box.lower = {-4, 0, -1};
  box.upper = {-3, 2, 1};
  s.boxes = {box};
  const float c = std::cos(0.5f), sn = std::sin(0.5f);
  // Rotation by 0.5 rad about z, then the result about x by 0.5 rad.
  const Vec3f a0{c, sn, 0}, a1{-sn, c, 0};
  const auto about_x = [&](Vec3f v) { return Vec3f{v.x, c * v.y - sn * v.z, sn * v.y + c * v.z}; };
  s.obbs = {{{0, 3.5f, 5}, {about_x(a0), about_x(a1), about_x({0, 0, 1})}, {1.0f, 0.5f, 0.25f}}};
  return s;
}

TEST(Tessellate, EachPrimitiveBecomesItsTrianglesInPrimIdOrder) {
  const Scene scene = mixed_scene();
  const Tessellation t{8, 4};
  // 8 segments x (2 * 4 - 2) = 48 per sphere, 12 per box.
  EXPECT_EQ(stand_in_triangle_count(scene, t), 2u + 2u * 48u + 12u + 12u);
  const StandIn s = tessellate(scene, t);
  EXPECT_EQ(s.scene.name, "mix@uv8x4");
  EXPECT_EQ(s.tessellation, t);
  EXPECT_FALSE(s.scene.has_analytic());
  ASSERT_EQ(s.scene.triangles.size(), stand_in_triangle_count(scene, t));
  ASSERT_EQ(s.prim_of.size(), s.scene.triangles.size());
  EXPECT_EQ(s.kept_triangles, 2u);
  std::map<std::int32_t, int> count;
  for (std::int32_t id : s.prim_of) ++count[id];
  EXPECT_EQ(count, (std::map<std::int32_t, int>{{0, 1}, {1, 1}, {2, 48}, {3, 48}, {4, 12}, {5, 12}}));
  for (std::size_t i = 1; i < s.prim_of.size(); ++i) EXPECT_LE(s.prim_of[i - 1], s.prim_of[i]) << "in prim id order";
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(std::memcmp(&s.scene.triangles[i], &scene.triangles[i], sizeof(Triangle)), 0) << "kept bit for bit";
  }
}

TEST(Tessellate, ASceneWithoutAnalyticPrimitivesStandsForItself) {
  Scene scene = mixed_scene();
  scene.spheres.clear();
  scene.boxes.clear();
  scene.obbs.clear();
  const StandIn s = tessellate(scene, {16, 8});
  EXPECT_EQ(s.scene.triangles.size(), 2u);
  EXPECT_EQ(s.prim_of, (std::vector<std::int32_t>{0, 1}));
}

// Every edge of a closed surface is shared by exactly two triangles, and
// shared bit for bit: the stand-in is as watertight as the triangle test.
void expect_closed(const std::vector<Triangle>& tris, std::size_t first, std::size_t count) {
  using Key = std::tuple<float, float, float>;
  const auto key = [](Vec3f v) { return Key{v.x, v.y, v.z}; };
  std::map<std::pair<Key, Key>, int> edges;
  for (std::size_t i = first; i < first + count; ++i) {
    const Vec3f v[3] = {tris[i].v0, tris[i].v1, tris[i].v2};
    for (int e = 0; e < 3; ++e) {
      Key a = key(v[e]), b = key(v[(e + 1) % 3]);
      if (b < a) std::swap(a, b);
      ++edges[{a, b}];
    }
  }
  for (const auto& [edge, n] : edges) EXPECT_EQ(n, 2) << "an edge not shared by exactly two triangles";
}

TEST(Tessellate, ASphereBecomesAClosedInscribedUvSphere) {
  const Scene scene = mixed_scene();
  const StandIn s = tessellate(scene, {12, 6});
  const std::size_t per_sphere = 12 * 10;
  for (std::size_t k = 0; k < 2; ++k) {
    const Sphere& sphere = scene.spheres[k];
    const std::size_t first = 2 + k * per_sphere;
    expect_closed(s.scene.triangles, first, per_sphere);
    for (std::size_t i = first; i < first + per_sphere; ++i) {
      for (const Vec3f v : {s.scene.triangles[i].v0, s.scene.triangles[i].v1, s.scene.triangles[i].v2}) {
        // Every vertex on the sphere, up to float rounding of its coordinates.
        EXPECT_NEAR(length(v - sphere.center), sphere.radius, 4e-7 * (length(sphere.center) + sphere.radius));
      }
    }
  }
}

TEST(Tessellate, ABoxBecomesItsTwelveTrianglesOnItsSixFaces) {
  const Scene scene = mixed_scene();
  const StandIn s = tessellate(scene, {8, 4});
  const std::size_t first = 2 + 2 * 48;
  const BBox& b = scene.boxes[0];
  expect_closed(s.scene.triangles, first, 12);
  double area = 0.0;
  for (std::size_t i = first; i < first + 12; ++i) {
    const Triangle& t = s.scene.triangles[i];
    int on_face = 0;  // coordinates constant over the triangle, at the box's lower or upper side
    for (int a = 0; a < 3; ++a) {
      for (const Vec3f v : {t.v0, t.v1, t.v2}) EXPECT_TRUE(v[a] == b.lower[a] || v[a] == b.upper[a]) << "a corner";
      on_face += t.v0[a] == t.v1[a] && t.v1[a] == t.v2[a];
    }
    EXPECT_EQ(on_face, 1) << "triangle " << i << " lies in one face";
    // Outward winding: the normal points away from the box's centre.
    const Vec3f centre = (b.lower + b.upper) * 0.5f, n = cross(t.v1 - t.v0, t.v2 - t.v0);
    EXPECT_GT(dot(n, t.v0 - centre), 0.0f) << "triangle " << i;
    area += 0.5 * length(n);
  }
  const Vec3f e = b.upper - b.lower;
  EXPECT_NEAR(area, 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x), 1e-5);
}

TEST(Tessellate, AnOrientedBoxBecomesTwelveTrianglesThroughItsCorners) {
  const Scene scene = mixed_scene();
  const StandIn s = tessellate(scene, {8, 4});
  const std::size_t first = 2 + 2 * 48 + 12;
  const OrientedBox& o = scene.obbs[0];
  expect_closed(s.scene.triangles, first, 12);
  for (std::size_t i = first; i < first + 12; ++i) {
    const Triangle& t = s.scene.triangles[i];
    for (const Vec3f v : {t.v0, t.v1, t.v2}) {
      for (int k = 0; k < 3; ++k) {
        // In the box's frame every corner sits at +-half extent on each axis.
        EXPECT_NEAR(std::fabs(dot(v - o.center, o.axis[k])), o.half_extent[k], 1e-6) << "triangle " << i;
      }
    }
    EXPECT_GT(dot(cross(t.v1 - t.v0, t.v2 - t.v0), t.v0 - o.center), 0.0f) << "outward, triangle " << i;
  }
}

// proc:terrain_spheres tessellates its balls as UV spheres (64 segments by
// 32 rings; the small one 32 by 16); terrain_spheres_analytic holds the same
// terrain and the same balls as spheres: its stand-in at that resolution is
// terrain_spheres, triangle for triangle, so the study's uv64x32 row is the
// tessellated scene's.
TEST(Tessellate, TheAnalyticTerrainsStandInIsTheTessellatedTerrain) {
  Scene analytic;
  try {
    analytic = load_scene("proc:terrain_spheres_analytic_small");
  } catch (const InputError& e) {
    GTEST_SKIP() << "needs the procedural analytic scenes: " << e.what();
  }
  const Scene tessellated = load_scene("proc:terrain_spheres_small");
  ASSERT_FALSE(analytic.spheres.empty());
  // terrain_spheres_small: 16 rings by 32 segments.
  const StandIn s = tessellate(analytic, {32, 16});
  ASSERT_EQ(s.scene.triangles.size(), tessellated.triangles.size());
  EXPECT_EQ(std::memcmp(s.scene.triangles.data(), tessellated.triangles.data(),
                        tessellated.triangles.size() * sizeof(Triangle)),
            0);
}

TEST(Tessellate, AStandInBeyondInt32PrimIdsIsRefusedBeforeAnyTriangleIsMade) {
  Scene scene;
  scene.name = "many";
  // 4096 x 8190 = 33.5 million triangles per sphere: 65 of them pass 2^31 - 1.
  scene.spheres.assign(65, Sphere{{0, 0, 0}, 1.0f});
  const Tessellation finest{kMaxTessellation, kMaxTessellation};
  EXPECT_EQ(stand_in_triangle_count(scene, finest), 65u * 4096u * 8190u);
  const std::string message = input_error_of([&] { tessellate(scene, finest); });
  EXPECT_NE(message.find("scene 'many': its uv4096x4096 stand-in would have 2180505600 triangles"), std::string::npos)
      << message;
  EXPECT_NO_THROW(check_stand_in_size(scene, {64, 32}));
}

TEST(Tessellate, HitsOnAStandInAreHitsOnThePrimitiveItStandsFor) {
  const Scene scene = mixed_scene();
  const StandIn s = tessellate(scene, {8, 4});
  std::vector<Hit> hits(4);
  hits[0] = {2.0f, 1, 0.25f, 0.5f};   // a kept triangle: id and barycentrics kept
  hits[1] = {3.0f, 2 + 48 + 5, 0.1f, 0.2f};  // on the second sphere's stand-in
  hits[2] = {4.0f, static_cast<std::int32_t>(s.scene.triangles.size() - 1), 0.3f, 0.3f};  // the oriented box's last
  // hits[3]: a miss
  const std::vector<Hit> a = analytic_hits(hits, s);
  EXPECT_EQ(a[0].prim, 1);
  EXPECT_EQ(a[0].u, 0.25f);
  EXPECT_EQ(a[0].v, 0.5f);
  EXPECT_EQ(a[1].prim, 3);
  EXPECT_EQ(a[1].t, 3.0f);
  EXPECT_EQ(a[1].u, 0.0f) << "analytic hits report u = v = 0";
  EXPECT_EQ(a[1].v, 0.0f);
  EXPECT_EQ(a[2].prim, 5);
  EXPECT_FALSE(a[3].hit());
}

// Traced by a backend: a ray at each analytic primitive hits a triangle that
// stands for that primitive, never nearer than the primitive itself.
TEST(Tessellate, ATracedStandInHitsThePrimitiveEachRayAimsAt) {
  const Scene scene = mixed_scene();
  const PrimitiveSpans prims = scene.primitives();
  std::vector<Ray> rays;
  std::vector<std::int32_t> aimed;
  std::vector<double> exact_t;
  const auto aim = [&](Vec3f target, std::int32_t id, double t) {
    rays.push_back({target + Vec3f{0.0f, 0.0f, -20.0f}, 0.0f, {0.0f, 0.0f, 1.0f}, 1e30f});
    aimed.push_back(id);
    exact_t.push_back(t);
  };
  const auto id = [](std::size_t i) { return static_cast<std::int32_t>(i); };
  // Seen from -z, a sphere's surface is one radius before its centre.
  for (std::size_t k = 0; k < 2; ++k)
    aim(scene.spheres[k].center + Vec3f{0.013f, 0.007f, 0.0f}, id(prims.first_sphere() + k),
        20.0 - scene.spheres[k].radius);
  aim((scene.boxes[0].lower + scene.boxes[0].upper) * 0.5f, id(prims.first_box()), 20.0 - 1.0);
  aim(scene.obbs[0].center, id(prims.first_obb()), std::nan(""));
  aim({7.0f, 0.0f, 0.0f}, kNoHit, std::nan(""));  // above the floor (y = -1), beside everything
  const TraceExecutor executor(1);
  for (const Tessellation t : {Tessellation{8, 4}, Tessellation{64, 32}}) {
    const StandIn s = tessellate(scene, t);
    const auto backend = make_backend("bvh2");
    backend->build(s.scene);
    std::vector<Hit> hits(rays.size());
    executor.intersect(*backend, rays, hits);
    const std::vector<Hit> a = analytic_hits(hits, s);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(a[i].prim, aimed[i]) << t.name() << " ray " << i;
      if (std::isnan(exact_t[i])) continue;
      if (i < 2) EXPECT_GE(a[i].t, exact_t[i] * (1.0 - 1e-6)) << "an inscribed stand-in is never nearer";
      else EXPECT_NEAR(a[i].t, exact_t[i], 1e-5) << "a box's stand-in is the box";
    }
  }
}

// The mean distance from a sphere to its stand-in along rays over the inner
// half of its disc falls with the square of the resolution (the sagitta of a
// facet): 16 times the segments and rings, far more than 5 times closer.
TEST(Tessellate, AStandInApproachesItsSphereAsTheResolutionGrows) {
  Scene scene;
  scene.name = "ball";
  scene.spheres = {{{0.0f, 0.0f, 0.0f}, 1.0f}};
  std::vector<Ray> rays;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j)
      if (i * i + j * j <= 100) rays.push_back({{0.05f * i + 0.001f, 0.05f * j + 0.002f, -10.0f}, 0.0f, {0, 0, 1}, 1e30f});
  const TraceExecutor executor(1);
  std::vector<double> mean_error;
  for (const Tessellation t : {Tessellation{8, 4}, Tessellation{32, 16}, Tessellation{128, 64}}) {
    const StandIn s = tessellate(scene, t);
    const auto backend = make_backend("bvh2");
    backend->build(s.scene);
    std::vector<Hit> hits(rays.size());
    executor.intersect(*backend, rays, hits);
    double sum = 0.0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      ASSERT_TRUE(hits[i].hit()) << t.name() << " ray " << i;
      const double x = rays[i].org.x, y = rays[i].org.y;
      const double exact = 10.0 - std::sqrt(1.0 - x * x - y * y);
      EXPECT_GE(hits[i].t, exact - 1e-5) << t.name() << " ray " << i;
      sum += hits[i].t - exact;
    }
    mean_error.push_back(sum / static_cast<double>(rays.size()));
  }
  EXPECT_GT(mean_error[0], 1e-2) << "8x4 is a coarse sphere";
  EXPECT_LT(mean_error[1], mean_error[0] / 5);
  EXPECT_LT(mean_error[2], mean_error[1] / 5);
  EXPECT_GT(mean_error[2], 0.0);
}


// The tessellation study in a run (suite/suite_run.h): after a scene with
// analytic primitives, each stand-in traced by every backend with the same
// rays, its rows marked with their representation, and, in accuracy runs,
// judged by the same referee. Scenes made here: a manifest cannot name
// analytic primitives before the scene files land (issue 31).
RunOptions small_run(const testing::TempDir& dir) {
  RunOptions options;
  options.settings.rays = 1024;
  options.settings.raysets = {"primary", "shadow"};
  options.settings.backends = {"embree", "bvh2"};
  options.settings.repetitions = 1;
  options.settings.build_repetitions = 1;
  options.settings.min_time = 0.001;
  options.settings.warmup = 0.0;
  options.settings.tessellate = {{8, 4}, {32, 16}};
  options.out_csv = dir.file("run.csv");
  options.rays_dir = dir.file("rays");
  return options;
}

Scene triangles_only() {
  Scene s = mixed_scene();
  s.name = "floor";
  s.spheres.clear();
  s.boxes.clear();
  s.obbs.clear();
  return s;
}

// A backend that cannot model the analytic scene is skipped for it (with a
// note, backends_for_scene) but traces its stand-ins, which are triangles.
TEST(TessellationStudy, EachStandInIsTracedByEveryBackendWithTheScenesRaysAndJudgedByItsReferee) {
  testing::TempDir dir;
  RunOptions options = small_run(dir);
  options.accuracy_csv = dir.file("accuracy.csv");
  const RunResults results = run_scenes(options, {mixed_scene(), triangles_only()});
  int modelling = 0;  // backends of the run that model spheres, boxes and oriented boxes
  for (const std::string& b : options.settings.backends) {
    const Capabilities c = make_backend(b)->capabilities();
    modelling += c.spheres && c.boxes && c.oriented_boxes;
  }
  ASSERT_GE(modelling, 1) << "Embree models every type";
  // (scene, representation, triangles) of every row, per ray set and backend.
  std::map<std::string, std::pair<std::string, std::size_t>> seen;
  std::map<std::string, int> rows_of;
  for (const ResultRow& r : results.rows) {
    seen[r.scene] = {r.representation, r.triangles};
    ++rows_of[r.scene];
    EXPECT_EQ(r.rays, 1024u);
  }
  const Scene mix = mixed_scene();
  EXPECT_EQ(seen["mix"].first, "analytic");
  EXPECT_EQ(seen["mix@uv8x4"], std::make_pair(std::string("uv8x4"), stand_in_triangle_count(mix, {8, 4})));
  EXPECT_EQ(seen["mix@uv32x16"], std::make_pair(std::string("uv32x16"), stand_in_triangle_count(mix, {32, 16})));
  EXPECT_EQ(seen["floor"].first, "triangles");
  EXPECT_EQ(seen.size(), 4u) << "a scene without analytic primitives has no stand-in";
  EXPECT_EQ(rows_of["mix"], 2 * modelling) << "every ray set, every backend that models the scene";
  for (const char* scene : {"mix@uv8x4", "mix@uv32x16", "floor"}) EXPECT_EQ(rows_of[scene], 2 * 2) << scene;
  // The scene's rows, then its stand-ins', in the order given.
  const std::size_t first = 2 * static_cast<std::size_t>(modelling);
  ASSERT_EQ(results.rows.size(), first + 12);
  EXPECT_EQ(results.rows[0].scene, "mix");
  EXPECT_EQ(results.rows[first].scene, "mix@uv8x4");
  EXPECT_EQ(results.rows[first + 4].scene, "mix@uv32x16");
  // On disk, with the run's resolutions in the metadata.
  const auto csv = read_results_csv(options.out_csv);
  ASSERT_EQ(csv.size(), first + 12);
  EXPECT_EQ(csv[first + 1].at("representation"), "uv8x4");
  EXPECT_EQ(csv[first + 1].at("scene"), "mix@uv8x4");
  std::ifstream meta(metadata_path_for(options.out_csv));
  const std::string metadata((std::istreambuf_iterator<char>(meta)), std::istreambuf_iterator<char>());
  EXPECT_NE(metadata.find("tessellate = \"8x4,32x16\""), std::string::npos) << metadata;

  // The same rays and the same referee: what the truth says is the same for
  // every representation; what each answered is its own.
  const std::vector<AccuracyRow> accuracy = read_accuracy_csv(options.accuracy_csv);
  ASSERT_EQ(accuracy.size(), first + 12);
  const auto row = [&](const std::string& scene, const std::string& rayset, const std::string& backend) {
    for (const AccuracyRow& r : accuracy)
      if (r.scene == scene && r.rayset == rayset && r.backend == backend) return r;
    ADD_FAILURE() << "no accuracy row " << scene << " " << rayset << " " << backend;
    return AccuracyRow{};
  };
  for (const char* rayset : {"primary", "shadow"}) {
    const AccuracyRow analytic = row("mix", rayset, "embree");
    EXPECT_EQ(analytic.representation, "analytic");
    if (std::string(rayset) == "primary") EXPECT_GT(analytic.truth_hits, 0.0);
    for (const char* stand_in : {"mix@uv8x4", "mix@uv32x16"}) {
      for (const char* backend : {"embree", "bvh2"}) {
        const AccuracyRow r = row(stand_in, rayset, backend);
        EXPECT_EQ(r.representation, std::string(stand_in).substr(4));
        EXPECT_EQ(r.rays, analytic.rays);
        EXPECT_EQ(r.truth_hits, analytic.truth_hits) << stand_in << " " << rayset;
        EXPECT_EQ(r.ambiguous, analytic.ambiguous) << stand_in << " " << rayset;
        EXPECT_EQ(r.invalid, analytic.invalid);
        EXPECT_GT(r.mrays_s, 0.0);
      }
    }
  }
  EXPECT_EQ(row("floor", "primary", "bvh2").representation, "triangles");
}

TEST(TessellationStudy, ASceneWithoutSpheresHasOneStandInAndNoneWhenTheListIsEmpty) {
  testing::TempDir dir;
  RunOptions options = small_run(dir);
  options.settings.raysets = {"primary"};
  Scene boxes = mixed_scene();
  boxes.name = "boxes";
  boxes.spheres.clear();
  std::set<std::string> scenes;
  for (const ResultRow& r : run_scenes(options, {boxes}).rows) scenes.insert(r.scene + " " + r.representation);
  EXPECT_EQ(scenes, (std::set<std::string>{"boxes analytic", "boxes@uv8x4 uv8x4"}))
      << "boxes are 12 triangles at every resolution: one stand-in, at the first";
  options.settings.tessellate.clear();
  scenes.clear();
  for (const ResultRow& r : run_scenes(options, {mixed_scene()}).rows) scenes.insert(r.scene);
  EXPECT_EQ(scenes, (std::set<std::string>{"mix"}));
}

TEST(TessellationStudy, AStandInBeyondInt32PrimIdsFailsBeforeAnySceneIsMeasured) {
  testing::TempDir dir;
  RunOptions options = small_run(dir);
  options.settings.tessellate = {{16, 8}, {kMaxTessellation, kMaxTessellation}};
  Scene many;
  many.name = "many";
  many.spheres.assign(65, Sphere{{0, 0, 0}, 1.0f});
  Scene first = mixed_scene();  // measured first were the check late
  const std::string message = testing::input_error_of([&] { run_scenes(options, {first, many}); });
  EXPECT_NE(message.find("scene 'many': its uv4096x4096 stand-in would have"), std::string::npos) << message;
  EXPECT_FALSE(testing::exists(options.out_csv)) << "nothing measured, nothing written";
}

}  // namespace
}  // namespace raybench
