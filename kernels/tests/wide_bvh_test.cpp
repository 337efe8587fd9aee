// Specification of the wide BVHs, 8 and 4 wide (bvh/wide_bvh.h,
// bvh/wide_bvh_traverse.h), over the BVH2 of every builder: the collapse
// keeps every triangle exactly once under bounds that contain it (the SBVH's
// split ones at least once, under bounds that together cover them), each
// node orders its children far to near per octant, and traversal answers
// exactly as testing every triangle does.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "bvh_test_util.h"

#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/wide_bvh_traverse.h"
#include "raybench/geometry/uv_sphere.h"

namespace raybench {
namespace {

using testing::brute_force_closest;
using testing::random_soup;

constexpr float kInf = std::numeric_limits<float>::infinity();

// Whether two arrays hold the same bytes. memcmp must not be given an empty
// array's data(), null, even to compare 0 bytes (UBSan: null pointer passed
// as argument), so empty arrays are compared by size alone.
template <typename Array>
bool same_bytes(const Array& a, const Array& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}

class WideBvhBuild : public ::testing::TestWithParam<Bvh2Builder> {
 protected:
  // As the backends' quality builds (sbvh, reinsert) make them: BVH2 leaves
  // of at most W triangles, scored as scalar tests, gathered into packs by
  // the collapse. The watertight tests below build as the default does.
  template <int W = 8>
  WideBvh<W> build(const std::vector<Triangle>& tris, WideLaneOrder lanes = WideLaneOrder::kByArea,
                   WideLeaves leaves = WideLeaves::kMollerTrumbore) const {
    Bvh2BuildOptions options;
    options.leaf_granularity = 1;
    options.max_leaf_size = W;
    return collapse_bvh2<W>(build_bvh2(tris, GetParam(), options), tris, leaves, lanes);
  }
  // Runs body(std::integral_constant<int, W>) for both widths.
  template <typename Body>
  static void for_each_width(Body&& body) {
    {
      SCOPED_TRACE("8 wide");
      body(std::integral_constant<int, 8>{});
    }
    {
      SCOPED_TRACE("4 wide");
      body(std::integral_constant<int, 4>{});
    }
  }
};

// Walks the tree checking bounds; collects the boxes of the leaves that hold
// each triangle. A leaf's box contains its triangles whole unless the
// builder splits them (splits_triangles: the SBVH), and then meets them.
template <int W>
void check(const WideBvh<W>& bvh, const std::vector<Triangle>& tris, std::uint32_t node, const BBox& parent,
           bool splits, std::vector<std::vector<BBox>>& leaves_of) {
  for (int lane = 0; lane < W; ++lane) {
    const std::uint32_t child = bvh.nodes[node].child[lane];
    const BBox box = bvh.nodes[node].bounds.lane(lane);
    if (child == WideBvh<W>::kEmptyChild) {
      EXPECT_TRUE(box.empty());
      continue;
    }
    EXPECT_TRUE(parent.contains(box));
    if (child & WideBvh<W>::kLeafBit) {
      const std::uint32_t first = WideBvh<W>::first_pack(child);
      for (std::uint32_t i = 0; i < W * WideBvh<W>::pack_count(child); ++i) {
        const std::int32_t id = bvh.pack_prims[W * first + i];
        if (id < 0) continue;
        leaves_of[static_cast<std::size_t>(id)].push_back(box);
        BBox t = triangle_bounds(tris[id]);
        if (splits) {
          t.lower = max(t.lower, box.lower);
          t.upper = min(t.upper, box.upper);
          EXPECT_FALSE(t.empty()) << "a leaf holds triangle " << id << " but none of it";
        } else {
          EXPECT_TRUE(box.contains(t)) << "triangle " << id;
        }
      }
    } else {
      check(bvh, tris, child, box, splits, leaves_of);
    }
  }
}

// Exactly one leaf per triangle, or (SBVH) leaves that together cover it.
TEST_P(WideBvhBuild, EveryTriangleInALeafUnderBoundsThatContainItOrTogetherCoverIt) {
  const bool splits = splits_triangles(GetParam());
  for_each_width([&](auto width) {
  for (std::size_t n : {1u, 7u, 9u, 5000u}) {
    const auto tris = random_soup(n, 1);
    const auto bvh = build<width()>(tris);
    std::vector<std::vector<BBox>> leaves_of(tris.size());
    // Every box lies within the tree's bounds: the extent SlabFmaRobust's
    // margins are computed over (a plane outside it could be missed).
    check(bvh, tris, 0, bvh.bounds, splits, leaves_of);
    BBox soup;
    for (const Triangle& t : tris) soup.extend(triangle_bounds(t));
    EXPECT_TRUE(bvh.bounds.contains(soup));
    for (std::size_t i = 0; i < tris.size(); ++i) {
      if (!splits) {
        EXPECT_EQ(leaves_of[i].size(), 1u) << "triangle " << i << " of " << tris.size();
        continue;
      }
      EXPECT_GE(leaves_of[i].size(), 1u) << "triangle " << i << " of " << tris.size();
      EXPECT_FALSE(testing::uncovered_point(tris[i], leaves_of[i]).has_value())
          << "triangle " << i << " of " << tris.size();
    }
    EXPECT_LT(bvh.depth, 40u);
  }
  });
}

// Closest and any hit of every ray against brute force with the leaves'
// own triangle test (Möller–Trumbore in its stored-normal form, or for
// WideMollerTrumboreEdges the same with the normal recomputed); returns
// the number of rays that hit. Exact ties in t may name either triangle.
template <typename Leaf = WideMollerTrumbore, int W>
int expect_same_hits_as_brute_force(const WideBvh<W>& bvh, const std::vector<Triangle>& tris,
                                    const std::vector<Ray>& rays) {
  using Kernel = std::conditional_t<std::is_same_v<Leaf, WideMollerTrumboreEdges>, MollerTrumboreEdges, MollerTrumboreNormal>;
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    const Hit expected = brute_force_closest<Kernel>(tris, r);
    const Hit got = intersect_wide<Leaf>(bvh, r);
    EXPECT_EQ(got.hit(), expected.hit()) << "ray " << i;
    EXPECT_EQ(occluded_wide<Leaf>(bvh, r), expected.hit()) << "ray " << i;
    if (!expected.hit() || !got.hit()) continue;
    ++hits;
    EXPECT_EQ(got.t, expected.t) << "ray " << i;
    if (got.prim != expected.prim) EXPECT_EQ(got.t, expected.t);  // an exact tie: either is right
    else {
      EXPECT_EQ(got.u, expected.u);
      EXPECT_EQ(got.v, expected.v);
    }
  }
  return hits;
}

std::string describe(WideLaneOrder lanes) {
  switch (lanes) {
    case WideLaneOrder::kByArea: return "lanes by area";
    case WideLaneOrder::kBvh2: return "lanes in the BVH2's order";
    case WideLaneOrder::kOcclusion: return "lanes by hit chance per cost";
  }
  return "?";
}
constexpr WideLaneOrder kLaneOrders[] = {WideLaneOrder::kByArea, WideLaneOrder::kBvh2, WideLaneOrder::kOcclusion};

// Coordinates of +-1e19 and +-3e38 (issue 28) are finite, but their boxes'
// areas overflow float to inf (and an extent of inf times one of 0 makes
// NaN), so every SAH cost of the collapse is inf or NaN. The tree must
// still be a valid one: every triangle in a leaf under bounds that contain
// it, packs of at most W triangles. The collapse segfaulted here (a plan
// with no valid slot choice read left[-1] and packed too many triangles).
TEST_P(WideBvhBuild, CoordinatesWhoseBoxAreasOverflowFloatStillCollapseToAValidTree) {
  const bool splits = splits_triangles(GetParam());
  for (const float scale : {1e18f, 3e37f}) {  // random_soup spans about +-11: up to +-1.1e19 and +-3.3e38
    SCOPED_TRACE("scale " + std::to_string(scale));
    auto tris = random_soup(2000, 4);
    for (Triangle& t : tris)
      for (Vec3f* v : {&t.v0, &t.v1, &t.v2}) *v = *v * scale;
    tris.push_back({{-3e38f, 0, 0}, {3e38f, 0, 0}, {0, 1, 0}});  // an extent of inf, a flat box
    for (const WideLaneOrder lanes : kLaneOrders) {
      SCOPED_TRACE(describe(lanes));
      for_each_width([&](auto width) {
        const auto bvh = build<width()>(tris, lanes);
        std::vector<std::vector<BBox>> leaves_of(tris.size());
        check(bvh, tris, 0, bvh.bounds, splits, leaves_of);
        for (std::size_t i = 0; i < tris.size(); ++i) {
          if (splits) EXPECT_GE(leaves_of[i].size(), 1u) << "triangle " << i;
          else EXPECT_EQ(leaves_of[i].size(), 1u) << "triangle " << i;
        }
      });
    }
  }
}

TEST_P(WideBvhBuild, ClosestAndAnyHitMatchBruteForceInEveryLaneOrder) {
  const auto tris = random_soup(4000, 2);
  for_each_width([&](auto width) {
  for (const WideLaneOrder lanes : kLaneOrders) {
  SCOPED_TRACE(describe(lanes));
  const auto bvh = build<width()>(tris, lanes);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.0f, 25.0f);
  std::vector<Ray> rays;
  for (int i = 0; i < 4000; ++i) {
    Ray r{{u(rng) * 15, u(rng) * 15, u(rng) * 15}, 0.0f, normalize(Vec3f{u(rng), u(rng), u(rng)}), kInf};
    if (i % 2) r.tfar = len(rng);
    rays.push_back(r);
  }
  EXPECT_GT(expect_same_hits_as_brute_force(bvh, tris, rays), 500);  // many hits, not only misses
  }
  });
}

// Large triangles stacked over one another (walls a few units apart, as in
// an architectural interior): any split of them leaves children whose boxes
// overlap almost whole, so a leaf of several packs costs less than a node
// over them. The collapse makes such leaves, never of more packs than
// allowed; every triangle is in one, and rays get the brute-force answers
// (a leaf's packs tested in order, each within the hits before it).
TEST_P(WideBvhBuild, StackedWallsShareLeavesOfSeveralPacksWithinTheLimit) {
  std::vector<Triangle> tris;
  for (int i = 0; i < 40; ++i) {
    const float z = 0.25f * static_cast<float>(i), skew = 0.01f * static_cast<float>(i % 7);
    tris.push_back({{-10, -10, z}, {10, -10, z + skew}, {10, 10, z}});
    tris.push_back({{-10, -10, z}, {10, 10, z}, {-10, 10, z + skew}});
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Ray> rays;
  for (int i = 0; i < 2000; ++i) {
    Ray r{{u(rng) * 12, u(rng) * 12, -5.0f + 25.0f * (u(rng) + 1.0f) / 2}, 0.0f,
          normalize(Vec3f{u(rng), u(rng), u(rng)}), kInf};
    if (i % 3 == 0) r.tfar = 3.0f;
    rays.push_back(r);
  }
  Bvh2BuildOptions options;
  options.leaf_granularity = 1;
  options.max_leaf_size = 8;
  const Bvh2 bvh2 = build_bvh2(tris, GetParam(), options);
  for (int packs : {1, 2, 3, 8}) {
    SCOPED_TRACE("leaves of at most " + std::to_string(packs) + " packs");
    const Bvh8 bvh = collapse_bvh2<8>(bvh2, tris, WideLeaves::kMollerTrumbore, WideLaneOrder::kByArea, packs);
    std::uint32_t most = 0;
    for (const WideNode<8>& node : bvh.nodes)
      for (std::uint32_t child : node.child)
        if (child != Bvh8::kEmptyChild && (child & Bvh8::kLeafBit)) most = std::max(most, Bvh8::pack_count(child));
    EXPECT_LE(most, static_cast<std::uint32_t>(packs));
    if (packs > 1) {
      EXPECT_GT(most, 1u);
    }
    std::vector<std::vector<BBox>> leaves_of(tris.size());
    check(bvh, tris, 0, bvh.bounds, splits_triangles(GetParam()), leaves_of);
    for (std::size_t i = 0; i < tris.size(); ++i) EXPECT_GE(leaves_of[i].size(), 1u) << "triangle " << i;
    EXPECT_GT(expect_same_hits_as_brute_force(bvh, tris, rays), 500);  // many hits, not only misses
  }
  EXPECT_THROW(collapse_bvh2<8>(bvh2, tris, WideLeaves::kMollerTrumbore, WideLaneOrder::kByArea, -1), std::invalid_argument);
  // The watertight leaves hold one pack each (their traversal tests one), by default and always.
  const Bvh8 watertight = collapse_bvh2<8>(bvh2, tris, WideLeaves::kVertices);
  for (const WideNode<8>& node : watertight.nodes)
    for (std::uint32_t child : node.child)
      if (child != Bvh8::kEmptyChild && (child & Bvh8::kLeafBit)) {
        EXPECT_EQ(Bvh8::pack_count(child), 1u);
      }
  EXPECT_THROW(collapse_bvh2<8>(bvh2, tris, WideLeaves::kVertices, WideLaneOrder::kByArea, 2), std::invalid_argument);
  // The default: leaves of several packs for the Möller-Trumbore leaves.
  std::uint32_t most = 0;
  for (const WideNode<8>& node : collapse_bvh2<8>(bvh2, tris).nodes)
    for (std::uint32_t child : node.child)
      if (child != Bvh8::kEmptyChild && (child & Bvh8::kLeafBit)) most = std::max(most, Bvh8::pack_count(child));
  EXPECT_GT(most, 1u);
  EXPECT_THROW(collapse_bvh2<8>(bvh2, tris, WideLeaves::kMollerTrumbore, WideLaneOrder::kByArea, 9), std::invalid_argument);
}

TEST_P(WideBvhBuild, EveryRayKindOnAMeshMatchesBruteForce) {
  const auto tris = testing::sphere_cluster();
  for_each_width([&](auto width) {
    const auto bvh = build<width()>(tris);
    unsigned seed = 20;
    for (std::string_view kind : testing::kRayKinds) {
      SCOPED_TRACE(std::string(kind));
      const int hits = expect_same_hits_as_brute_force(bvh, tris, testing::rays_at(tris, kind, 2000, seed++));
      EXPECT_GT(hits, 100);
    }
  });
}

// Leaves without normals (WideLeaves::kMollerTrumboreEdges) hold the same
// triangles in packs of 9 floats per triangle instead of 12, and their test
// answers as its scalar kernel (prim/triangle_mt_edges.h) does by brute force.
TEST_P(WideBvhBuild, EdgeLeavesAreAQuarterSmallerAndMatchTheirScalarTestOnEveryRayKind) {
  const auto tris = testing::sphere_cluster();
  for_each_width([&](auto width) {
    constexpr int W = width();
    const auto stored = build<W>(tris);
    const auto edges = build<W>(tris, WideLaneOrder::kByArea, WideLeaves::kMollerTrumboreEdges);
    EXPECT_TRUE(edges.packs.empty());
    ASSERT_EQ(edges.edge_packs.size(), stored.packs.size());
    EXPECT_TRUE(edges.pack_prims == stored.pack_prims);  // the same triangles in the same packs
    EXPECT_EQ(4 * sizeof(TriangleEdgePack<W>), 3 * sizeof(TrianglePack<W>));
    EXPECT_LT(edges.memory_bytes(), stored.memory_bytes());
    unsigned seed = 40;
    for (std::string_view kind : testing::kRayKinds) {
      SCOPED_TRACE(std::string(kind));
      EXPECT_GT(expect_same_hits_as_brute_force<WideMollerTrumboreEdges>(edges, tris, testing::rays_at(tris, kind, 2000, seed++)),
                100);
    }
  });
}

// Rays with zero direction components (either sign) take the plain slab
// test's loop instead of the fused one (aabb_slab_fma.h), whose NaN
// distances would not bound the slabs they run along: they find what brute
// force finds.
TEST_P(WideBvhBuild, AxisParallelRaysMatchBruteForce) {
  const auto tris = testing::sphere_cluster();
  for_each_width([&](auto width) {
    const auto bvh = build<width()>(tris);
    std::vector<Ray> rays = testing::rays_at(tris, "aimed", 3000, 60);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      Ray& r = rays[i];
      const int axis = static_cast<int>(i % 3);
      const float zero = i % 2 ? 0.0f : -0.0f;
      r.org[axis] += r.dir[axis];  // still through the point org + dir, which it aimed at
      r.dir[axis] = zero;
      if (i % 7 == 0) r.dir[(axis + 1) % 3] = zero;  // two zero components
    }
    EXPECT_GT(expect_same_hits_as_brute_force(bvh, tris, rays), 300);
  });
}

// Watertight leaves (WideLeaves::kVertices), with plain and conservative
// traversal, against the scalar watertight test on every triangle: the same
// hits at the same t (the interval test is on the divided t alone, so
// lowering tmax to a hit's t never rejects another at exactly that t).
template <typename BoxTest>
void expect_watertight_leaves_match_brute_force(const Bvh8& bvh, const std::vector<Triangle>& tris,
                                                const std::vector<Ray>& rays) {
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit expected = brute_force_closest<WatertightTriangle>(tris, rays[i]);
    const Hit got = intersect_wide<Bvh8Watertight, BoxTest>(bvh, rays[i]);
    ASSERT_EQ(got.hit(), expected.hit()) << "ray " << i;
    EXPECT_EQ((occluded_wide<Bvh8Watertight, BoxTest>(bvh, rays[i])), expected.hit()) << "ray " << i;
    if (!got.hit()) continue;
    ++hits;
    EXPECT_EQ(got.t, expected.t) << "ray " << i;
  }
  EXPECT_GT(hits, 100);
}

TEST_P(WideBvhBuild, WatertightLeavesMatchTheScalarWatertightTestOnEveryRayKind) {
  const auto tris = testing::sphere_cluster();
  Bvh2BuildOptions options;
  options.leaf_granularity = 8;
  const Bvh8 bvh = collapse_bvh2<8>(build_bvh2(tris, GetParam(), options), tris, WideLeaves::kVertices);
  EXPECT_TRUE(bvh.packs.empty());
  EXPECT_FALSE(bvh.vertex_packs.empty());
  unsigned seed = 40;
  for (std::string_view kind : testing::kRayKinds) {
    SCOPED_TRACE(std::string(kind));
    const std::vector<Ray> rays = testing::rays_at(tris, kind, 2000, seed++);
    expect_watertight_leaves_match_brute_force<Slab>(bvh, tris, rays);
    expect_watertight_leaves_match_brute_force<SlabRobust>(bvh, tris, rays);
    expect_watertight_leaves_match_brute_force<SlabRobustRay>(bvh, tris, rays);
    expect_watertight_leaves_match_brute_force<SlabFmaRobust>(bvh, tris, rays);
  }
}

TEST_P(WideBvhBuild, WatertightRobustTraversalLeaksNoRayAimedAtEdgesAndVerticesFromInside) {
  std::vector<Triangle> tris;
  append_uv_sphere(tris, {0, 0, 0}, 1.0f, 24, 48);
  Bvh2BuildOptions options;
  options.leaf_granularity = 8;
  const Bvh8 bvh = collapse_bvh2<8>(build_bvh2(tris, GetParam(), options), tris, WideLeaves::kVertices);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f), s(0, 1);
  int leaks = 0, leaks_ray_padded = 0, leaks_fused = 0;
  for (int i = 0; i < 6000; ++i) {
    const Triangle& t = tris[static_cast<std::size_t>(i) * 7919 % tris.size()];
    const Vec3f target = i % 2 ? t.v1 : t.v0 + (t.v2 - t.v0) * s(rng);  // a vertex, or a float point of an edge
    const Vec3f org{u(rng), u(rng), u(rng)};
    const Ray ray{org, 0.0f, target - org, kInf};
    leaks += !intersect_wide<Bvh8Watertight, SlabRobust>(bvh, ray).hit();
    leaks_ray_padded += !intersect_wide<Bvh8Watertight, SlabRobustRay>(bvh, ray).hit();
    leaks_fused += !intersect_wide<Bvh8Watertight, SlabFmaRobust>(bvh, ray).hit();
  }
  EXPECT_EQ(leaks, 0);
  EXPECT_EQ(leaks_ray_padded, 0);
  EXPECT_EQ(leaks_fused, 0);
}

TEST_P(WideBvhBuild, FindsTheClosedSphereFromInsideAndNothingOutsideIt) {
  std::vector<Triangle> tris;
  append_uv_sphere(tris, {0, 0, 0}, 1.0f, 24, 48);
  for_each_width([&](auto width) {
  const auto bvh = build<width()>(tris);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const Ray r{{u(rng) * 0.5f, u(rng) * 0.5f, u(rng) * 0.5f}, 0.0f, normalize(Vec3f{u(rng), u(rng), u(rng)}), kInf};
    const Hit h = intersect_wide(bvh, r);
    ASSERT_TRUE(h.hit()) << "ray " << i;
    EXPECT_NEAR(length(r.org + r.dir * h.t), 1.0f, 0.02f);
  }
  const Ray away{{3, 0, 0}, 0.0f, {1, 0, 0}, kInf};
  EXPECT_FALSE(intersect_wide(bvh, away).hit());
  });
}

// The build and the collapse run in parallel (TBB), yet the wide tree, its
// layout included, is the same for any number of threads: results and
// memory do not depend on the machine's core count.
TEST_P(WideBvhBuild, TheTreeIsTheSameBuiltOnOneThreadOrTwo) {
  const auto tris = random_soup(20000, 11);  // above the parallel thresholds
  for_each_width([&](auto width) {
  constexpr int W = width();
  // The occlusion order's hit chances are computed in the collapse's tasks too.
  for (const WideLaneOrder lanes : {WideLaneOrder::kByArea, WideLaneOrder::kOcclusion}) {
    SCOPED_TRACE(describe(lanes));
    WideBvh<W> one, two;
    tbb::task_arena(1).execute([&] { one = build<W>(tris, lanes); });
    tbb::task_arena(2).execute([&] { two = build<W>(tris, lanes); });
    ASSERT_EQ(one.nodes.size(), two.nodes.size());
    ASSERT_EQ(one.packs.size(), two.packs.size());
    EXPECT_EQ(one.depth, two.depth);
    EXPECT_TRUE(same_bytes(one.nodes, two.nodes));
    EXPECT_TRUE(same_bytes(one.packs, two.packs));
    EXPECT_TRUE(one.pack_prims == two.pack_prims);
  }
  });
}

// The collapse faults the pages of its output in on every thread before
// filling them (kernels/src/fault_in_parallel.h); with arrays of several
// huge pages that runs, and the tree must still be the same as on one
// thread, every leaf form filled whole.
TEST(WideBvhCollapse, ATreeSpanningSeveralHugePagesIsTheSameBuiltOnOneThreadOrTwo) {
  const auto tris = random_soup(80000, 5);
  Bvh2BuildOptions options;  // the default build's, as bvh8 makes it
  options.leaf_granularity = 8;
  options.max_leaf_size = 8;
  const Bvh2 bvh2 = build_bvh2(tris, Bvh2Builder::kBinnedSah, options);
  for (const WideLeaves leaves : {WideLeaves::kMollerTrumbore, WideLeaves::kMollerTrumboreEdges, WideLeaves::kVertices}) {
    WideBvh<8> one, two;
    tbb::task_arena(1).execute([&] { one = collapse_bvh2<8>(bvh2, tris, leaves, WideLaneOrder::kByArea); });
    tbb::task_arena(2).execute([&] { two = collapse_bvh2<8>(bvh2, tris, leaves, WideLaneOrder::kByArea); });
    const auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
    ASSERT_GT(bytes(one.packs) + bytes(one.edge_packs) + bytes(one.vertex_packs), kHugePageBytes);  // two or more
    ASSERT_EQ(one.nodes.size(), two.nodes.size());
    EXPECT_TRUE(same_bytes(one.nodes, two.nodes));
    EXPECT_TRUE(one.pack_prims == two.pack_prims);
    ASSERT_EQ(one.packs.size(), two.packs.size());
    ASSERT_EQ(one.edge_packs.size(), two.edge_packs.size());
    ASSERT_EQ(one.vertex_packs.size(), two.vertex_packs.size());
    EXPECT_TRUE(same_bytes(one.packs, two.packs));
    EXPECT_TRUE(same_bytes(one.edge_packs, two.edge_packs));
    EXPECT_TRUE(same_bytes(one.vertex_packs, two.vertex_packs));
    // Filled whole: every used lane holds its triangle, as its leaf form
    // stores it (a lane left as the fault's zero bytes would hold zeros).
    const auto expect_lane = [&](const auto& pack, const auto& expected, std::size_t p, int lane) {
      const auto stored = pack.lane(lane);
      static_assert(sizeof(stored) == sizeof(expected));
      ASSERT_EQ(0, std::memcmp(&stored, &expected, sizeof(stored))) << "pack " << p << " lane " << lane;
    };
    for (std::size_t p = 0; p < one.pack_prims.size() / 8; ++p)
      for (int lane = 0; lane < 8; ++lane) {
        const std::int32_t prim = one.pack_prims[p * 8 + lane];
        if (prim < 0) continue;
        const Triangle& tri = tris[static_cast<std::size_t>(prim)];
        switch (leaves) {
          case WideLeaves::kMollerTrumbore: expect_lane(one.packs[p], Triangle8::Kernel::prepare(tri), p, lane); break;
          case WideLeaves::kMollerTrumboreEdges:
            expect_lane(one.edge_packs[p], TriangleEdgePack<8>::Kernel::prepare(tri), p, lane);
            break;
          case WideLeaves::kVertices: expect_lane(one.vertex_packs[p], tri, p, lane); break;
        }
      }
  }
}

TEST_P(WideBvhBuild, EmptyInputBuildsATreeThatNothingHits) {
  const std::vector<Triangle> none;
  for_each_width([&](auto width) {
    const auto bvh = build<width()>(none);
    EXPECT_FALSE(intersect_wide(bvh, Ray{{0, 0, 0}, 0.0f, {0, 0, 1}, kInf}).hit());
    EXPECT_FALSE(occluded_wide(bvh, Ray{{0, 0, 0}, 0.0f, {0, 0, 1}, kInf}));
    EXPECT_TRUE(bvh.bounds.empty());
  });
}

TEST_P(WideBvhBuild, SahCostCountsNodeVisitsAndPackTests) {
  // One triangle: the root visit, then its one pack, under a box of the root's area.
  const std::vector<Triangle> one{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const auto tris = random_soup(5000, 3);
  for_each_width([&](auto width) {
    EXPECT_DOUBLE_EQ(build<width()>(one).sah_cost(), 2.0);
    // Many: finite, and more than the root visit alone.
    const double cost = build<width()>(tris).sah_cost();
    EXPECT_TRUE(std::isfinite(cost));
    EXPECT_GT(cost, 1.0);
    EXPECT_EQ(build<width()>({}).sah_cost(), 0.0);
  });
}

// The least SAH cost (as WideBvh::sah_cost, times the root's area) of any wide
// tree whose nodes are cuts of `bvh2`, by trying every cut: independent of
// the collapse's dynamic programme, and exponential, so for small trees only.
class ExhaustiveCollapse {
 public:
  ExhaustiveCollapse(const Bvh2& bvh2, std::size_t width, std::size_t max_leaf_packs)
      : bvh2_(bvh2), width_(width), max_leaf_packs_(max_leaf_packs) {}

  // The root is always a wide node.
  double least_cost() { return as_node(0); }

 private:
  using Cut = std::vector<std::uint32_t>;

  std::uint32_t triangles(std::uint32_t n) const {
    const Bvh2Node& node = bvh2_.nodes[n];
    return node.is_leaf() ? node.prim_count : triangles(node.first_index) + triangles(node.first_index + 1);
  }
  // Every set of at most width_ nodes below or at n that holds each of its leaves once.
  std::vector<Cut> cuts(std::uint32_t n) const {
    std::vector<Cut> out{{n}};
    if (!bvh2_.nodes[n].is_leaf()) {
      for (const Cut& left : cuts(bvh2_.nodes[n].first_index))
        for (const Cut& right : cuts(bvh2_.nodes[n].first_index + 1))
          if (left.size() + right.size() <= width_) {
            Cut both = left;
            both.insert(both.end(), right.begin(), right.end());
            out.push_back(both);
          }
    }
    return out;
  }
  double area(std::uint32_t n) const { return bvh2_.nodes[n].bounds.half_area(); }
  // n in one child slot: a leaf of ceil(triangles / width) packs, a test
  // each, or a wide node.
  double in_one_slot(std::uint32_t n) {
    const std::size_t packs = (triangles(n) + width_ - 1) / width_;
    const double leaf = packs <= max_leaf_packs_ ? static_cast<double>(packs) * area(n) : std::numeric_limits<double>::infinity();
    return bvh2_.nodes[n].is_leaf() ? leaf : std::min(leaf, as_node(n));
  }
  // n as a wide node: its visit, then its children, the best cut below it.
  double as_node(std::uint32_t n) {
    if (const auto it = node_cost_.find(n); it != node_cost_.end()) return it->second;
    double best = std::numeric_limits<double>::infinity();
    for (const Cut& left : cuts(bvh2_.nodes[n].first_index))
      for (const Cut& right : cuts(bvh2_.nodes[n].first_index + 1)) {
        if (left.size() + right.size() > width_) continue;
        double cost = 0.0;
        for (std::uint32_t c : left) cost += in_one_slot(c);
        for (std::uint32_t c : right) cost += in_one_slot(c);
        best = std::min(best, cost);
      }
    return node_cost_[n] = area(n) + best;
  }

  const Bvh2& bvh2_;
  std::size_t width_;
  std::size_t max_leaf_packs_;
  std::map<std::uint32_t, double> node_cost_;
};

TEST_P(WideBvhBuild, TheCollapseHasTheLeastSahCostOfAnyWideTreeCutFromTheBvh2) {
  for_each_width([&](auto width) {
    constexpr int W = width();
    for (std::size_t n : {2u, 5u, 9u, 13u, 18u, 30u}) {
      for (std::uint64_t seed : {1u, 2u, 3u}) {
        const auto tris = random_soup(n, seed);
        for (int granularity : {1, W}) {  // small BVH2 leaves, and leaves of up to W
          Bvh2BuildOptions options;
          options.leaf_granularity = granularity;
          options.max_leaf_size = W;
          const Bvh2 bvh2 = build_bvh2(tris, GetParam(), options);
          if (bvh2.nodes[0].is_leaf()) continue;  // nothing to choose
          for (int packs : {1, 2, 3}) {  // leaves of one pack, and of several
            if (n > 18 && granularity == 1) continue;  // the exhaustive search's time
            const double least =
                ExhaustiveCollapse(bvh2, W, static_cast<std::size_t>(packs)).least_cost() / bvh2.nodes[0].bounds.half_area();
            EXPECT_NEAR(collapse_bvh2<W>(bvh2, tris, WideLeaves::kMollerTrumbore, WideLaneOrder::kByArea, packs).sah_cost(),
                        least, 1e-5 * least)
                << n << " triangles, seed " << seed << ", granularity " << granularity << ", width " << W << ", packs "
                << packs;
          }
        }
      }
    }
  });
}

TEST_P(WideBvhBuild, ByAreaEveryNodeHoldsItsChildrenByDecreasingBoxAreaEmptyLanesLast) {
  // The any-hit traversal visits the smallest child first (wide_bvh_traverse.h);
  // in the BVH2's order it does not.
  const auto tris = random_soup(5000, 4);
  for_each_width([&](auto width) {
  constexpr int W = width();
  for (const WideLaneOrder lanes : {WideLaneOrder::kByArea, WideLaneOrder::kBvh2}) {
    const auto bvh = build<W>(tris, lanes);
    std::size_t increasing = 0, decreasing = 0;
    for (const WideNode<W>& node : bvh.nodes) {
      for (int lane = 1; lane < W; ++lane) {
        if (node.child[lane] == WideBvh<W>::kEmptyChild) continue;
        ASSERT_NE(node.child[lane - 1], WideBvh<W>::kEmptyChild) << "a child after an empty lane";
        const float before = node.bounds.lane(lane - 1).half_area(), here = node.bounds.lane(lane).half_area();
        increasing += before < here;
        decreasing += before > here;
      }
    }
    if (lanes == WideLaneOrder::kByArea) {
      EXPECT_EQ(increasing, 0u);
      EXPECT_GT(decreasing, bvh.nodes.size());  // the order is not vacuous
    } else {
      EXPECT_GT(increasing, bvh.nodes.size() / 2);
    }
  }
  });
}

// Which of two groups of triangles each lane of the root holds: 1 for ids
// below `first_of_second`, 2 for the others, 3 for both, 0 for an empty lane.
template <int W>
std::array<int, W> groups_of_root_lanes(const WideBvh<W>& bvh, std::int32_t first_of_second) {
  std::array<int, W> groups{};
  for (int lane = 0; lane < W; ++lane) {
    std::vector<std::uint32_t> todo{bvh.nodes[0].child[lane]};
    while (!todo.empty()) {
      const std::uint32_t ref = todo.back();
      todo.pop_back();
      if (ref == WideBvh<W>::kEmptyChild) continue;
      if (ref & WideBvh<W>::kLeafBit) {
        const std::uint32_t first = WideBvh<W>::first_pack(ref);
        for (std::uint32_t pack = first; pack != first + WideBvh<W>::pack_count(ref); ++pack)
          for (int i = 0; i < W; ++i)
            if (const std::int32_t id = bvh.pack_prims[WideBvh<W>::slot(pack, i)]; id >= 0)
              groups[lane] |= id < first_of_second ? 1 : 2;
      } else {
        todo.insert(todo.end(), bvh.nodes[ref].child, bvh.nodes[ref].child + W);
      }
    }
  }
  return groups;
}

// A ray entering a box that a wall fills certainly hits it; one entering a
// box around a few small triangles at its corners likely does not. Any-hit
// traversal visits the highest lane first: by hit chance per cost, the
// wall's lanes come first though its boxes are the larger, which the order
// by area visits last.
TEST_P(WideBvhBuild, ByOcclusionTheChildrenLikeliestToEndTheRayPerCostAreVisitedFirst) {
  std::vector<Triangle> tris;
  // The wall: a 10 x 10 square at z = 0 in 2 x 25 triangles, ids 0-49.
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const float x = 2.0f * i, y = 2.0f * j;
      tris.push_back({{x, y, 0}, {x + 2, y, 0}, {x + 2, y + 2, 0}});
      tris.push_back({{x, y, 0}, {x + 2, y + 2, 0}, {x, y + 2, 0}});
    }
  const auto first_sparse = static_cast<std::int32_t>(tris.size());
  // Sparse: 16 triangles of side 0.01 at the corners of two cubes of side
  // 0.5 off to the side, whose boxes are all smaller than the wall's pieces.
  for (int cube = 0; cube < 2; ++cube)
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3f c = Vec3f{60.0f + 1.0f * cube + (corner & 1), static_cast<float>(corner >> 1 & 1),
                            static_cast<float>(corner >> 2 & 1)} * 0.5f;
      tris.push_back({c, c + Vec3f{0.01f, 0, 0}, c + Vec3f{0, 0.01f, 0}});
    }
  for_each_width([&](auto width) {
    constexpr int W = width();
    for (const WideLaneOrder lanes : {WideLaneOrder::kOcclusion, WideLaneOrder::kByArea}) {
      SCOPED_TRACE(describe(lanes));
      const auto groups = groups_of_root_lanes(build<W>(tris, lanes), first_sparse);
      int lowest_wall = W, highest_wall = -1, lowest_sparse = W, highest_sparse = -1;
      for (int lane = 0; lane < W; ++lane) {
        ASSERT_NE(groups[lane], 3) << "a root lane holds both groups: lane " << lane;
        if (groups[lane] == 1) lowest_wall = std::min(lowest_wall, lane), highest_wall = lane;
        if (groups[lane] == 2) lowest_sparse = std::min(lowest_sparse, lane), highest_sparse = lane;
      }
      ASSERT_GE(highest_wall, 0);
      ASSERT_GE(highest_sparse, 0);
      if (lanes == WideLaneOrder::kOcclusion) EXPECT_GT(lowest_wall, highest_sparse);
      else EXPECT_GT(lowest_sparse, highest_wall);
    }
  });
}

TEST_P(WideBvhBuild, EveryNodeOrdersItsChildrenFarToNearAlongEachOctantsDiagonal) {
  const auto tris = random_soup(5000, 4);
  for_each_width([&](auto width) {
  constexpr int W = width();
  const auto bvh = build<W>(tris);
  for (const WideNode<W>& node : bvh.nodes) {
    for (int octant = 0; octant < 8; ++octant) {
      // Along the octant's diagonal: +x for bit 0 clear, -x when set, and so on.
      const auto along = [&](int lane) {
        float d = 0.0f;
        for (int a = 0; a < 3; ++a) {
          const float centre2 = node.bounds.lower[a][lane] + node.bounds.upper[a][lane];
          d += (octant >> a & 1) ? -centre2 : centre2;
        }
        return d;
      };
      unsigned seen = 0;
      bool children_started = false;
      float previous = kInf;
      for (int rank = 0; rank < W; ++rank) {
        const int lane = far_to_near_lane(node, octant, rank);
        seen |= 1u << lane;
        if (node.child[lane] == WideBvh<W>::kEmptyChild) {
          EXPECT_FALSE(children_started) << "empty lanes come first";
          continue;
        }
        children_started = true;
        EXPECT_LE(along(lane), previous) << "octant " << octant << " rank " << rank;
        previous = along(lane);
      }
      EXPECT_EQ(seen, (1u << W) - 1) << "a permutation of the W lanes";
    }
  }
  });
}

TEST(WideBvhTraversal, ARaysOctantIsWhereItsSlabTestEntersByTheUpperPlane) {
  EXPECT_EQ(ray_octant(Slab::precompute(Ray{{0, 0, 0}, 0.0f, {1, 2, 3}, kInf})), 0);
  EXPECT_EQ(ray_octant(Slab::precompute(Ray{{0, 0, 0}, 0.0f, {-1, 2, -3}, kInf})), 0b101);
  EXPECT_EQ(ray_octant(Slab::precompute(Ray{{0, 0, 0}, 0.0f, {-0.0f, 0.0f, -1}, kInf})), 0b101);  // -0 as negative
}

TEST(WideBvhTraversal, AnyHitPushesTheEnteredChildrenInLaneOrderAboveWhatIsThere) {
  WideNode<8> node{};
  for (int lane = 0; lane < 8; ++lane) node.child[lane] = 100 + static_cast<std::uint32_t>(lane);
  for (unsigned mask = 0; mask < 256; ++mask) {
    wide_bvh_detail::Stack<8> stack;
    stack.top = 3;
    for (int i = 0; i < 3; ++i) stack.ref[i] = 7 + static_cast<std::uint32_t>(i);
    wide_bvh_detail::push_in_lane_order(stack, node, mask);
    ASSERT_EQ(stack.top, 3 + __builtin_popcount(mask)) << mask;
    for (int i = 0; i < 3; ++i) EXPECT_EQ(stack.ref[i], 7u + static_cast<std::uint32_t>(i)) << "mask " << mask;
    for (int i = 3, lane = 0; i < stack.top; ++i, ++lane) {
      while (!(mask >> lane & 1u)) ++lane;
      EXPECT_EQ(stack.ref[i], node.child[lane]) << "mask " << mask;
    }
  }
}

#if defined(__AVX2__)
// The SIMD traversal permutes and compacts what the scalar fallback pushes
// lane by lane: both must leave the same entries in the same order, far to
// near with entry distances, for the closest hit.
template <int W>
void expect_compacted_push_equals_lane_by_lane_push() {
  std::mt19937 rng(5);
  WideNode<W> node{};
  for (int lane = 0; lane < W; ++lane) node.child[lane] = 100 + static_cast<std::uint32_t>(lane);
  constexpr int bits = WideNode<W>::kOrderBits;
  for (int trial = 0; trial < 2000; ++trial) {
    int lanes[W];
    for (int lane = 0; lane < W; ++lane) lanes[lane] = lane;
    std::shuffle(lanes, lanes + W, rng);
    const int octant = static_cast<int>(rng() % 8);
    std::uint32_t order = 0;
    for (int rank = 0; rank < W; ++rank) order |= static_cast<std::uint32_t>(lanes[rank]) << (bits * rank);
    node.far_to_near[octant] = static_cast<typename WideNode<W>::Order>(order);
    alignas(32) float entry[W];
    for (float& e : entry) e = static_cast<float>(rng() % 1000);
    const unsigned mask = rng() % (1u << W);

    wide_bvh_detail::Stack<W> scalar, simd;
    scalar.top = simd.top = 3;  // pushes land above what is there
    wide_bvh_detail::push_children_scalar<true>(scalar, node, octant, mask, entry);
    const auto permutation = wide_bvh_detail::unpack_lanes<W, bits>(node.far_to_near[octant]);
    // The mask in rank order, as the traversal computes it from the permuted hit lanes.
    unsigned ranked = 0;
    for (int rank = 0; rank < W; ++rank) ranked |= (mask >> far_to_near_lane(node, octant, rank) & 1u) << rank;
    wide_bvh_detail::push_compacted(simd, simd::IntLanes<W>::load(node.child).permute(permutation),
                                    simd::FloatLanes<W>::load(entry).permute(permutation), ranked);
    ASSERT_EQ(simd.top, scalar.top);
    for (int i = 3; i < scalar.top; ++i) {
      EXPECT_EQ(simd.ref[i], scalar.ref[i]);
      EXPECT_EQ(simd.entry[i], scalar.entry[i]);
    }

  }
}

TEST(WideBvhTraversal, TheCompactedPushStoresWhatTheLaneByLanePushStores) {
  expect_compacted_push_equals_lane_by_lane_push<8>();
  expect_compacted_push_equals_lane_by_lane_push<4>();
}
#endif

INSTANTIATE_TEST_SUITE_P(Builders, WideBvhBuild, ::testing::ValuesIn(kBvh2Builders),
                         [](const auto& info) { return std::string(to_string(info.param)); });

}  // namespace
}  // namespace raybench
