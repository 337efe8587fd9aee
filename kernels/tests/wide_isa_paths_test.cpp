// Specification that the wide traversal's AVX-512 leaf tests (comparisons
// into mask registers: simd/lanes.h, simd/wide_triangle.h,
// simd/triangle8_watertight.h) answer bit for bit as the AVX2 ones
// (compare-and-movemask). This file is built twice (kernels/tests/CMakeLists.txt):
// for AVX2, where it writes every answer to the file RAYBENCH_WIDE_ANSWERS
// names, and for AVX-512, where it compares its own answers with that file
// (a ctest fixture runs the writer first). The trees are built by the same
// code from the same triangles, so only the leaf tests' instructions differ.
// The rays: every kind of bvh_test_util.h on a mesh with shared edges and on
// a soup with degenerate triangles and a partly filled last pack, rays aimed
// exactly at vertices (the watertight test's exact lanes), axis-parallel,
// NaN, infinite, empty-interval and zero-direction rays.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_util.h"

#include "raybench/bvh/wide_bvh_batch.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

std::vector<Ray> every_ray_kind(const std::vector<Triangle>& tris) {
  std::vector<Ray> rays;
  unsigned seed = 70;
  for (std::string_view kind : testing::kRayKinds) {
    const std::vector<Ray> some = testing::rays_at(tris, kind, 3000, seed++);
    rays.insert(rays.end(), some.begin(), some.end());
  }
  // Exactly at vertices and edge midpoints, from outside and from the origin.
  std::mt19937 rng(71);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t i = 0; i < tris.size(); i += 7) {
    const Vec3f org{u(rng) * 9, u(rng) * 9, u(rng) * 9};
    rays.push_back(Ray{org, 0.0f, tris[i].v0 - org, kInf});
    rays.push_back(Ray{{0, 0, 0}, 0.0f, (tris[i].v1 + tris[i].v2) * 0.5f, kInf});
  }
  // Axis-parallel (either sign of zero), and rays the backends would not
  // trace (NaN, infinite, empty intervals, no direction): the traversal
  // must still answer the same on both paths.
  for (int i = 0; i < 300; ++i) {
    Ray r{{u(rng) * 3, u(rng) * 3, u(rng) * 3}, 0.0f, {u(rng), u(rng), u(rng)}, kInf};
    r.dir[i % 3] = i % 2 ? 0.0f : -0.0f;
    if (i % 5 == 0) r.dir[(i + 1) % 3] = 0.0f;
    rays.push_back(r);
  }
  const Ray odd[] = {
      {{0, 0, 0}, 0.0f, {kNan, 1, 0}, kInf},   {{kNan, 0, 0}, 0.0f, {1, 1, 1}, kInf},
      {{0, 0, 0}, kNan, {1, 1, 1}, kInf},      {{0, 0, 0}, 0.0f, {1, 1, 1}, kNan},
      {{0, 0, 0}, 0.0f, {0, 0, 0}, kInf},      {{-kInf, 0, 0}, 0.0f, {1, 0, 0}, kInf},
      {{0, 0, 0}, 0.0f, {kInf, 1, 0}, kInf},   {{0, 0, 0}, 5.0f, {1, 1, 1}, 2.0f},
      {{0, 0, 0}, -3.0f, {1, 0.5f, 0.25f}, kInf}, {{0, 0, 0}, 0.0f, {1e-30f, 1e-30f, 1}, kInf},
      {{0, 0, 0}, 0.0f, {1, 1, 1}, 0.0f},      {{20, 20, 20}, 0.0f, {-1, -1, -1}, kInf},
  };
  rays.insert(rays.end(), std::begin(odd), std::end(odd));
  return rays;
}

// Every answer of one configuration as 32-bit words: per ray the closest
// hit (t, prim, u, v bit patterns) from the traversal as called directly,
// the same through the backends' batch, then both any-hit answers.
// Returns how many rays hit (closest hit, through the batch).
template <int W, typename Leaf, typename BoxTest>
std::size_t append_answers(const std::vector<Triangle>& tris, const std::vector<Ray>& rays, std::vector<std::uint32_t>& words) {
  const WideBvh<W> bvh = build_wide_bvh<W, Leaf>(tris, Bvh2Builder::kBinnedSah, Bvh2Reinsertion::kLight);
  std::vector<Hit> batch(rays.size());
  std::vector<std::uint8_t> occluded(rays.size());
  intersect_wide_batch<Leaf, BoxTest>(bvh, rays, batch);
  occluded_wide_batch<Leaf, BoxTest>(bvh, rays, occluded);
  const auto put = [&](const Hit& h) {
    for (const float f : {h.t, h.u, h.v}) {
      std::uint32_t bits;
      std::memcpy(&bits, &f, sizeof bits);
      words.push_back(bits);
    }
    words.push_back(static_cast<std::uint32_t>(h.prim));
  };
  for (std::size_t i = 0; i < rays.size(); ++i) {
    put(intersect_wide<Leaf, BoxTest>(bvh, rays[i]));
    put(batch[i]);
    words.push_back(occluded_wide<Leaf, BoxTest>(bvh, rays[i]));
    words.push_back(occluded[i]);
  }
  return static_cast<std::size_t>(std::count_if(batch.begin(), batch.end(), [](const Hit& h) { return h.hit(); }));
}

std::vector<std::uint32_t> all_answers() {
  std::vector<std::uint32_t> words;
  const std::vector<Triangle> scenes[] = {testing::sphere_cluster(), testing::random_soup(4001, 72)};
  for (const std::vector<Triangle>& tris : scenes) {
    const std::vector<Ray> rays = every_ray_kind(tris);
    const std::size_t hits[] = {
        append_answers<8, WideMollerTrumbore, SlabFma>(tris, rays, words),
        append_answers<8, Bvh8Watertight, SlabRobustRay>(tris, rays, words),
        append_answers<8, WideMollerTrumboreEdges, SlabFma>(tris, rays, words),
        append_answers<4, WideMollerTrumbore, SlabFma>(tris, rays, words),
        append_answers<8, WideMollerTrumbore, Slab>(tris, rays, words),
        append_answers<8, WideMollerTrumbore, SlabRobust>(tris, rays, words),
    };
    for (const std::size_t h : hits) EXPECT_GT(h, rays.size() / 4);  // many hits, not only misses
  }
  return words;
}

TEST(WideIsaPaths, Avx512AnswersEveryRayBitForBitAsAvx2) {
  const char* path = std::getenv("RAYBENCH_WIDE_ANSWERS");
  if (path == nullptr) GTEST_SKIP() << "RAYBENCH_WIDE_ANSWERS names no answers file (ctest sets it)";
  const std::vector<std::uint32_t> words = all_answers();
  ASSERT_GT(words.size(), 100000u);
#if defined(RAYBENCH_AVX512)
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << "no answers of the AVX2 path at " << path << " (its test, Avx2.WideIsaPaths.*, writes them)";
  std::vector<std::uint32_t> avx2(words.size() + 1);
  in.read(reinterpret_cast<char*>(avx2.data()), static_cast<std::streamsize>(avx2.size() * sizeof(std::uint32_t)));
  ASSERT_EQ(static_cast<std::size_t>(in.gcount()), words.size() * sizeof(std::uint32_t)) << "answers of another size";
  avx2.pop_back();
  std::size_t differing = 0, first = words.size();
  for (std::size_t i = 0; i < words.size(); ++i)
    if (words[i] != avx2[i]) differing += 1, first = std::min(first, i);
  EXPECT_EQ(differing, 0u) << "first at word " << first << " (10 per ray per configuration)";
#elif defined(__AVX2__)
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(words.data()), static_cast<std::streamsize>(words.size() * sizeof(std::uint32_t)));
  ASSERT_TRUE(out.good()) << "could not write " << path;
#else
  GTEST_FAIL() << "built for neither AVX2 nor AVX-512";
#endif
}

}  // namespace
}  // namespace raybench
