// Specification of the 8-wide batched tests (raybench/simd/): on every input,
// the AVX2 form answers exactly as the scalar kernels, lane by lane.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "raybench/simd/wide_box.h"
#include "raybench/simd/wide_triangle.h"
#include "raybench/simd/triangle8_watertight.h"
#include "raybench/geometry/uv_sphere.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(TrianglePack, UnusedLanesNeverHit) {
  const std::vector<Triangle> one{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const Triangle8 packed = Triangle8::pack(one);
  TriangleHit h;
  EXPECT_EQ(intersect_pack(Ray{{0.25f, 0.25f, 1}, 0, {0, 0, -1}, kInf}, kInf, packed, h), 0);
  EXPECT_FLOAT_EQ(h.t, 1.0f);
  EXPECT_EQ(intersect_pack(Ray{{5, 5, 1}, 0, {0, 0, -1}, kInf}, kInf, packed, h), -1);
}

TEST(TrianglePack, ReturnsTheClosestLane) {
  std::vector<Triangle> stack;
  for (float z : {-3.0f, -1.0f, -2.0f}) stack.push_back({{0, 0, z}, {1, 0, z}, {0, 1, z}});
  TriangleHit h;
  EXPECT_EQ(intersect_pack(Ray{{0.25f, 0.25f, 0}, 0, {0, 0, -1}, kInf}, kInf, Triangle8::pack(stack), h), 1);
  EXPECT_FLOAT_EQ(h.t, 1.0f);
}

#if defined(__AVX2__)
// Case i of the SIMD-against-scalar tests: 1 to `width` random triangles (every
// 10th case with two equal ones, every 7th with a degenerate one) and a ray
// aimed at a point of one of them, so most rays exercise hits; every 13th
// ray has a zero direction component, every third case a finite tmax. With
// edge_cases, every 5th case has two triangles sharing an edge and rays aim
// at an edge (every 4th) or a vertex (every 6th).
struct RandomPack {
  std::vector<Triangle> tris;
  Ray ray;
  float tmax;
};

RandomPack random_pack(std::mt19937& rng, int i, bool edge_cases, int width = 8) {
  std::uniform_real_distribution<float> u(-1, 1);
  RandomPack c;
  for (int k = 0; k < 8; ++k) c.tris.push_back({{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}});
  auto& tris = c.tris;
  if (i % 10 == 0) tris[3] = tris[2];                                // duplicates tie
  if (i % 7 == 0) tris[5] = {tris[5].v0, tris[5].v0, tris[5].v1};     // degenerate
  if (edge_cases && i % 5 == 0) tris[1].v0 = tris[0].v1, tris[1].v1 = tris[0].v0;  // a shared edge
  tris.resize(static_cast<std::size_t>(1 + i % width));
  const Triangle aim = tris[static_cast<std::size_t>(i % width % (1 + i % width))];
  const float wa = std::fabs(u(rng)), wb = edge_cases && i % 4 == 0 ? 0.0f : std::fabs(u(rng)) * (1.0f - wa);
  const Vec3f org{u(rng) * 3, u(rng) * 3, u(rng) * 3};
  const Vec3f target = edge_cases && i % 6 == 0 ? aim.v0 : aim.v0 + (aim.v1 - aim.v0) * wa + (aim.v2 - aim.v0) * wb;
  c.ray = Ray{org, 0.0f, target - org, kInf};
  if (i % 13 == 0) c.ray.dir.x = 0.0f;
  c.tmax = i % 3 ? kInf : 2.0f;
  return c;
}

// 20,000 random packs (random_pack, seeded `seed`), each traced by the SIMD
// and the scalar form of a pack test (pack(tris), then simd/scalar(case,
// packed, hit) -> lane): the same lane, and where one hits, the same t, u, v.
template <typename Pack, typename Simd, typename Scalar>
void expect_simd_answers_as_scalar(unsigned seed, bool edge_cases, int width, Simd simd, Scalar scalar) {
  std::mt19937 rng(seed);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const RandomPack c = random_pack(rng, i, edge_cases, width);
    const Pack packed = Pack::pack(c.tris);
    TriangleHit a{}, b{};
    const int lane_simd = simd(c, packed, a);
    const int lane_scalar = scalar(c, packed, b);
    ASSERT_EQ(lane_simd, lane_scalar) << "ray " << i;
    if (lane_simd < 0) continue;
    ++hits;
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.u, b.u);
    EXPECT_EQ(a.v, b.v);
  }
  EXPECT_GT(hits, 5000);
}

template <typename Pack>
void expect_triangle_pack_simd_equals_scalar() {
  expect_simd_answers_as_scalar<Pack>(
      1, false, Pack::kWidth,
      [](const RandomPack& c, const Pack& p, TriangleHit& h) { return intersect_pack_simd(c.ray, c.tmax, p, h); },
      [](const RandomPack& c, const Pack& p, TriangleHit& h) { return intersect_pack_scalar(c.ray, c.tmax, p, h); });
}

TEST(TrianglePack, Avx2AnswersExactlyAsTheScalarKernel) { expect_triangle_pack_simd_equals_scalar<TrianglePack<8>>(); }
TEST(TrianglePack, SseFourWideAnswersExactlyAsTheScalarKernel) { expect_triangle_pack_simd_equals_scalar<TrianglePack<4>>(); }
// Without stored normals the SIMD form recomputes each lane's normal with
// the scalar kernel's fused operations (prim/triangle_mt_edges.h).
TEST(TriangleEdgePack, Avx2AnswersExactlyAsTheScalarKernel) {
  expect_triangle_pack_simd_equals_scalar<TriangleEdgePack<8>>();
}
TEST(TriangleEdgePack, SseFourWideAnswersExactlyAsTheScalarKernel) {
  expect_triangle_pack_simd_equals_scalar<TriangleEdgePack<4>>();
}

template <typename BoxTest, int W>
void expect_boxes_simd_equals_scalar() {
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
    const BBoxWide<W> packed = BBoxWide<W>::pack({boxes.data(), static_cast<std::size_t>(1 + i % W)});
    const Vec3f org{u(rng) * 3, u(rng) * 3, u(rng) * 3}, target{u(rng), u(rng), u(rng)};
    Ray r{org, 0.0f, target - org, kInf};  // aimed into the region the boxes fill
    if (i % 11 == 0) {  // axis-parallel, origin on a slab plane: the NaN case
      r.dir = {0.0f, i % 2 ? 0.0f : -0.0f, 1.0f};
      r.org.x = boxes[0].lower.x;
    }
    const Slab::Precomputed pre = Slab::precompute(r);
    const float tmax = i % 5 == 0 ? 1.0f : kInf;  // clipped by tmax too
    alignas(32) float e_simd[W], e_scalar[W];
    const unsigned m_simd = intersect_boxes_simd<BoxTest>(pre, tmax, packed, e_simd);
    const unsigned m_scalar = intersect_boxes_scalar<BoxTest>(pre, tmax, packed, e_scalar);
    ASSERT_EQ(m_simd, m_scalar) << "ray " << i;
    for (int lane = 0; lane < W; ++lane)
      if (m_simd >> lane & 1) {
        EXPECT_EQ(e_simd[lane], e_scalar[lane]);
      }
    hits += __builtin_popcount(m_simd);
  }
  EXPECT_GT(hits, W == 8 ? 10000 : 5000);
}

TEST(Box8, Avx2AnswersExactlyAsTheScalarSlabTest) { expect_boxes_simd_equals_scalar<Slab, 8>(); }
TEST(Box8, Avx2AnswersExactlyAsTheScalarRobustSlabTest) { expect_boxes_simd_equals_scalar<SlabRobust, 8>(); }
TEST(Box4, SseAnswersExactlyAsTheScalarSlabTest) { expect_boxes_simd_equals_scalar<Slab, 4>(); }
TEST(Box4, SseAnswersExactlyAsTheScalarRobustSlabTest) { expect_boxes_simd_equals_scalar<SlabRobust, 4>(); }
TEST(Box8, Avx2AnswersExactlyAsTheScalarRobustRaySlabTest) { expect_boxes_simd_equals_scalar<SlabRobustRay, 8>(); }
TEST(Box4, SseAnswersExactlyAsTheScalarRobustRaySlabTest) { expect_boxes_simd_equals_scalar<SlabRobustRay, 4>(); }
TEST(Box8, Avx2AnswersExactlyAsTheScalarFusedSlabTest) { expect_boxes_simd_equals_scalar<SlabFma, 8>(); }
TEST(Box4, SseAnswersExactlyAsTheScalarFusedSlabTest) { expect_boxes_simd_equals_scalar<SlabFma, 4>(); }
// Both forms set SlabFmaRobust's offsets from the W boxes' union.
TEST(Box8, Avx2AnswersExactlyAsTheScalarFusedRobustSlabTest) { expect_boxes_simd_equals_scalar<SlabFmaRobust, 8>(); }
TEST(Box4, SseAnswersExactlyAsTheScalarFusedRobustSlabTest) { expect_boxes_simd_equals_scalar<SlabFmaRobust, 4>(); }

TEST(Watertight8, Avx2AnswersExactlyAsTheScalarWoopTestEvenThroughEdgesAndVertices) {
  expect_simd_answers_as_scalar<TriangleVertices8>(
      3, true, 8,
      [](const RandomPack& c, const TriangleVertices8& p, TriangleHit& h) {
        return intersect8_watertight_simd(WatertightTriangle::precompute(c.ray), c.tmax, p, h);
      },
      [](const RandomPack& c, const TriangleVertices8& p, TriangleHit& h) {
        return intersect8_watertight_scalar(WatertightTriangle::precompute(c.ray), c.tmax, p, h);
      });
}

// Any hit asks only for some lane that hits: the test returns one exactly
// when the closest-hit test returns a lane, and that lane hits on its own.
TEST(Watertight8, AnyLaneAnswersALaneThatHitsExactlyWhenTheClosestTestHits) {
  std::mt19937 rng(5);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const RandomPack c = random_pack(rng, i, true, 8);
    const TriangleVertices8 packed = TriangleVertices8::pack(c.tris);
    const WatertightTriangle::RayData ray = WatertightTriangle::precompute(c.ray);
    TriangleHit closest{}, unused{};
    const bool hit = intersect8_watertight_simd(ray, c.tmax, packed, closest) >= 0;
    for (const int any : {intersect8_watertight_simd<true>(ray, c.tmax, packed, unused),
                          intersect8_watertight_scalar<true>(ray, c.tmax, packed, unused)}) {
      ASSERT_EQ(any >= 0, hit) << "ray " << i;
      if (any < 0) continue;
      TriangleHit own{};
      EXPECT_TRUE(WatertightTriangle::intersect(ray, c.tmax, packed.lane(any), own)) << "ray " << i;
    }
    hits += hit;
  }
  EXPECT_GT(hits, 5000);
}
#endif

TEST(Watertight8, NoRayFromInsideAClosedMeshSlipsBetweenPacks) {
  // A closed UV sphere, packed 8 triangles at a time in order: rays from
  // near the centre at its vertices and at float points of its edges must
  // each hit some lane of some pack (Woop et al.: no cracks).
  std::vector<Triangle> sphere;
  append_uv_sphere(sphere, {0, 0, 0}, 1.0f, 24, 48);
  std::vector<TriangleVertices8> packs;
  for (std::size_t first = 0; first < sphere.size(); first += 8)
    packs.push_back(TriangleVertices8::pack({sphere.data() + first, std::min<std::size_t>(8, sphere.size() - first)}));
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-0.3f, 0.3f), s(0, 1);
  int misses = 0;
  for (int i = 0; i < 4000; ++i) {
    const Triangle& t = sphere[static_cast<std::size_t>(i * 7919) % sphere.size()];
    const Vec3f target = i % 2 ? t.v1 : t.v0 + (t.v2 - t.v0) * s(rng);
    const Vec3f org{u(rng), u(rng), u(rng)};
    const WatertightTriangle::RayData data = WatertightTriangle::precompute(Ray{org, 0.0f, target - org, kInf});
    bool hit = false;
    for (const TriangleVertices8& p : packs) {
      TriangleHit h;
      hit |= intersect8_watertight(data, kInf, p, h) >= 0;
    }
    misses += !hit;
  }
  EXPECT_EQ(misses, 0);
}

TEST(Box8, EmptyLanesAreMissed) {
  const std::vector<BBox> one{BBox{{0, 0, 0}, {1, 1, 1}}};
  alignas(32) float entry[8];
  const Slab::Precomputed r = Slab::precompute(Ray{{0.5f, 0.5f, -1}, 0, {0, 0, 1}, kInf});
  EXPECT_EQ(intersect_boxes(r, kInf, BBox8::pack(one), entry), 1u);
  EXPECT_FLOAT_EQ(entry[0], 1.0f);
}

#if defined(__AVX2__)
// load_transposed8 of W rows of 8 floats: lane i of field k is row i's element k, bit for bit
// (signed zeros and NaN payloads included), for every one of the W x 8 positions.
template <int W>
void expect_rows_transposed() {
  alignas(64) float rows[W * 8];
  for (int i = 0; i < W * 8; ++i) rows[i] = static_cast<float>(i) + 0.5f;
  rows[3] = -0.0f;
  rows[W * 8 - 1] = std::bit_cast<float>(0x7fc01234u);  // a NaN with a payload
  simd::FloatLanes<W> fields[8];
  simd::FloatLanes<W>::load_transposed8(rows, fields);
  for (int k = 0; k < 8; ++k) {
    alignas(64) float lanes[W];
    fields[k].storeu(lanes);
    for (int i = 0; i < W; ++i)
      EXPECT_EQ(std::bit_cast<std::uint32_t>(lanes[i]), std::bit_cast<std::uint32_t>(rows[i * 8 + k])) << "field " << k << " lane " << i;
  }
}
TEST(FloatLanes, EightRowsLoadTransposedIntoEightLanesPerField) { expect_rows_transposed<8>(); }
#if defined(RAYBENCH_AVX512)
TEST(FloatLanes, SixteenRowsLoadTransposedIntoSixteenLanesPerField) { expect_rows_transposed<16>(); }
#endif

// reduce_min_each / reduce_max_each: lane k is the smallest / largest lane of
// row k, for each of the 8 rows, whichever lane holds it (every position is
// tried), as reduce_min / reduce_max of that row alone.
TEST(FloatLanes, EightRowsReduceEachIntoItsOwnLane) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> u(-1e6f, 1e6f);
  for (int trial = 0; trial < 64; ++trial) {
    simd::FloatLanes<8> rows[8];
    float want_min[8], want_max[8];
    for (int k = 0; k < 8; ++k) {
      alignas(32) float row[8];
      for (float& x : row) x = u(rng);
      row[(trial + k) % 8] = -kInf * (k % 2 ? 1.0f : -1.0f);  // an infinity at each position in turn
      rows[k] = simd::FloatLanes<8>::load(row);
      want_min[k] = simd::reduce_min(rows[k]);
      want_max[k] = simd::reduce_max(rows[k]);
      EXPECT_EQ(want_min[k], *std::min_element(row, row + 8));
      EXPECT_EQ(want_max[k], *std::max_element(row, row + 8));
    }
    alignas(32) float got_min[8], got_max[8];
    simd::reduce_min_each(rows).storeu(got_min);
    simd::reduce_max_each(rows).storeu(got_max);
    for (int k = 0; k < 8; ++k) {
      EXPECT_EQ(got_min[k], want_min[k]) << "row " << k;
      EXPECT_EQ(got_max[k], want_max[k]) << "row " << k;
      alignas(32) float lanes[8];
      simd::broadcast_lane(simd::reduce_min_each(rows), k).storeu(lanes);
      for (float x : lanes) EXPECT_EQ(x, want_min[k]) << "broadcast of lane " << k;
    }
  }
}
#if defined(RAYBENCH_AVX512)
TEST(FloatLanes, AnyOfSixteenLanesBroadcastsIntoEight) {
  alignas(64) float values[16];
  for (int i = 0; i < 16; ++i) values[i] = static_cast<float>(i) - 7.5f;
  values[5] = -0.0f;
  const simd::FloatLanes<16> x = simd::FloatLanes<16>::load(values);
  for (int k = 0; k < 16; ++k) {
    alignas(32) float lanes[8];
    simd::broadcast_lane8(x, k).storeu(lanes);
    for (float v : lanes) EXPECT_EQ(std::bit_cast<std::uint32_t>(v), std::bit_cast<std::uint32_t>(values[k])) << "lane " << k;
  }
}
#endif

// Two registers of lanes (LanePair: the packets' 32 lanes with AVX-512, 16
// with AVX2): each lane as one register computes it, the comparisons' masks
// bit i for lane i (the high register's lanes in the high bits), and the
// transpose's lane i row i.
#if defined(RAYBENCH_AVX512)
using LanePairUnderTest = simd::LanePair<simd::FloatLanes<16>, 16>;
constexpr int kPairLanes = 32;
#else
using LanePairUnderTest = simd::LanePair<simd::FloatLanes<8>, 8>;
constexpr int kPairLanes = 16;
#endif
TEST(FloatLanes, TwoRegistersComputeLaneByLaneAsOne) {
  using P = LanePairUnderTest;
  alignas(64) float a[kPairLanes], b[kPairLanes], rows[kPairLanes * 8];
  for (int i = 0; i < kPairLanes; ++i) {
    a[i] = static_cast<float>(i) * 0.75f - 11.0f;
    b[i] = static_cast<float>(kPairLanes - 1 - i) * 0.5f - 3.0f;
    for (int k = 0; k < 8; ++k) rows[i * 8 + k] = static_cast<float>(i * 8 + k);
  }
  a[kPairLanes / 2 + 3] = std::numeric_limits<float>::quiet_NaN();  // in the high register
  const P x = P::load(a), y = P::load(b);
  alignas(64) float sum[kPairLanes], product[kPairLanes], fused[kPairLanes], low[kPairLanes], picked[kPairLanes];
  (x + y).storeu(sum);
  (x * y).storeu(product);
  fmsub(x, y, x).storeu(fused);
  min(x, y).storeu(low);
  const unsigned le = (x <= y).mask();
  select(x <= y, x, y).storeu(picked);
  unsigned want_le = 0;
  for (int i = 0; i < kPairLanes; ++i) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(sum[i]), std::bit_cast<std::uint32_t>(a[i] + b[i])) << i;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(product[i]), std::bit_cast<std::uint32_t>(a[i] * b[i])) << i;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(fused[i]), std::bit_cast<std::uint32_t>(std::fma(a[i], b[i], -a[i]))) << i;
    const float want_low = a[i] < b[i] ? a[i] : b[i];  // the second operand when either is NaN
    EXPECT_EQ(std::bit_cast<std::uint32_t>(low[i]), std::bit_cast<std::uint32_t>(want_low)) << i;
    want_le |= static_cast<unsigned>(a[i] <= b[i]) << i;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(picked[i]), std::bit_cast<std::uint32_t>(a[i] <= b[i] ? a[i] : b[i])) << i;
  }
  EXPECT_EQ(le, want_le);
  EXPECT_EQ(P::Mask::from_bits(want_le).mask(), want_le);
  P fields[8];
  P::load_transposed8(rows, fields);
  for (int k = 0; k < 8; ++k) {
    alignas(64) float lanes[kPairLanes];
    fields[k].storeu(lanes);
    for (int i = 0; i < kPairLanes; ++i) EXPECT_EQ(lanes[i], rows[i * 8 + k]) << "field " << k << " lane " << i;
  }
  for (int k = 0; k < kPairLanes; k += 3) {
    alignas(32) float lanes[8];
    simd::broadcast_lane8(y, k).storeu(lanes);
    for (float v : lanes) EXPECT_EQ(v, b[k]) << "broadcast of lane " << k;
  }
}
#endif

}  // namespace
}  // namespace raybench
