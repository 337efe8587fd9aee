// Specification of the BVH2 builder and traversal: structural invariants, and
// answers identical to testing every triangle (brute force).
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_util.h"

#include "raybench/bvh/bvh2.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "raybench/prim/triangle_mt.h"

namespace raybench {
namespace {

using testing::brute_force_closest;
using testing::random_soup;

BBox bounds_of(const Triangle& t) {
  BBox b;
  b.extend(t.v0);
  b.extend(t.v1);
  b.extend(t.v2);
  return b;
}

void expect_valid(const Bvh2& bvh, const std::vector<Triangle>& tris) {
  std::vector<int> seen(tris.size(), 0);
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const Bvh2Node& n = bvh.nodes[stack.back()];
    stack.pop_back();
    if (n.is_leaf()) {
      for (std::uint32_t i = n.first_index; i < n.first_index + n.prim_count; ++i) {
        const std::uint32_t id = bvh.prim_ids[i];
        ++seen[id];
        EXPECT_TRUE(n.bounds.contains(bounds_of(tris[id]))) << "leaf does not contain triangle " << id;
      }
    } else {
      for (std::uint32_t c : {n.first_index, n.first_index + 1}) {
        ASSERT_LT(c, bvh.nodes.size());
        EXPECT_TRUE(n.bounds.contains(bvh.nodes[c].bounds));
        stack.push_back(c);
      }
    }
  }
  for (std::size_t i = 0; i < tris.size(); ++i) EXPECT_EQ(seen[i], 1) << "triangle " << i << " in " << seen[i] << " leaves";
  EXPECT_TRUE(std::isfinite(bvh.sah_cost()));
  EXPECT_GT(bvh.sah_cost(), 0.0);
}

std::vector<MollerTrumbore::Prepared> prepare(const Bvh2& bvh, const std::vector<Triangle>& tris) {
  std::vector<MollerTrumbore::Prepared> p;
  for (std::uint32_t id : bvh.prim_ids) p.push_back(MollerTrumbore::prepare(tris[id]));
  return p;
}

TEST(Bvh2, EveryTriangleInExactlyOneLeafAndBoundsNest) {
  const auto tris = random_soup(5000, 1);
  expect_valid(build_bvh2_binned_sah(tris), tris);
}

TEST(Bvh2, ParallelBuildOfALargeInputIsValid) {
  const auto tris = random_soup(60000, 2);  // above the parallel threshold
  expect_valid(build_bvh2_binned_sah(tris), tris);
}

TEST(Bvh2, CoincidentTrianglesAreSplitIntoSmallLeaves) {
  std::vector<Triangle> tris(1000, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Bvh2 bvh = build_bvh2_binned_sah(tris);
  expect_valid(bvh, tris);
  for (const Bvh2Node& n : bvh.nodes)
    if (n.is_leaf()) {
      EXPECT_LE(n.prim_count, 8u);
    }
}

TEST(Bvh2, ClosestHitMatchesBruteForce) {
  const auto tris = random_soup(3000, 3);
  const Bvh2 bvh = build_bvh2_binned_sah(tris);
  const auto prepared = prepare(bvh, tris);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hit_count = 0;
  for (int i = 0; i < 3000; ++i) {
    Ray r;
    r.org = {u(rng) * 15, u(rng) * 15, u(rng) * 15};
    r.dir = normalize(Vec3f{u(rng), u(rng), u(rng)});
    const Hit expected = brute_force_closest(tris, r);
    const Hit got = intersect_bvh2<MollerTrumbore>(bvh, prepared, r);
    ASSERT_EQ(got.hit(), expected.hit()) << "ray " << i;
    if (!expected.hit()) continue;
    ++hit_count;
    EXPECT_EQ(got.t, expected.t) << "ray " << i;
    if (got.t == expected.t && got.prim != expected.prim) continue;  // an exact tie: either triangle is right
    EXPECT_EQ(got.prim, expected.prim) << "ray " << i;
    EXPECT_EQ(got.u, expected.u);
    EXPECT_EQ(got.v, expected.v);
  }
  EXPECT_GT(hit_count, 500);  // the test exercises hits, not only misses
}

TEST(Bvh2, AnyHitMatchesBruteForceWithinTheInterval) {
  const auto tris = random_soup(3000, 5);
  const Bvh2 bvh = build_bvh2_binned_sah(tris);
  const auto prepared = prepare(bvh, tris);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.0f, 20.0f);
  int occluded = 0;
  for (int i = 0; i < 3000; ++i) {
    Ray r;
    r.org = {u(rng) * 15, u(rng) * 15, u(rng) * 15};
    r.dir = normalize(Vec3f{u(rng), u(rng), u(rng)});
    r.tfar = len(rng);
    const bool expected = brute_force_closest(tris, r).hit();
    ASSERT_EQ(occluded_bvh2<MollerTrumbore>(bvh, prepared, r), expected) << "ray " << i;
    occluded += expected;
  }
  EXPECT_GT(occluded, 300);
  EXPECT_LT(occluded, 2700);
}

TEST(Bvh2, AxisParallelRaysWithZeroDirectionComponentsHit) {
  // 1/±0 = ±inf in the slab test; an origin on a slab plane gives 0 * inf = NaN,
  // which must not reject the box.
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const Bvh2 bvh = build_bvh2_binned_sah(tris);
  const auto prepared = prepare(bvh, tris);
  for (float zero : {0.0f, -0.0f}) {
    Ray r;
    r.org = {0.0f, 0.25f, 1.0f};  // x on the box's lower x plane
    r.dir = {zero, zero, -1.0f};
    EXPECT_TRUE(intersect_bvh2<MollerTrumbore>(bvh, prepared, r).hit()) << "zero sign " << std::signbit(zero);
  }
}

TEST(Bvh2, EmptyInputBuildsATreeThatNothingHits) {
  const std::vector<Triangle> none;
  const Bvh2 bvh = build_bvh2_binned_sah(none);
  Ray r;
  r.dir = {0, 0, 1};
  EXPECT_FALSE(intersect_bvh2<MollerTrumbore>(bvh, {}, r).hit());
  EXPECT_FALSE(occluded_bvh2<MollerTrumbore>(bvh, {}, r));
}

}  // namespace
}  // namespace raybench
