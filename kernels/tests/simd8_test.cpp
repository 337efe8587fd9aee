// Specification of the 8-wide batched tests (raybench/simd/): on every input,
// the AVX2 form answers exactly as the scalar kernels, lane by lane.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "raybench/simd/box8.h"
#include "raybench/simd/triangle8.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(Triangle8, UnusedLanesNeverHit) {
  const std::vector<Triangle> one{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const Triangle8 packed = Triangle8::pack(one);
  TriangleHit h;
  EXPECT_EQ(intersect8(Ray{{0.25f, 0.25f, 1}, 0, {0, 0, -1}, kInf}, kInf, packed, h), 0);
  EXPECT_FLOAT_EQ(h.t, 1.0f);
  EXPECT_EQ(intersect8(Ray{{5, 5, 1}, 0, {0, 0, -1}, kInf}, kInf, packed, h), -1);
}

TEST(Triangle8, ReturnsTheClosestLane) {
  std::vector<Triangle> stack;
  for (float z : {-3.0f, -1.0f, -2.0f}) stack.push_back({{0, 0, z}, {1, 0, z}, {0, 1, z}});
  TriangleHit h;
  EXPECT_EQ(intersect8(Ray{{0.25f, 0.25f, 0}, 0, {0, 0, -1}, kInf}, kInf, Triangle8::pack(stack), h), 1);
  EXPECT_FLOAT_EQ(h.t, 1.0f);
}

#if defined(__AVX2__)
TEST(Triangle8, Avx2AnswersExactlyAsTheScalarKernel) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<Triangle> tris;
    for (int k = 0; k < 8; ++k) tris.push_back({{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}});
    if (i % 10 == 0) tris[3] = tris[2];                               // duplicates tie
    if (i % 7 == 0) tris[5] = {tris[5].v0, tris[5].v0, tris[5].v1};    // degenerate
    const Triangle8 packed = Triangle8::pack({tris.data(), static_cast<std::size_t>(1 + i % 8)});
    // Aimed at a point of one lane's triangle, so most rays exercise hits.
    const Triangle& aim = tris[i % 8 % (1 + i % 8)];
    const float wa = std::fabs(u(rng)), wb = std::fabs(u(rng)) * (1.0f - wa);
    const Vec3f org{u(rng) * 3, u(rng) * 3, u(rng) * 3};
    Ray r{org, 0.0f, aim.v0 + (aim.v1 - aim.v0) * wa + (aim.v2 - aim.v0) * wb - org, kInf};
    if (i % 13 == 0) r.dir.x = 0.0f;
    const float tmax = i % 3 ? kInf : 2.0f;
    TriangleHit a{}, b{};
    const int lane_simd = intersect8_avx2(r, tmax, packed, a);
    const int lane_scalar = intersect8_scalar(r, tmax, packed, b);
    ASSERT_EQ(lane_simd, lane_scalar) << "ray " << i;
    if (lane_simd < 0) continue;
    ++hits;
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.u, b.u);
    EXPECT_EQ(a.v, b.v);
  }
  EXPECT_GT(hits, 5000);
}

TEST(Box8, Avx2AnswersExactlyAsTheScalarSlabTest) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<BBox> boxes;
    for (int k = 0; k < 8; ++k) {
      BBox b;
      b.extend(Vec3f{u(rng), u(rng), u(rng)});
      b.extend(Vec3f{u(rng), u(rng), u(rng)});
      boxes.push_back(b);
    }
    const BBox8 packed = BBox8::pack({boxes.data(), static_cast<std::size_t>(1 + i % 8)});
    const Vec3f org{u(rng) * 3, u(rng) * 3, u(rng) * 3}, target{u(rng), u(rng), u(rng)};
    Ray r{org, 0.0f, target - org, kInf};  // aimed into the region the boxes fill
    if (i % 11 == 0) {  // axis-parallel, origin on a slab plane: the NaN case
      r.dir = {0.0f, i % 2 ? 0.0f : -0.0f, 1.0f};
      r.org.x = boxes[0].lower.x;
    }
    const Slab::Precomputed pre = Slab::precompute(r);
    alignas(32) float e_simd[8], e_scalar[8];
    const unsigned m_simd = intersect8_avx2(pre, kInf, packed, e_simd);
    const unsigned m_scalar = intersect8_scalar(pre, kInf, packed, e_scalar);
    ASSERT_EQ(m_simd, m_scalar) << "ray " << i;
    for (int lane = 0; lane < 8; ++lane)
      if (m_simd >> lane & 1) {
        EXPECT_EQ(e_simd[lane], e_scalar[lane]);
      }
    hits += __builtin_popcount(m_simd);
  }
  EXPECT_GT(hits, 10000);
}
#endif

TEST(Box8, EmptyLanesAreMissed) {
  const std::vector<BBox> one{BBox{{0, 0, 0}, {1, 1, 1}}};
  alignas(32) float entry[8];
  const Slab::Precomputed r = Slab::precompute(Ray{{0.5f, 0.5f, -1}, 0, {0, 0, 1}, kInf});
  EXPECT_EQ(intersect8(r, kInf, BBox8::pack(one), entry), 1u);
  EXPECT_FLOAT_EQ(entry[0], 1.0f);
}

}  // namespace
}  // namespace raybench
