// The accuracy report, specified: how a backend's answers are judged against
// the referee, that the stability sweep is leak-free for the watertight
// configuration at every scale and offset, and that the report keeps its
// power to detect (a seed-faithful kernel's known failure shows as an error).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "accuracy/accuracy_csv.h"
#include "accuracy/judge.h"
#include "backends/backend.h"
#include "build_info.h"
#include "rays/rayset.h"
#include "referee/referee.h"
#include "suite/suite.h"
#include "suite/suite_run.h"
#include "test_util.h"
#include "measure/trace.h"

namespace raybench {
namespace {

Ray down_from(float x, float y) {
  Ray r;
  r.org = {x, y, 1.0f};
  r.dir = {0, 0, -1};
  return r;
}

Scene pair_and_floor() {
  Scene s;
  s.name = "pair";
  s.triangles = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},      // 0
                 {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}},      // 1, sharing the edge (1,0)-(0,1)
                 {{-5, -5, -1}, {5, -5, -1}, {0, 5, -1}}};  // 2, a floor below both
  return s;
}

TEST(UlpError, IsMeasuredInFloatSpacingsAtTheExactT) {
  EXPECT_EQ(ulp_error(1.0f, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(ulp_error(std::nextafter(1.0f, 2.0f), 1.0), 1.0);
  EXPECT_DOUBLE_EQ(ulp_error(1.0f, 1.0 + std::ldexp(1.0, -24)), 0.5);
  EXPECT_DOUBLE_EQ(ulp_error(1024.0f, 1024.0 + 3.0 * std::ldexp(1.0, -13)), 3.0);
}

TEST(Judge, CountsEachKindOfErrorAgainstTheReferee) {
  const Scene scene = pair_and_floor();
  const Referee referee(scene);
  const std::vector<Ray> rays = {
      down_from(0.25f, 0.25f),  // truth: prim 0 at t = 1; answered right
      down_from(0.25f, 0.25f),  // truth: prim 0; answered as a miss (false miss)
      down_from(3.0f, 3.0f),    // truth: a miss (the floor ends at y = 5 - x); answered as a hit (false hit)
      down_from(0.75f, 0.6f),   // truth: prim 1; answered prim 2, the floor behind (wrong triangle)
      down_from(0.5f, 0.5f),    // truth: a tie of 0 and 1 on the shared edge; answered 1: right
  };
  std::vector<RefereeVerdict> truth(rays.size());
  referee.judge(rays, truth);
  ASSERT_FALSE(truth[2].hit());
  const std::vector<Hit> hits = {{1.0f, 0, 0.25f, 0.25f}, {}, {2.0f, 2, 0, 0}, {2.0f, 2, 0, 0}, {std::nextafter(1.0f, 2.0f), 1, 0, 0}};
  AccuracyRow row;
  judge_hits(referee, rays, truth, hits, {}, row);
  EXPECT_EQ(row.rays, 5u);
  EXPECT_DOUBLE_EQ(row.truth_hits, 4.0 / 5);
  EXPECT_DOUBLE_EQ(row.false_miss, 1.0 / 5);
  EXPECT_DOUBLE_EQ(row.false_hit, 1.0 / 5);
  EXPECT_DOUBLE_EQ(row.wrong_prim, 1.0 / 5);
  EXPECT_DOUBLE_EQ(row.ambiguous, 1.0 / 5);  // the tie
  EXPECT_TRUE(std::isnan(row.self_hits));    // no sources: not secondary rays
  // t errors over the rays answered right: 0 ulp and 1 ulp.
  EXPECT_DOUBLE_EQ(row.ulp_p50, 0.0);
  EXPECT_DOUBLE_EQ(row.ulp_max, 1.0);
  // And in relative terms, |t - t_exact| / t_exact: one ulp above 1 is 2^-23.
  EXPECT_DOUBLE_EQ(row.t_relerr_max, std::ldexp(1.0, -23));
  EXPECT_DOUBLE_EQ(row.t_relerr_p99, std::ldexp(1.0, -23));
}

TEST(Judge, ASecondaryRayHittingItsOwnTriangleIsASelfIntersection) {
  const Scene scene = pair_and_floor();
  const Referee referee(scene);
  // Leaving prim 2 (the floor) upwards: the truth is prim 0 at t = 1.
  Ray up;
  up.org = {0.25f, 0.25f, -1.0f};
  up.dir = {0, 0, 1};
  const std::vector<Ray> rays = {up, up};
  std::vector<RefereeVerdict> truth(2);
  referee.judge(rays, truth);
  const std::vector<Hit> hits = {{0.0f, 2, 0, 0}, {1.0f, 0, 0, 0}};
  const std::vector<std::int32_t> sources = {2, 2};
  AccuracyRow row;
  judge_hits(referee, rays, truth, hits, sources, row);
  EXPECT_DOUBLE_EQ(row.self_hits, 0.5);
  EXPECT_DOUBLE_EQ(row.wrong_prim, 0.5);
}

// pair_and_floor with a sphere (prim 3) and a box (prim 4) above the floor.
Scene pair_floor_sphere_box() {
  Scene s = pair_and_floor();
  s.spheres = {{{-2, -2, 0}, 0.5f}};
  s.boxes = {{{2, -3, -0.5f}, {3, -2, 0.5f}}};
  return s;
}

TEST(Judge, AnalyticHitsAreJudgedAsTrianglesAre) {
  const Scene scene = pair_floor_sphere_box();
  const Referee referee(scene);
  const std::vector<Ray> rays = {
      down_from(-2, -2),     // truth: the sphere's top at t = 0.5; answered right
      down_from(-2, -2),     // the same, answered 3 float ulps late
      down_from(2.5f, -2.5f),  // truth: the box's top at t = 0.5; answered as a miss (false miss)
      down_from(2.5f, -2.5f),  // answered the floor behind it (wrong primitive)
      down_from(4, 4),       // truth: a miss; answered the sphere (false hit)
      down_from(0.75f, 0.6f),  // truth: triangle 1; answered the box (wrong primitive)
  };
  std::vector<RefereeVerdict> truth(rays.size());
  referee.judge(rays, truth);
  ASSERT_EQ(truth[0].prim, 3);
  ASSERT_EQ(truth[2].prim, 4);
  ASSERT_FALSE(truth[4].hit());
  const float late = std::nextafter(std::nextafter(std::nextafter(0.5f, 1.0f), 1.0f), 1.0f);
  const std::vector<Hit> hits = {{0.5f, 3, 0, 0}, {late, 3, 0, 0}, {}, {2.0f, 2, 0, 0}, {1.0f, 3, 0, 0}, {1.0f, 4, 0, 0}};
  AccuracyRow row;
  judge_hits(referee, rays, truth, hits, {}, row);
  EXPECT_DOUBLE_EQ(row.truth_hits, 5.0 / 6);
  EXPECT_DOUBLE_EQ(row.false_miss, 1.0 / 6);
  EXPECT_DOUBLE_EQ(row.false_hit, 1.0 / 6);
  EXPECT_DOUBLE_EQ(row.wrong_prim, 2.0 / 6);
  EXPECT_DOUBLE_EQ(row.ambiguous, 0.0);
  EXPECT_DOUBLE_EQ(row.ulp_p50, 0.0);
  EXPECT_DOUBLE_EQ(row.ulp_max, 3.0);  // in float ulps at t = 0.5
}

TEST(Judge, ASecondaryRayHittingItsOwnSphereAgainIsASelfIntersection) {
  const Scene scene = pair_floor_sphere_box();
  const Referee referee(scene);
  // Leaving the sphere's bottom downwards (just below it): the truth is the
  // floor at z = -1. Answering the sphere itself is a self-intersection.
  Ray down = down_from(-2, -2);
  down.org.z = std::nextafter(-0.5f, -1.0f);
  // Leaving its side outwards and back through it: the sphere is the truth, no self-hit.
  Ray back;
  back.org = {-2.75f, -2, 0};
  back.dir = {1, 0, 0};
  const std::vector<Ray> rays = {down, down, back};
  std::vector<RefereeVerdict> truth(rays.size());
  referee.judge(rays, truth);
  ASSERT_EQ(truth[0].prim, 2);
  ASSERT_EQ(truth[2].prim, 3);
  const std::vector<Hit> hits = {{1e-7f, 3, 0, 0}, {0.5f, 2, 0, 0}, {0.25f, 3, 0, 0}};
  const std::vector<std::int32_t> sources = {3, 3, 3};
  AccuracyRow row;
  judge_hits(referee, rays, truth, hits, sources, row);
  EXPECT_DOUBLE_EQ(row.self_hits, 1.0 / 3);
  EXPECT_DOUBLE_EQ(row.wrong_prim, 1.0 / 3);
}

TEST(Judge, OcclusionCanOnlyBeWrongAboutHitOrMiss) {
  const Scene scene = pair_and_floor();
  const Referee referee(scene);
  const std::vector<Ray> rays = {down_from(0.25f, 0.25f), down_from(3.0f, 3.0f)};
  std::vector<RefereeVerdict> truth(2);
  referee.judge(rays, truth);
  AccuracyRow row;
  judge_occlusion(rays, truth, std::vector<std::uint8_t>{0, 1}, row);
  EXPECT_DOUBLE_EQ(row.false_miss, 0.5);
  EXPECT_DOUBLE_EQ(row.false_hit, 0.5);
  EXPECT_EQ(row.wrong_prim, 0.0);
}

TEST(AccuracyCsv, RoundTripsAndRejectsABadNumber) {
  testing::TempDir dir;
  AccuracyRow r;
  r.scene = "sphere@s1e-06";
  r.scale = 1e-6;
  r.offset_x = 148376;
  r.rayset = "vertex-aimed";
  r.query = "intersect";
  r.backend = "bvh2:watertight";
  r.accuracy_class = "watertight";
  r.rays = 100;
  r.false_miss = 0.25;
  r.mrays_s = 3.5;
  write_accuracy_csv(dir.file("a.csv"), {r});
  const std::vector<AccuracyRow> back = read_accuracy_csv(dir.file("a.csv"));
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].scene, r.scene);
  EXPECT_EQ(back[0].scale, 1e-6);
  EXPECT_EQ(back[0].offset_x, 148376);
  EXPECT_EQ(back[0].false_miss, 0.25);
  EXPECT_TRUE(std::isnan(back[0].self_hits));
  std::ofstream(dir.file("bad.csv")) << fmt::format("{}\n", fmt::join(accuracy_columns(), ",")) << "s,x"
                                     << std::string(accuracy_columns().size() - 2, ',') << "\n";
  EXPECT_NE(testing::input_error_of([&] { read_accuracy_csv(dir.file("bad.csv")); }).find("not a number"), std::string::npos);
}

// Issue 31: a stand-in's rows say what was traced and how far its depths lie
// from the exact ones; files written before these columns still read.
TEST(AccuracyCsv, TheRepresentationAndRelativeTErrorRoundTripAndOlderFilesRead) {
  testing::TempDir dir;
  AccuracyRow r;
  r.scene = "balls@uv8x4";
  r.rayset = "primary";
  r.query = "intersect";
  r.backend = "bvh2";
  r.rays = 10;
  r.t_relerr_p99 = 0.015;
  r.t_relerr_max = 0.0625;
  r.representation = "uv8x4";
  write_accuracy_csv(dir.file("a.csv"), {r});
  const std::vector<std::string>& columns = accuracy_columns();
  ASSERT_GE(columns.size(), 3u);
  EXPECT_EQ(columns[columns.size() - 3], "t_relerr_p99");
  EXPECT_EQ(columns[columns.size() - 2], "t_relerr_max");
  EXPECT_EQ(columns.back(), "representation");
  const std::vector<AccuracyRow> back = read_accuracy_csv(dir.file("a.csv"));
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].representation, "uv8x4");
  EXPECT_EQ(back[0].t_relerr_p99, 0.015);
  EXPECT_EQ(back[0].t_relerr_max, 0.0625);
  // The schema up to mrays_s_max, as results/accuracy.csv was written before issue 31.
  const std::vector<std::string> old_columns(columns.begin(), columns.end() - 3);
  std::vector<std::string> fields(old_columns.size(), "");
  fields[0] = "sphere";
  for (const char* c : {"scale", "rays"}) fields[std::find(old_columns.begin(), old_columns.end(), c) - old_columns.begin()] = "1";
  std::ofstream(dir.file("old.csv")) << fmt::format("{}\n{}\n", fmt::join(old_columns, ","), fmt::join(fields, ","));
  const std::vector<AccuracyRow> old = read_accuracy_csv(dir.file("old.csv"));
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].scene, "sphere");
  EXPECT_EQ(old[0].representation, "");
  EXPECT_TRUE(std::isnan(old[0].t_relerr_max));
  // An older column is still required.
  std::ofstream(dir.file("broken.csv")) << "scene,rays\nsphere,1\n";
  EXPECT_NE(testing::input_error_of([&] { read_accuracy_csv(dir.file("broken.csv")); }).find("missing column"),
            std::string::npos);
}

// Issue 5: "The watertight triangle test and robust traversal leak no ray
// fired from inside a closed mesh, at every scale and offset of the sweep."
TEST(StabilitySweep, WatertightWithRobustTraversalLeaksNothingAtEveryScaleAndOffset) {  // bvh2 and bvh8
  const Suite suite = load_suite(std::string(RAYBENCH_SOURCE_DIR) + "/meshes/accuracy.toml");
  std::size_t swept = 0;
  double smallest = 1e300, largest = 0, farthest = 0;
  for (const SuiteScene& entry : suite.scenes) {
    if (entry.name.find('@') == std::string::npos) continue;
    ++swept;
    smallest = std::min(smallest, entry.scale);
    largest = std::max(largest, entry.scale);
    farthest = std::max(farthest, std::fabs(entry.offset[0]));
    ASSERT_TRUE(entry.inside.has_value()) << entry.name;
    const Scene scene = load_suite_scene(entry);
    const RayGenerator generator(scene);
    const Referee referee(scene);
    for (const char* name : {"bvh2:watertight", "bvh8:watertight"}) {
    const auto backend = make_backend(name);
    backend->build(scene);
    for (RaySetKind kind : {RaySetKind::kClosedInsideRandom, RaySetKind::kSharedEdgeAimed, RaySetKind::kVertexAimed}) {
      RaySetSpec spec;
      spec.kind = kind;
      spec.count = 1500;
      spec.inside = entry.inside;
      const std::vector<Ray> rays = generator.generate(spec);
      std::vector<Hit> hits(rays.size());
      backend->intersect(rays, hits);
      std::size_t leaks = 0, truth_misses = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        leaks += !hits[i].hit();
        truth_misses += !referee.judge(rays[i]).hit();
      }
      EXPECT_EQ(truth_misses, 0u) << entry.name << " " << to_string(kind) << ": the ball must be inside the mesh";
      EXPECT_EQ(leaks, 0u) << name << " on " << entry.name << " " << to_string(kind);
    }
    }
  }
  EXPECT_GE(swept, 16u);
  EXPECT_EQ(smallest, 1e-6);
  EXPECT_EQ(largest, 1e6);
  EXPECT_EQ(farthest, 1e7);
}

// The report keeps its power to detect: a small accuracy run in which the
// triangle seed's det < 1e-4 rejection hides tiny triangles (G05), Embree's
// default mode leaks through shared edges (G02), and the referee, judged
// against itself, makes no error.
TEST(AccuracyRun, SeedFailuresAndEmbreeLeaksAppearTheRefereeIsClean) {
  testing::TempDir dir;
  const std::string manifest = dir.write("acc.toml", R"(
[defaults]
rays = 4096
backends = ["embree", "bvh2:mt_seed", "bvh2:watertight", "reference"]
repetitions = 1
build_repetitions = 1
min_time = 0.001
warmup = 0.0
[[scene]]
name = "tiny"
path = "proc:tiny_triangles"
raysets = ["tiny-triangles", "invalid-rays"]
[[scene]]
name = "sphere"
path = "proc:sphere"
inside = { center = [0.0, 0.0, 0.0], radius = 0.9 }
raysets = ["shared-edge-aimed"]
)");
  RunOptions options;
  options.suite = load_suite(manifest);
  options.settings = options.suite.settings;
  options.out_csv = dir.file("run.csv");
  options.rays_dir = dir.file("rays");
  options.accuracy_csv = dir.file("accuracy.csv");
  run_suite(options);
  const std::vector<AccuracyRow> rows = read_accuracy_csv(options.accuracy_csv);
  ASSERT_EQ(rows.size(), 3u * 4u);
  const auto row = [&](const std::string& scene, const std::string& rayset, const std::string& backend) {
    for (const AccuracyRow& r : rows)
      if (r.scene == scene && r.rayset == rayset && r.backend == backend) return r;
    ADD_FAILURE() << "no row " << scene << " " << rayset << " " << backend;
    return AccuracyRow{};
  };
  const AccuracyRow seed = row("tiny", "tiny-triangles", "bvh2:mt_seed");
  EXPECT_GT(seed.truth_hits, 0.3);
  EXPECT_GT(seed.false_miss, 0.9 * seed.truth_hits) << "det < 1e-4 hides triangles with legs below 5e-3";
  EXPECT_EQ(seed.accuracy_class, "epsilon");
  EXPECT_GT(row("sphere", "shared-edge-aimed", "embree").false_miss, 0.0);
  EXPECT_EQ(row("sphere", "shared-edge-aimed", "bvh2:watertight").false_miss, 0.0);
  for (const AccuracyRow& r : rows) {
    EXPECT_GT(r.mrays_s, 0.0) << r.backend;
    if (r.rayset == "invalid-rays") {
      EXPECT_GT(r.invalid, 0.8);
      EXPECT_EQ(r.false_hit, 0.0) << r.backend << " must answer invalid rays as misses";
    }
    if (r.backend == "reference") {
      EXPECT_EQ(r.error_rate(), 0.0) << r.scene << " " << r.rayset;
      EXPECT_EQ(r.accuracy_class, "exact");
      if (!std::isnan(r.ulp_max)) {
        EXPECT_LE(r.ulp_max, 0.5) << "the float nearest the exact t";
      }
    }
  }
}

}  // namespace
}  // namespace raybench
