// Specification of our BVHs over mixed primitive types (bvh/mixed_bvh2.h,
// bvh/mixed_wide_bvh.h, bvh/mixed_leaf.h): every primitive is in one leaf
// under a box that holds it, and the traversals answer exactly as testing
// every primitive with the same tests does (prim/analytic_hit.h for the
// analytic ones), closest hit and any hit, on random rays and on the hard
// ones: starting inside spheres, boxes and oriented boxes, tangent to
// spheres, in the planes of box faces, at huge and tiny radii, from far
// away; rays with NaN or Inf miss. The seed-faithful tests are used when
// chosen, so their failures show in the tree's answers.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_util.h"

#include "raybench/bvh/mixed_bvh2.h"
#include "raybench/bvh/mixed_wide_bvh.h"
#include "raybench/bvh/wide_bvh_batch.h"
#include "raybench/prim/triangle_mt_edges.h"
#include "raybench/prim/triangle_mt_normal.h"
#include "raybench/prim/triangle_watertight.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct MixedScene {
  std::vector<Triangle> triangles;
  std::vector<Sphere> spheres;
  std::vector<BBox> boxes;
  std::vector<OrientedBox> obbs;

  PrimitiveSpans spans() const { return {triangles, spheres, boxes, obbs}; }
};

// A rotation's columns from a random unit quaternion: orthonormal axes to
// within a few float ulps.
void random_axes(std::mt19937& rng, Vec3f (&axis)[3]) {
  std::normal_distribution<double> n;
  double q[4];
  double len = 0.0;
  for (double& c : q) {
    c = n(rng);
    len += c * c;
  }
  len = std::sqrt(len);
  for (double& c : q) c /= len;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  for (int i = 0; i < 3; ++i)
    axis[i] = {static_cast<float>(m[0][i]), static_cast<float>(m[1][i]), static_cast<float>(m[2][i])};
}

// Triangles, spheres, boxes and oriented boxes in [-10, 10]^3, overlapping
// each other, plus the hard members: a huge sphere whose surface is the
// floor at y = -12, spheres of radius 1e-4 and 1e-3, two nested spheres,
// a flat box (zero thickness in y) and a box inside a sphere.
MixedScene mixed_scene(unsigned seed, bool with_triangles = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-10.0f, 10.0f), unit(0.0f, 1.0f);
  MixedScene s;
  if (with_triangles) s.triangles = testing::random_soup(300, seed);
  for (int i = 0; i < 60; ++i)
    s.spheres.push_back({{pos(rng), pos(rng), pos(rng)}, std::pow(10.0f, -2.0f + 2.5f * unit(rng))});
  s.spheres.push_back({{0.0f, -1012.0f, 0.0f}, 1000.0f});
  s.spheres.push_back({{3.0f, 3.0f, 3.0f}, 1e-4f});
  s.spheres.push_back({{-3.0f, 3.0f, 3.0f}, 1e-3f});
  s.spheres.push_back({{5.0f, -5.0f, 5.0f}, 2.0f});
  s.spheres.push_back({{5.0f, -5.0f, 5.0f}, 1.0f});
  for (int i = 0; i < 40; ++i) {
    const Vec3f c{pos(rng), pos(rng), pos(rng)};
    const Vec3f h{0.05f + 2 * unit(rng), 0.05f + 2 * unit(rng), 0.05f + 2 * unit(rng)};
    s.boxes.push_back({c - h, c + h});
  }
  s.boxes.push_back({{-8.0f, 6.0f, -8.0f}, {-4.0f, 6.0f, -4.0f}});
  s.boxes.push_back({{4.6f, -5.4f, 4.6f}, {5.4f, -4.6f, 5.4f}});  // inside both nested spheres' shells' hole
  for (int i = 0; i < 40; ++i) {
    OrientedBox o;
    o.center = {pos(rng), pos(rng), pos(rng)};
    random_axes(rng, o.axis);
    o.half_extent = {0.05f + 2 * unit(rng), 0.05f + 2 * unit(rng), 0.05f + 2 * unit(rng)};
    s.obbs.push_back(o);
  }
  return s;
}

// Every primitive's own answer, for the closest hit: the least t, and every
// primitive reporting it (the traversal's order decides among exact ties).
struct Expected {
  std::vector<Hit> closest;  // all at the least t; empty for a miss
};

template <typename Tri, typename SphereT = SpherePrecise, typename BoxT = Slab, typename ObbT = Obb>
Expected brute_force(const PrimitiveSpans& p, const Ray& ray) {
  Expected e;
  const auto& tri_ray = Tri::precompute(ray);
  const typename BoxT::Precomputed box_ray = BoxT::precompute(ray);
  const auto consider = [&](std::size_t id, float t, float u, float v) {
    const Hit h{t, static_cast<std::int32_t>(id), u, v};
    if (e.closest.empty() || t < e.closest[0].t) e.closest = {h};
    else if (t == e.closest[0].t) e.closest.push_back(h);
  };
  for (std::size_t id = 0; id < p.size(); ++id) {
    const std::size_t i = p.local(id);
    float t;
    switch (p.kind(id)) {
      case PrimitiveKind::kTriangle: {
        TriangleHit h;
        if (Tri::intersect(tri_ray, ray.tfar, Tri::prepare(p.triangles[i]), h)) consider(id, h.t, h.u, h.v);
        break;
      }
      case PrimitiveKind::kSphere:
        if (intersect_sphere_surface<SphereT>(ray, ray.tfar, p.spheres[i], t)) consider(id, t, 0, 0);
        break;
      case PrimitiveKind::kBox:
        if (intersect_box_surface<BoxT>(box_ray, ray, ray.tfar, p.boxes[i], t)) consider(id, t, 0, 0);
        break;
      case PrimitiveKind::kOrientedBox:
        if (intersect_obb_surface<ObbT>(ray, ray.tfar, p.obbs[i], t)) consider(id, t, 0, 0);
        break;
    }
  }
  return e;
}

// Expects closest(ray) to be one of the brute-force closest hits, bit for
// bit, and occluded(ray) to be whether there is one; returns the number of
// rays that hit, and counts the hits per kind in `kinds`.
// With `exact` false (a box test that is not conservative, on rays that
// graze boxes), a ray may instead find a farther hit or none, when the box
// test culls the box of a primitive the ray only grazes: for at most 1 % of
// the rays, never a nearer hit.
template <typename Closest, typename Occluded>
int expect_brute_force_answers(const PrimitiveSpans& p, const std::vector<Ray>& rays,
                               const std::vector<Expected>& expected, Closest&& closest, Occluded&& occluded,
                               int (&kinds)[4], bool exact = true) {
  int hits = 0;
  std::size_t culled = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Expected& e = expected[i];
    const Hit got = closest(rays[i]);
    if (!exact && !e.closest.empty() && !(got.hit() && got.t == e.closest[0].t)) {
      EXPECT_TRUE(!got.hit() || got.t > e.closest[0].t) << "ray " << i << ": a nearer hit than testing every primitive";
      ++culled;
      continue;
    }
    EXPECT_EQ(got.hit(), !e.closest.empty()) << "ray " << i;
    EXPECT_EQ(occluded(rays[i]), !e.closest.empty()) << "ray " << i;
    if (!got.hit() || e.closest.empty()) continue;
    ++hits;
    ++kinds[static_cast<int>(p.kind(static_cast<std::size_t>(got.prim)))];
    const bool one_of_them = std::any_of(e.closest.begin(), e.closest.end(), [&](const Hit& h) {
      return h.prim == got.prim && h.t == got.t && h.u == got.u && h.v == got.v;
    });
    EXPECT_TRUE(one_of_them) << "ray " << i << ": got prim " << got.prim << " t " << got.t << ", expected prim "
                             << e.closest[0].prim << " t " << e.closest[0].t;
  }
  EXPECT_LE(culled, rays.size() / 100);
  return hits;
}

// The hard rays at the scene's analytic primitives, by kind (each set has
// tnear = 0):
//   random   origins in [-15, 15]^3, any direction, half with a finite tfar;
//   aimed    from a shell of radius 30 at a random point on the surface of a
//            random sphere, box or oriented box;
//   inside   from inside a random sphere, box or oriented box (its centre
//            moved by up to half its size), any direction;
//   tangent  tangent to a random sphere, in a random direction or along an
//            axis (touching it where its box's face touches it);
//   faces    in the plane of a random box face, across the face, and aimed
//            at its edges and corners;
//   far      from 1e5 away, at the centres and silhouettes of small spheres
//            and boxes.
inline const std::vector<std::string> kHardRayKinds = {"random", "aimed", "inside", "tangent", "faces", "far"};

std::vector<Ray> hard_rays(const MixedScene& s, const std::string& kind, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), unit(0.0f, 1.0f);
  const auto direction = [&] {
    for (;;) {
      const Vec3f d{u(rng), u(rng), u(rng)};
      if (dot(d, d) > 1e-4f && dot(d, d) <= 1.0f) return normalize(d);
    }
  };
  const auto pick = [&](std::size_t size) { return std::uniform_int_distribution<std::size_t>(0, size - 1)(rng); };
  const auto box_point = [&](const BBox& b, bool on_surface) {
    Vec3f p;
    for (int a = 0; a < 3; ++a) p[a] = b.lower[a] + unit(rng) * (b.upper[a] - b.lower[a]);
    if (on_surface) {
      const int a = static_cast<int>(pick(3));
      p[a] = unit(rng) < 0.5f ? b.lower[a] : b.upper[a];
    }
    return p;
  };
  const auto obb_point = [&](const OrientedBox& o, bool on_surface) {
    float c[3];
    for (int i = 0; i < 3; ++i) c[i] = u(rng) * o.half_extent[i] * (on_surface ? 1.0f : 0.5f);
    if (on_surface) {
      const int i = static_cast<int>(pick(3));
      c[i] = u(rng) < 0 ? -o.half_extent[i] : o.half_extent[i];
    }
    return o.center + o.axis[0] * c[0] + o.axis[1] * c[1] + o.axis[2] * c[2];
  };
  const auto aim = [](Vec3f from, Vec3f at) { return Ray{from, 0.0f, normalize(at - from), kInf}; };
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const int type = i % 3;  // sphere, box, oriented box
    if (kind == "random") {
      Ray r{{u(rng) * 15, u(rng) * 15, u(rng) * 15}, 0.0f, direction(), kInf};
      if (i % 2) r.tfar = 30.0f * unit(rng);
      rays.push_back(r);
    } else if (kind == "aimed") {
      Vec3f at;
      if (type == 0) {
        const Sphere& sp = s.spheres[pick(s.spheres.size())];
        at = sp.center + direction() * sp.radius;
      } else if (type == 1) {
        at = box_point(s.boxes[pick(s.boxes.size())], true);
      } else {
        at = obb_point(s.obbs[pick(s.obbs.size())], true);
      }
      rays.push_back(aim(direction() * 30.0f, at));
    } else if (kind == "inside") {
      Vec3f from;
      if (type == 0) {
        const Sphere& sp = s.spheres[pick(s.spheres.size())];
        from = sp.center + direction() * (0.5f * sp.radius * unit(rng));
      } else if (type == 1) {
        from = box_point(s.boxes[pick(s.boxes.size())], false);
      } else {
        from = obb_point(s.obbs[pick(s.obbs.size())], false);
      }
      rays.push_back({from, 0.0f, direction(), kInf});
    } else if (kind == "tangent") {
      const Sphere& sp = s.spheres[pick(s.spheres.size())];
      if (i % 2) {
        const Vec3f d = direction();
        const Vec3f n = normalize(cross(d, direction()));
        rays.push_back({sp.center + n * sp.radius - d * (2.0f * sp.radius + 5.0f), 0.0f, d, kInf});
      } else {
        const int a = static_cast<int>(pick(3)), b = (a + 1) % 3;
        Vec3f from = sp.center, d{0, 0, 0};
        from[a] -= sp.radius + 5.0f;
        from[b] += (i % 4 == 0 ? 1.0f : -1.0f) * sp.radius;
        d[a] = 1.0f;
        rays.push_back({from, 0.0f, d, kInf});
      }
    } else if (kind == "faces") {
      const BBox& b = s.boxes[pick(s.boxes.size())];
      if (i % 2) {
        // In the plane of a face, across it.
        const int a = static_cast<int>(pick(3));
        Vec3f from = box_point(b, false), to = box_point(b, false);
        from[a] = to[a] = unit(rng) < 0.5f ? b.lower[a] : b.upper[a];
        const Vec3f d = to - from;
        if (!(dot(d, d) > 0.0f)) continue;
        rays.push_back({from - d * 3.0f, 0.0f, d, kInf});
      } else {
        // At an edge or a corner.
        Vec3f at;
        for (int a = 0; a < 3; ++a) at[a] = unit(rng) < 0.5f ? b.lower[a] : b.upper[a];
        const int free = static_cast<int>(pick(4));  // 3: a corner
        if (free < 3) at[free] = b.lower[free] + unit(rng) * (b.upper[free] - b.lower[free]);
        rays.push_back(aim(direction() * 30.0f, at));
      }
    } else {  // far
      const Vec3f from = Vec3f{1.0f, 0.3f, -0.2f} * 1e5f;
      Vec3f at;
      if (type == 0) {
        const Sphere& sp = s.spheres[pick(s.spheres.size())];
        at = sp.center + (i % 2 ? direction() * sp.radius : Vec3f{0, 0, 0});
      } else if (type == 1) {
        at = box_point(s.boxes[pick(s.boxes.size())], i % 2 == 1);
      } else {
        at = obb_point(s.obbs[pick(s.obbs.size())], i % 2 == 1);
      }
      rays.push_back(aim(from, at));
    }
  }
  return rays;
}

template <typename Tri, typename SphereT = SpherePrecise, typename BoxT = Slab, typename ObbT = Obb>
std::vector<Expected> brute_force_all(const PrimitiveSpans& p, const std::vector<Ray>& rays) {
  std::vector<Expected> out;
  for (const Ray& r : rays) out.push_back(brute_force<Tri, SphereT, BoxT, ObbT>(p, r));
  return out;
}

// Runs check(kind, rays) for each hard ray kind on scene s.
template <typename Check>
void for_each_hard_ray_kind(const MixedScene& s, Check&& check) {
  unsigned seed = 100;
  for (const std::string& kind : kHardRayKinds) {
    SCOPED_TRACE(kind);
    check(kind, hard_rays(s, kind, 1500, seed++));
  }
}

// Enough hits of every kind, so that no type goes untested.
void expect_every_kind_hit(const int (&kinds)[4], bool with_triangles = true) {
  if (with_triangles) {
    EXPECT_GT(kinds[0], 50);
  }
  EXPECT_GT(kinds[1], 50);
  EXPECT_GT(kinds[2], 50);
  EXPECT_GT(kinds[3], 50);
}

// --- The binary tree -------------------------------------------------------

TEST(MixedBvh2, EveryPrimitiveIsInOneLeafUnderABoxThatHoldsIt) {
  const MixedScene s = mixed_scene(1);
  const PrimitiveSpans p = s.spans();
  const auto m = build_mixed_bvh2<MollerTrumbore>(p);
  ASSERT_EQ(m.bvh.prim_ids.size(), p.size());
  ASSERT_EQ(m.refs.size(), p.size());
  EXPECT_EQ(m.triangles.size(), s.triangles.size());
  EXPECT_EQ(m.analytic.spheres.size(), s.spheres.size());
  EXPECT_EQ(m.analytic.boxes.size(), s.boxes.size());
  EXPECT_EQ(m.analytic.obbs.size(), s.obbs.size());
  std::vector<int> seen(p.size(), 0);
  for (const Bvh2Node& n : m.bvh.nodes) {
    if (!n.is_leaf()) continue;
    for (std::uint32_t i = n.first_index; i < n.first_index + n.prim_count; ++i) {
      const std::uint32_t id = m.bvh.prim_ids[i];
      ++seen[id];
      EXPECT_TRUE(n.bounds.contains(p.bounds(id))) << "prim " << id;
      // The slot's reference names the primitive's kind and a copy of it.
      const std::uint32_t ref = m.refs[i], k = mixed_ref_index(ref);
      ASSERT_EQ(mixed_ref_kind(ref), p.kind(id));
      const std::size_t local = p.local(id);
      switch (p.kind(id)) {
        case PrimitiveKind::kTriangle: EXPECT_EQ(m.triangles[k].v0.x, s.triangles[local].v0.x); break;
        case PrimitiveKind::kSphere: EXPECT_EQ(m.analytic.spheres[k].radius, s.spheres[local].radius); break;
        case PrimitiveKind::kBox: EXPECT_EQ(m.analytic.boxes[k].upper.y, s.boxes[local].upper.y); break;
        case PrimitiveKind::kOrientedBox: EXPECT_EQ(m.analytic.obbs[k].axis[1].z, s.obbs[local].axis[1].z); break;
      }
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
  EXPECT_GT(m.memory_bytes(), m.bvh.memory_bytes());
}

template <typename Tri, typename BoxTest>
void expect_mixed_bvh2_matches_brute_force(const MixedScene& s, Bvh2Reinsertion reinsertion = Bvh2Reinsertion::kNone) {
  const PrimitiveSpans p = s.spans();
  Bvh2BuildOptions options;
  options.reinsertion = reinsertion;
  const auto m = build_mixed_bvh2<Tri>(p, options);
  int kinds[4] = {};
  for_each_hard_ray_kind(s, [&](const std::string&, const std::vector<Ray>& rays) {
    expect_brute_force_answers(
        p, rays, brute_force_all<Tri>(p, rays), [&](const Ray& r) { return intersect_mixed_bvh2<Tri, BoxTest>(m, r); },
        [&](const Ray& r) { return occluded_mixed_bvh2<Tri, BoxTest>(m, r); }, kinds);
  });
  expect_every_kind_hit(kinds, !s.triangles.empty());
}

TEST(MixedBvh2, EveryHardRayKindMatchesBruteForceWithTheConservativeBoxTest) {
  expect_mixed_bvh2_matches_brute_force<MollerTrumbore, SlabRobust>(mixed_scene(2));
}

TEST(MixedBvh2, EveryHardRayKindMatchesBruteForceWithThePlainBoxTest) {
  expect_mixed_bvh2_matches_brute_force<MollerTrumbore, Slab>(mixed_scene(3));
}

TEST(MixedBvh2, WatertightTrianglesAndAReinsertedTreeMatchBruteForce) {
  expect_mixed_bvh2_matches_brute_force<WatertightTriangle, SlabRobust>(mixed_scene(4), Bvh2Reinsertion::kFull);
}

TEST(MixedBvh2, ASceneWithoutTrianglesMatchesBruteForce) {
  expect_mixed_bvh2_matches_brute_force<MollerTrumbore, Slab>(mixed_scene(5, /*with_triangles=*/false));
}

// The tree answers with the seed notes' tests when they are chosen: the
// same answers as testing every primitive with them, on rays where their
// hits lie in the primitives' boxes (random, aimed, inside).
TEST(MixedBvh2, TheChosenSeedTestsJudgeTheAnalyticPrimitives) {
  const MixedScene s = mixed_scene(6);
  const PrimitiveSpans p = s.spans();
  const auto m = build_mixed_bvh2<MollerTrumbore>(p, {}, {.sphere_seed = true, .box_seed = true, .obb_seed = true});
  int kinds[4] = {};
  unsigned seed = 300;
  for (const char* kind : {"random", "aimed", "inside"}) {
    SCOPED_TRACE(kind);
    const std::vector<Ray> rays = hard_rays(s, kind, 1500, seed++);
    expect_brute_force_answers(
        p, rays, brute_force_all<MollerTrumbore, SphereSeed, SlabSeed, ObbSeed>(p, rays),
        [&](const Ray& r) { return intersect_mixed_bvh2<MollerTrumbore, SlabRobust>(m, r); },
        [&](const Ray& r) { return occluded_mixed_bvh2<MollerTrumbore, SlabRobust>(m, r); }, kinds);
  }
  expect_every_kind_hit(kinds);
}

// One known failure per seed test, seen through the tree: a ray from inside
// a sphere whose centre is behind it (SphereSeed's projoc < 0 rejects), a
// direction shorter than 1e-6 (SlabSeed takes it as parallel to every
// slab), one shorter than 1e-20 (ObbSeed's parallel test).
TEST(MixedBvh2, EachSeedTestsKnownFailureShowsAtSceneLevel) {
  MixedScene s;
  s.spheres = {{{0, 0, 0}, 1.0f}};
  s.boxes = {{{10, 2, 2}, {11, 3, 3}}};
  OrientedBox o;
  o.center = {0, 10.5f, 0};
  o.axis[0] = {1, 0, 0};
  o.axis[1] = {0, 1, 0};
  o.axis[2] = {0, 0, 1};
  o.half_extent = {0.5f, 0.5f, 0.5f};
  s.obbs = {o};
  const PrimitiveSpans p = s.spans();
  const Ray from_inside{{0.5f, 0, 0}, 0.0f, {1, 0, 0}, kInf};
  const Ray slow_at_box{{8, 2.5f, 2.5f}, 0.0f, {1e-7f, 0, 0}, kInf};
  const Ray slower_at_obb{{0, 5, 0}, 0.0f, {0, 1e-21f, 0}, kInf};
  const auto fixed = build_mixed_bvh2<MollerTrumbore>(p);
  EXPECT_EQ(intersect_mixed_bvh2<MollerTrumbore>(fixed, from_inside).prim, 0);
  EXPECT_EQ(intersect_mixed_bvh2<MollerTrumbore>(fixed, slow_at_box).prim, 1);
  EXPECT_EQ(intersect_mixed_bvh2<MollerTrumbore>(fixed, slower_at_obb).prim, 2);
  const auto sphere_seed = build_mixed_bvh2<MollerTrumbore>(p, {}, {.sphere_seed = true});
  EXPECT_FALSE(intersect_mixed_bvh2<MollerTrumbore>(sphere_seed, from_inside).hit());
  EXPECT_EQ(intersect_mixed_bvh2<MollerTrumbore>(sphere_seed, slow_at_box).prim, 1);
  const auto box_seed = build_mixed_bvh2<MollerTrumbore>(p, {}, {.box_seed = true});
  EXPECT_FALSE(intersect_mixed_bvh2<MollerTrumbore>(box_seed, slow_at_box).hit());
  EXPECT_EQ(intersect_mixed_bvh2<MollerTrumbore>(box_seed, from_inside).prim, 0);
  const auto obb_seed = build_mixed_bvh2<MollerTrumbore>(p, {}, {.obb_seed = true});
  EXPECT_FALSE(intersect_mixed_bvh2<MollerTrumbore>(obb_seed, slower_at_obb).hit());
  EXPECT_EQ(intersect_mixed_bvh2<MollerTrumbore>(obb_seed, slow_at_box).prim, 1);
}

// Analytic hits: the surface's first crossing (the exit from inside),
// u = v = 0, global ids after the triangles.
TEST(MixedBvh2, AnalyticHitsAreSurfaceCrossingsWithGlobalIds) {
  MixedScene s;
  s.triangles = {{{-5, -5, 20}, {5, -5, 20}, {0, 5, 20}}};
  s.spheres = {{{0, 0, 5}, 1.0f}};
  s.boxes = {{{-1, -1, 9}, {1, 1, 11}}};
  const PrimitiveSpans p = s.spans();
  const auto m = build_mixed_bvh2<MollerTrumbore>(p);
  const Hit outside = intersect_mixed_bvh2<MollerTrumbore>(m, {{0, 0, 0}, 0.0f, {0, 0, 1}, kInf});
  EXPECT_EQ(outside.prim, 1);
  EXPECT_EQ(outside.t, 4.0f);
  EXPECT_EQ(outside.u, 0.0f);
  EXPECT_EQ(outside.v, 0.0f);
  const Hit inside_sphere = intersect_mixed_bvh2<MollerTrumbore>(m, {{0, 0, 5}, 0.0f, {0, 0, 1}, kInf});
  EXPECT_EQ(inside_sphere.prim, 1);
  EXPECT_EQ(inside_sphere.t, 1.0f);
  const Hit inside_box = intersect_mixed_bvh2<MollerTrumbore>(m, {{0, 0, 10}, 0.0f, {0, 0, 1}, kInf});
  EXPECT_EQ(inside_box.prim, 2);
  EXPECT_EQ(inside_box.t, 1.0f);
  const Hit past_them = intersect_mixed_bvh2<MollerTrumbore>(m, {{0, 0, 12}, 0.0f, {0, 0, 1}, kInf});
  EXPECT_EQ(past_them.prim, 0);
  EXPECT_EQ(past_them.t, 8.0f);
  EXPECT_FALSE(occluded_mixed_bvh2<MollerTrumbore>(m, {{0, 0, 0}, 0.0f, {0, 0, 1}, 3.9f}));
  EXPECT_TRUE(occluded_mixed_bvh2<MollerTrumbore>(m, {{0, 0, 0}, 0.0f, {0, 0, 1}, 4.0f}));
}

std::vector<Ray> untraceable_rays() {
  return {{{kNaN, 0, 0}, 0.0f, {0, 0, 1}, kInf},  {{0, 0, -30}, 0.0f, {kNaN, 0, 1}, kInf},
          {{0, 0, -30}, 0.0f, {0, 0, kInf}, kInf}, {{kInf, 0, 0}, 0.0f, {-1, 0, 0}, kInf},
          {{0, 0, -30}, kNaN, {0, 0, 1}, kInf},   {{0, 0, -30}, 0.0f, {0, 0, 1}, kNaN}};
}

TEST(MixedBvh2, RaysWithNaNOrInfMissEverything) {
  const MixedScene s = mixed_scene(7);
  const auto m = build_mixed_bvh2<MollerTrumbore>(s.spans());
  for (const Ray& r : untraceable_rays()) {
    EXPECT_FALSE(intersect_mixed_bvh2<MollerTrumbore>(m, r).hit());
    EXPECT_FALSE(occluded_mixed_bvh2<MollerTrumbore>(m, r));
  }
}

// --- The wide trees --------------------------------------------------------

template <int W, typename TriLeaf>
void expect_pack_layout(const MixedScene& s, const MixedWideBvh<W>& m) {
  const PrimitiveSpans p = s.spans();
  const std::size_t pack_count = m.pack_prims.size() / W;
  ASSERT_EQ(m.first_mixed_pack + m.mixed_packs.size(), pack_count);
  if (!s.triangles.empty()) {
    EXPECT_GT(m.first_mixed_pack, 0u);  // packs of triangles only exist, and come first
  }
  EXPECT_GT(m.mixed_packs.size(), 0u);
  std::vector<int> seen(p.size(), 0);
  std::vector<BBox> pack_box(pack_count);
  for (const WideNode<W>& n : m.nodes)
    for (int lane = 0; lane < W; ++lane)
      if (n.child[lane] != WideBvh<W>::kEmptyChild && (n.child[lane] & WideBvh<W>::kLeafBit))
        pack_box[WideBvh<W>::first_pack(n.child[lane])] = n.bounds.lane(lane);
  std::size_t analytic = 0;
  for (std::size_t pack = 0; pack < pack_count; ++pack) {
    // The packs of triangles only first (no MixedPack), then the others.
    MixedPack info;
    if (pack < m.first_mixed_pack) {
      int used = 0;
      while (used < W && m.pack_prims[WideBvh<W>::slot(static_cast<std::uint32_t>(pack), used)] >= 0) ++used;
      info.lane = static_cast<std::uint8_t>(used);
    } else {
      info = m.mixed_packs[pack - m.first_mixed_pack];
      EXPECT_GT(info.count, 0);
      EXPECT_EQ(info.first, analytic);
    }
    for (int lane = 0; lane < W; ++lane) {
      const std::int32_t id = m.pack_prims[WideBvh<W>::slot(static_cast<std::uint32_t>(pack), lane)];
      if (lane >= info.lane + info.count) {
        EXPECT_EQ(id, -1);
        continue;
      }
      ASSERT_GE(id, 0);
      ++seen[static_cast<std::size_t>(id)];
      EXPECT_TRUE(pack_box[pack].contains(p.bounds(static_cast<std::size_t>(id)))) << "prim " << id;
      const PrimitiveKind kind = p.kind(static_cast<std::size_t>(id));
      if (lane < info.lane) {
        // A triangle lane of the SIMD pack: the triangle itself.
        EXPECT_EQ(kind, PrimitiveKind::kTriangle);
        if constexpr (TriLeaf::kLeaves == WideLeaves::kMollerTrumbore) {
          EXPECT_EQ(m.packs[pack].v0[0][lane], s.triangles[static_cast<std::size_t>(id)].v0.x);
        }
      } else {
        EXPECT_EQ(mixed_ref_kind(m.analytic_refs[info.first + static_cast<std::uint32_t>(lane - info.lane)]), kind);
        if constexpr (TriLeaf::kLeaves == WideLeaves::kMollerTrumbore) {
          EXPECT_TRUE(std::isnan(m.packs[pack].v0[0][lane])) << "an analytic lane's triangle is an unused lane";
        }
      }
    }
    analytic += info.count;
  }
  EXPECT_EQ(analytic, m.analytic_refs.size());
  EXPECT_EQ(analytic, s.spheres.size() + s.boxes.size() + s.obbs.size());
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
}

// The scalar kernel each wide leaf computes.
template <typename TriLeaf>
using ScalarOf = std::conditional_t<std::is_same_v<TriLeaf, WideMollerTrumboreEdges>, MollerTrumboreEdges,
                                    std::conditional_t<std::is_same_v<TriLeaf, Bvh8Watertight>, WatertightTriangle,
                                                       MollerTrumboreNormal>>;

template <int W, typename TriLeaf, typename BoxTest>
void expect_mixed_wide_matches_brute_force(const MixedScene& s, Bvh2Reinsertion reinsertion = Bvh2Reinsertion::kLight) {
  const PrimitiveSpans p = s.spans();
  SCOPED_TRACE(std::to_string(W) + " wide, " + std::string(BoxTest::name));
  const MixedWideBvh<W> m = build_mixed_wide_bvh<W, TriLeaf>(p, reinsertion);
  expect_pack_layout<W, TriLeaf>(s, m);
  using Leaf = MixedWideLeaf<TriLeaf>;
  int kinds[4] = {};
  for_each_hard_ray_kind(s, [&](const std::string& kind, const std::vector<Ray>& rays) {
    // The fused box test (SlabFma) rounds otherwise than the boxes' own
    // test (Slab), so it may cull the box of a box primitive that a ray in
    // the plane of its face, or at its edges, grazes.
    const bool exact = BoxTest::accuracy == AccuracyClass::kConservative || (kind != "faces" && kind != "far");
    expect_brute_force_answers(
        p, rays, brute_force_all<ScalarOf<TriLeaf>>(p, rays),
        [&](const Ray& r) { return intersect_wide<Leaf, BoxTest>(m, r); },
        [&](const Ray& r) { return occluded_wide<Leaf, BoxTest>(m, r); }, kinds, exact);
    // The batch form maps pack slots to prim ids after the batch.
    std::vector<Hit> batch(rays.size());
    intersect_wide_batch<Leaf, BoxTest>(m, rays, batch);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit one = intersect_wide<Leaf, BoxTest>(m, with_nonnegative_tnear(rays[i]));
      EXPECT_EQ(batch[i].prim, one.prim) << "ray " << i;
    }
  });
  expect_every_kind_hit(kinds, !s.triangles.empty());
}

TEST(MixedWideBvh, EightWideMatchesBruteForceWithEachBoxTest) {
  expect_mixed_wide_matches_brute_force<8, WideMollerTrumbore, SlabFma>(mixed_scene(10));
  expect_mixed_wide_matches_brute_force<8, WideMollerTrumbore, SlabRobustRay>(mixed_scene(11));
}

TEST(MixedWideBvh, FourWideMatchesBruteForceWithEachBoxTest) {
  expect_mixed_wide_matches_brute_force<4, WideMollerTrumbore, SlabFma>(mixed_scene(12));
  expect_mixed_wide_matches_brute_force<4, WideMollerTrumbore, SlabRobustRay>(mixed_scene(13));
}

TEST(MixedWideBvh, EdgeAndWatertightLeavesAndAReinsertedTreeMatchBruteForce) {
  expect_mixed_wide_matches_brute_force<8, WideMollerTrumboreEdges, SlabFma>(mixed_scene(14));
  expect_mixed_wide_matches_brute_force<4, WideMollerTrumboreEdges, SlabFma>(mixed_scene(15), Bvh2Reinsertion::kFull);
  expect_mixed_wide_matches_brute_force<8, Bvh8Watertight, SlabRobustRay>(mixed_scene(16), Bvh2Reinsertion::kFull);
}

TEST(MixedWideBvh, ASceneWithoutTrianglesMatchesBruteForce) {
  expect_mixed_wide_matches_brute_force<8, WideMollerTrumbore, SlabFma>(mixed_scene(17, /*with_triangles=*/false));
  expect_mixed_wide_matches_brute_force<4, WideMollerTrumbore, SlabFma>(mixed_scene(18, /*with_triangles=*/false));
}

TEST(MixedWideBvh, TheChosenSeedTestsJudgeTheAnalyticPrimitives) {
  const MixedScene s = mixed_scene(19);
  const PrimitiveSpans p = s.spans();
  const auto m = build_mixed_wide_bvh<8, WideMollerTrumbore>(p, Bvh2Reinsertion::kNone, {.sphere_seed = true, .box_seed = true, .obb_seed = true});
  using Leaf = MixedWideLeaf<WideMollerTrumbore>;
  int kinds[4] = {};
  unsigned seed = 400;
  for (const char* kind : {"random", "aimed", "inside"}) {
    SCOPED_TRACE(kind);
    const std::vector<Ray> rays = hard_rays(s, kind, 1500, seed++);
    expect_brute_force_answers(
        p, rays, brute_force_all<MollerTrumboreNormal, SphereSeed, SlabSeed, ObbSeed>(p, rays),
        [&](const Ray& r) { return intersect_wide<Leaf, SlabRobustRay>(m, r); },
        [&](const Ray& r) { return occluded_wide<Leaf, SlabRobustRay>(m, r); }, kinds);
  }
  expect_every_kind_hit(kinds);
}

TEST(MixedWideBvh, RaysWithNaNOrInfMissEverythingInTheBatch) {
  const MixedScene s = mixed_scene(20);
  const auto m = build_mixed_wide_bvh<8, WideMollerTrumbore>(s.spans());
  using Leaf = MixedWideLeaf<WideMollerTrumbore>;
  const std::vector<Ray> rays = untraceable_rays();
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint8_t> occluded(rays.size(), 1);
  intersect_wide_batch<Leaf, SlabFma>(m, rays, hits);
  occluded_wide_batch<Leaf, SlabFma>(m, rays, occluded);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_FALSE(hits[i].hit()) << "ray " << i;
    EXPECT_EQ(occluded[i], 0) << "ray " << i;
  }
}

}  // namespace
}  // namespace raybench
