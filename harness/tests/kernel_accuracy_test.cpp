// Specification of `raybench accuracy-kernels` (accuracy/kernel_accuracy.h,
// accuracy/prim_raysets.h): the rows it produces must show each seed note's
// known failure (../shared/EXTREMES.md, "What the four seed notes get wrong")
// as a non-zero error, and the fixed variants must show none where the
// catalogue's pass/fail property says so. Runs every family on 256 rays per
// set, one timed repetition: about a second.
#include "accuracy/kernel_accuracy.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "accuracy/prim_raysets.h"
#include "raybench/variants.h"
#include "io/npy.h"
#include "test_util.h"

namespace raybench {
namespace {

constexpr std::size_t kRays = 256;

const std::vector<AccuracyRow>& all_rows() {
  static const std::vector<AccuracyRow> rows = [] {
    KernelAccuracyOptions o;
    o.rays = kRays;
    o.seed = 1;
    o.repetitions = 1;
    return run_kernel_accuracy(o);
  }();
  return rows;
}

// The row of (scene, rayset, variant); fails the test when there is none.
const AccuracyRow& row(const std::string& scene, const std::string& rayset, const std::string& variant) {
  for (const AccuracyRow& r : all_rows())
    if (r.scene == scene && r.rayset == rayset && r.backend == "kernel:" + variant) return r;
  ADD_FAILURE() << "no row " << scene << "/" << rayset << "/kernel:" << variant;
  static const AccuracyRow none;
  return none;
}

double errors(const AccuracyRow& r) { return r.false_miss + r.false_hit; }

std::vector<std::string> names_of_fixed(const std::string& scene) {
  if (scene == "prim:box") return {"slab", "slab_robust"};
  if (scene == "prim:obb") return {"obb"};
  if (scene == "prim:sphere") return {"sphere_precise", "sphere_quadratic"};
  return {"mt", "watertight", "baldwin_weber", "mt_double"};
}

TEST(KernelAccuracy, OneRowPerRaySetAndVariantInTheSchema) {
  std::size_t variants = 0;
  for_each_variant<BoxTests>([&](auto) { variants += box_raysets(1, 1).size(); });
  for_each_variant<ObbTests>([&](auto) { variants += obb_raysets(1, 1).size(); });
  for_each_variant<SphereTests>([&](auto) { variants += sphere_raysets(1, 1).size(); });
  for_each_variant<TriangleTests>([&](auto) { variants += triangle_raysets(1, 1).size(); });
  EXPECT_EQ(all_rows().size(), variants);
  for (const AccuracyRow& r : all_rows()) {
    SCOPED_TRACE(r.scene + "/" + r.rayset + "/" + r.backend);
    EXPECT_EQ(r.rays, kRays);
    EXPECT_EQ(r.query, "intersect");
    EXPECT_EQ(r.backend.rfind("kernel:", 0), 0u);
    EXPECT_TRUE(r.accuracy_class == "epsilon" || r.accuracy_class == "fast" || r.accuracy_class == "watertight" ||
                r.accuracy_class == "conservative" || r.accuracy_class == "reference");
    EXPECT_EQ(r.wrong_prim, 0.0);
    EXPECT_GE(r.false_miss, 0.0);
    EXPECT_LE(r.false_miss, r.truth_hits);  // only rays that hit can be missed
    EXPECT_LE(r.false_hit, 1.0 - r.truth_hits);
    EXPECT_GT(r.mrays_s, 0.0);
    EXPECT_LE(r.mrays_s_min, r.mrays_s);
    EXPECT_GE(r.mrays_s_max, r.mrays_s);
  }
  EXPECT_EQ(row("prim:sphere", "far-small-sphere:D=1e3", "sphere_seed").accuracy_class, "epsilon");
  EXPECT_EQ(row("prim:box", "control-random", "slab_robust").accuracy_class, "conservative");
}

TEST(KernelAccuracy, RaySetsAreStoredAsNpyLikeEveryRaySet) {
  testing::TempDir dir;
  KernelAccuracyOptions o;
  o.rays = 64;
  o.repetitions = 1;
  o.filter = "prim:sphere/origin-inside/kernel:sphere_seed";
  o.rays_dir = dir.file("rays");
  run_kernel_accuracy(o);
  const std::string base = dir.file("rays/prim_sphere.origin-inside.n64.seed1");
  const std::vector<Ray> rays = read_ray_file(base + ".rays.npy");
  const std::vector<PrimRaySet<Sphere>> sets = sphere_raysets(64, 1);
  const auto set = std::find_if(sets.begin(), sets.end(), [](const auto& s) { return s.rayset == "origin-inside"; });
  ASSERT_NE(set, sets.end());
  ASSERT_EQ(rays.size(), set->rays.size());
  EXPECT_EQ(std::memcmp(rays.data(), set->rays.data(), rays.size() * sizeof(Ray)), 0);
  std::size_t n = 0, columns = 0;
  const std::vector<double> prims = read_npy_f64(base + ".prims.npy", n, columns);
  ASSERT_EQ(n, 64u);
  ASSERT_EQ(columns, 4u);  // centre xyz, radius
  EXPECT_EQ(static_cast<float>(prims[3]), set->prims[0].radius);
  EXPECT_EQ(static_cast<float>(prims[4 * 63]), set->prims[63].center.x);
}

// --- G15: every seed hits invalid rays; no fixed variant does -----------------

TEST(KernelAccuracy, EverySeedHitsInvalidRays) {
  for (const auto& [scene, seed] : std::map<std::string, std::string>{{"prim:box", "slab_seed"},
                                                                      {"prim:obb", "obb_seed"},
                                                                      {"prim:sphere", "sphere_seed"},
                                                                      {"prim:triangle", "mt_seed"}}) {
    SCOPED_TRACE(scene);
    const AccuracyRow& r = row(scene, "invalid-rays", seed);
    EXPECT_GT(r.invalid, 0.85);     // 24 of the 27 cases are no ray at all
    EXPECT_EQ(r.truth_hits, 0.0);   // and the other three have empty intervals
    EXPECT_GT(r.false_hit, 0.2);
    for (const std::string& fixed : names_of_fixed(scene)) EXPECT_EQ(row(scene, "invalid-rays", fixed).false_hit, 0.0) << fixed;
  }
}

// --- Boxes --------------------------------------------------------------------

TEST(KernelAccuracy, BoxSignedZeroErrorsAreOnlyTheTnearPolicy) {
  // G09: no box test misses a ray the closed box holds, and every extra hit
  // is a ray touching the box at t = 0 only (ambiguous: the box tests' closed
  // [tnear, tmax] against raybench's (max(tnear,0), tfar]).
  for (const std::string v : {"slab", "slab_seed", "slab_robust"}) {
    const AccuracyRow& r = row("prim:box", "axis-parallel-signed-zero", v);
    EXPECT_GT(r.ambiguous, 0.1) << v;
    EXPECT_GT(r.truth_hits, 0.1) << v;
    EXPECT_EQ(r.false_miss, 0.0) << v;
    EXPECT_EQ(r.false_hit, r.ambiguous) << v;
  }
}

// The G09 twins differ only in the sign of their zero direction components:
// the answer (hit, and t) must be identical (EXTREMES.md G09).
template <typename Prim, typename Run>
void expect_twins_agree(const PrimRaySet<Prim>& set, Run&& run, std::string_view variant) {
  ASSERT_EQ(set.rayset, "axis-parallel-signed-zero");
  std::size_t twins_with_zeros = 0;
  for (std::size_t i = 0; i + 1 < set.rays.size(); i += 2) {
    const Ray &a = set.rays[i], &b = set.rays[i + 1];
    ASSERT_EQ(std::memcmp(&set.prims[i], &set.prims[i + 1], sizeof(Prim)), 0);
    bool zero = false;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(a.dir[k], b.dir[k]);  // as numbers; only zero signs differ
      if (a.dir[k] == 0.0f) {
        zero = true;
        ASSERT_NE(std::signbit(a.dir[k]), std::signbit(b.dir[k]));
      }
    }
    twins_with_zeros += zero;
    BoxHit ha{-1, -1}, hb{-1, -1};
    const bool hit_a = run(a, set.prims[i], ha), hit_b = run(b, set.prims[i + 1], hb);
    EXPECT_EQ(hit_a, hit_b) << variant << " twin " << i;
    if (hit_a && hit_b) {
      EXPECT_EQ(ha.t_entry, hb.t_entry) << variant << " twin " << i;
      EXPECT_EQ(ha.t_exit, hb.t_exit) << variant << " twin " << i;
    }
  }
  // 18 of the 26 direction patterns have a zero component.
  EXPECT_GT(twins_with_zeros, set.rays.size() / 2 / 2);
}

TEST(KernelAccuracy, SignOfZeroNeverChangesABoxTest) {
  const PrimRaySet<BBox> set = box_raysets(kRays, 1).at(0);
  for_each_variant<BoxTests>([&](auto v) {
    using V = decltype(v);
    expect_twins_agree(set, [](const Ray& r, const BBox& b, BoxHit& h) { return V::intersect(V::precompute(r), b, r.tfar, h); },
                       V::name);
  });
}

TEST(KernelAccuracy, SignOfZeroNeverChangesAnObbTest) {
  const PrimRaySet<OrientedBox> set = obb_raysets(kRays, 1).at(0);
  for_each_variant<ObbTests>([&](auto v) {
    using V = decltype(v);
    expect_twins_agree(set, [](const Ray& r, const OrientedBox& b, BoxHit& h) { return V::intersect(r, r.tfar, b, h); },
                       V::name);
  });
}

TEST(KernelAccuracy, EveryBoxTestHitsFromInside) {
  // G10: an origin inside the box is a hit, t the exit, for every variant.
  for (const std::string v : {"slab", "slab_seed", "slab_robust"}) {
    const AccuracyRow& r = row("prim:box", "origin-inside", v);
    EXPECT_EQ(r.truth_hits, 1.0);
    EXPECT_EQ(errors(r), 0.0) << v;
    EXPECT_LT(r.ulp_max, v == "slab_robust" ? 16.0 : 4.0) << v;  // slab_robust pads the exit by 8 ulps (2^-21)
  }
  for (const std::string v : {"obb", "obb_seed"}) EXPECT_EQ(errors(row("prim:obb", "origin-inside", v)), 0.0) << v;
}

TEST(KernelAccuracy, ObbSeedMissesWhereTheOthersTouchOnTheSurface) {
  // G11, outward from a face: the OBB note starts minT at DBL_MIN and misses
  // the rays that touch the box at t = 0 only; obb (closed [tnear, tmax]) and
  // the AABB note hit them. The referee, open at t = 0, counts them as misses
  // and as ambiguous: the notes disagree by policy (EXTREMES.md G11).
  const AccuracyRow& obb = row("prim:obb", "origin-on-surface:outward", "obb");
  const AccuracyRow& seed = row("prim:obb", "origin-on-surface:outward", "obb_seed");
  EXPECT_GT(obb.ambiguous, 0.2);
  EXPECT_GE(obb.false_hit, obb.ambiguous);
  EXPECT_LT(seed.false_hit, 0.1 * obb.ambiguous);
  EXPECT_GE(row("prim:box", "origin-on-surface:outward", "slab_seed").false_hit,
            row("prim:box", "origin-on-surface:outward", "slab_seed").ambiguous);
  // Inward, every variant hits.
  for (const std::string v : {"obb", "obb_seed"}) EXPECT_EQ(row("prim:obb", "origin-on-surface:inward", v).false_miss, 0.0);
  for (const std::string v : {"slab", "slab_seed", "slab_robust"})
    EXPECT_EQ(row("prim:box", "origin-on-surface:inward", v).false_miss, 0.0);
}

TEST(KernelAccuracy, DirectionLengthOnlyMattersToTheSeeds) {
  // G16: the five lengths are the same geometric rays (exact powers of two),
  // so the truth is identical; the epsilon-free variants keep hit/miss, the
  // AABB and OBB notes' absolute thresholds (1e-6, 1e-20) drop hits.
  for (const std::string scene : {"prim:box", "prim:obb", "prim:sphere", "prim:triangle"}) {
    const double truth = row(scene, "direction-scaling:|d|=1", names_of_fixed(scene)[0]).truth_hits;
    EXPECT_GT(truth, 0.2) << scene;
    for (const std::string len : {"1e-20", "1e-7", "1", "1e7", "1e20"})
      EXPECT_EQ(row(scene, "direction-scaling:|d|=" + len, names_of_fixed(scene)[0]).truth_hits, truth) << scene << len;
  }
  for (const std::string len : {"1e-20", "1e-7", "1", "1e7", "1e20"}) {
    for (const std::string v : {"slab", "slab_robust"}) EXPECT_EQ(errors(row("prim:box", "direction-scaling:|d|=" + len, v)), 0.0);
    EXPECT_EQ(errors(row("prim:obb", "direction-scaling:|d|=" + len, "obb")), 0.0) << len;
  }
  EXPECT_GT(row("prim:box", "direction-scaling:|d|=1e-7", "slab_seed").false_miss, 0.2);
  EXPECT_GT(row("prim:obb", "direction-scaling:|d|=1e-20", "obb_seed").false_miss, 0.2);
  EXPECT_GT(row("prim:triangle", "direction-scaling:|d|=1e-7", "mt_seed").false_miss, 0.1);  // det < 1e-4
  EXPECT_GT(errors(row("prim:sphere", "direction-scaling:|d|=1e7", "sphere_seed")), 0.1);    // assumes |d| = 1
  EXPECT_EQ(errors(row("prim:sphere", "direction-scaling:|d|=1e-7", "sphere_precise")), 0.0);
  EXPECT_EQ(errors(row("prim:sphere", "direction-scaling:|d|=1e7", "sphere_precise")), 0.0);
}

// --- Spheres --------------------------------------------------------------------

TEST(KernelAccuracy, SphereSeedMissesFromInside) {
  // G10: seed 003's `projoc < 0` rejects every ray whose centre is behind
  // its origin, about half of those starting inside.
  EXPECT_EQ(row("prim:sphere", "origin-inside", "sphere_seed").truth_hits, 1.0);
  EXPECT_GT(row("prim:sphere", "origin-inside", "sphere_seed").false_miss, 0.3);
  for (const std::string v : {"sphere_precise", "sphere_quadratic"}) {
    const AccuracyRow& r = row("prim:sphere", "origin-inside", v);
    EXPECT_EQ(errors(r), 0.0) << v;
    EXPECT_LT(r.ulp_p99, 16.0) << v;
  }
}

TEST(KernelAccuracy, FarSmallSphereLosesTheSeedNotHaines) {
  // G12: seed 003 and the textbook quadratic cancel |oc|^2 - (oc.d)^2; Haines
  // et al.'s form (sphere_precise) keeps hit/miss to ~1e6 (EXTREMES.md).
  EXPECT_GT(errors(row("prim:sphere", "far-small-sphere:D=1e4", "sphere_seed")), 0.2);
  EXPECT_GT(errors(row("prim:sphere", "far-small-sphere:D=1e4", "sphere_quadratic")), 0.2);
  for (const std::string d : {"1e2", "1e3", "1e4", "1e5"})
    EXPECT_LT(errors(row("prim:sphere", "far-small-sphere:D=" + d, "sphere_precise")), 0.01) << d;
}

TEST(KernelAccuracy, TinySphereCollapsesInTheSeed) {
  // G13: below r = 3.4e-4 the seed's FLOAT_EPSILON makes every hit a tangent
  // at the centre's projection: the near root is off by about r, hundreds of
  // float ulps at distance 1-10; Haines et al. stay within a few ulps.
  const AccuracyRow& seed = row("prim:sphere", "tiny-sphere:r=1e-4", "sphere_seed");
  const AccuracyRow& precise = row("prim:sphere", "tiny-sphere:r=1e-4", "sphere_precise");
  EXPECT_GT(seed.ulp_p50, 100.0);
  EXPECT_LT(precise.ulp_p50, 4.0);
  EXPECT_GT(errors(seed), errors(precise));
}

// --- Triangles -------------------------------------------------------------------

TEST(KernelAccuracy, TriangleSeedHitsBehindAndMissesTinyTriangles) {
  // G14: seed 002 never checks t >= 0; G05: its det < 1e-4 hides legs <= 5e-3.
  EXPECT_EQ(row("prim:triangle", "behind-origin", "mt_seed").truth_hits, 0.0);
  EXPECT_GT(row("prim:triangle", "behind-origin", "mt_seed").false_hit, 0.9);
  EXPECT_GT(row("prim:triangle", "tiny-triangles:leg=1e-3", "mt_seed").false_miss, 0.9);
  EXPECT_GT(row("prim:triangle", "grazing:a=1e-5", "mt_seed").false_miss, 0.5);  // det shrinks with the angle
  for (const std::string& v : names_of_fixed("prim:triangle")) {
    EXPECT_EQ(row("prim:triangle", "behind-origin", v).false_hit, 0.0) << v;
    for (const std::string leg : {"1e-3", "1e-5", "1e-7"})
      EXPECT_EQ(errors(row("prim:triangle", "tiny-triangles:leg=" + leg, v)), 0.0) << v << leg;
    EXPECT_EQ(errors(row("prim:triangle", "grazing:a=1e-4", v)), 0.0) << v;
  }
}

TEST(KernelAccuracy, DegenerateAndCoplanarTrianglesAreNeverHitByTheReference) {
  // G08 (a), (b) and G19: the referee never hits them; mt_double, the
  // reference variant, neither; the seed hits the collinear one (EXTREMES.md: 18 %).
  for (const std::string set : {"degenerate-triangles:collinear", "degenerate-triangles:repeated", "coplanar"}) {
    EXPECT_EQ(row("prim:triangle", set, "mt_double").truth_hits, 0.0) << set;
    EXPECT_EQ(row("prim:triangle", set, "mt_double").false_hit, 0.0) << set;
  }
  EXPECT_GT(row("prim:triangle", "degenerate-triangles:collinear", "mt_seed").false_hit, 0.05);
}

// --- Ray sets and options --------------------------------------------------------

TEST(KernelAccuracy, RaySetsAreDeterministic) {
  const auto a = sphere_raysets(64, 7), b = sphere_raysets(64, 7), c = sphere_raysets(64, 8);
  ASSERT_EQ(a.size(), b.size());
  bool differs = false;
  for (std::size_t s = 0; s < a.size(); ++s) {
    ASSERT_EQ(a[s].rays.size(), 64u);
    for (std::size_t i = 0; i < a[s].rays.size(); ++i) {
      EXPECT_EQ(std::memcmp(&a[s].rays[i], &b[s].rays[i], sizeof(Ray)), 0) << a[s].rayset << " " << i;
      differs = differs || std::memcmp(&a[s].rays[i], &c[s].rays[i], sizeof(Ray)) != 0;
    }
  }
  EXPECT_TRUE(differs);  // the seed matters
}

TEST(KernelAccuracy, WritesTheAccuracyCsv) {
  testing::TempDir dir;
  KernelAccuracyOptions o;
  o.out_csv = dir.file("accuracy-kernels.csv");
  o.filter = "prim:sphere/origin-inside/";
  o.rays = 32;
  o.repetitions = 1;
  const std::vector<AccuracyRow> rows = run_kernel_accuracy(o);
  ASSERT_EQ(rows.size(), 3u);  // the three sphere variants
  const std::vector<AccuracyRow> back = read_accuracy_csv(o.out_csv);
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back[i].backend, rows[i].backend);
    EXPECT_EQ(back[i].rayset, "origin-inside");
    EXPECT_EQ(back[i].rays, 32u);
    EXPECT_NEAR(back[i].false_miss, rows[i].false_miss, 1e-5);
  }
  EXPECT_TRUE(testing::exists(dir.file("accuracy-kernels.meta.toml")));
}

TEST(KernelAccuracy, BadOptionsAreOneLineErrors) {
  KernelAccuracyOptions o;
  o.filter = "no-such-set";
  EXPECT_NE(testing::input_error_of([&] { run_kernel_accuracy(o); }).find("--filter 'no-such-set' matches no"),
            std::string::npos);
  o.filter = "";
  o.rays = 0;
  EXPECT_NE(testing::input_error_of([&] { run_kernel_accuracy(o); }).find("--rays"), std::string::npos);
}

}  // namespace
}  // namespace raybench
