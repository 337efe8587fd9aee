// Specification of the builders' shared binning (kernels/src/bvh2_build_util.h):
// every reference lands in its centroid_bin on each axis and extends that
// bin's box as BBox::extend would (NaN coordinates and signed zeros alike),
// and a range binned in parallel chunks gets the bins of one pass over it;
// the three axes' bins swept at once choose the split of the sweep axis by
// axis, to the bit.
// Built twice (CMakeLists.txt): with AVX, and as a machine without it.
#include "../src/bvh2_build_util.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

namespace raybench::bvh2_build {
namespace {

struct Ref {
  BBox bounds;
};

// Random boxes in [-10, 10]^3, every 97th with a NaN coordinate, every 89th
// a point, and a run of equal boxes (one bin's worth of ties).
std::vector<Ref> random_refs(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-10.0f, 10.0f), size(0.0f, 2.0f);
  std::vector<Ref> refs(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f lower{pos(rng), pos(rng), pos(rng)};
    refs[i].bounds = {lower, lower + Vec3f{size(rng), size(rng), size(rng)}};
    if (i % 89 == 0) refs[i].bounds.upper = lower;
    if (i % 97 == 0) refs[i].bounds.lower[static_cast<int>(i % 3)] = std::numeric_limits<float>::quiet_NaN();
    if (i >= n / 2 && i < n / 2 + 300) refs[i].bounds = refs[n / 2].bounds;
    // Zeros of both signs, of which min and max keep the one BBox::extend keeps.
    if (i % 7 == 0) refs[i].bounds.lower.y = (i % 14 == 0) ? -0.0f : 0.0f;
    if (i % 11 == 0) refs[i].bounds.upper.z = (i % 22 == 0) ? 0.0f : -0.0f;
  }
  return refs;
}

bool same_float(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }
bool same_bits(float a, float b) { return same_float(a, b) && std::signbit(a) == std::signbit(b); }

TEST(BinAllAxes, PutsEachReferenceInItsCentroidBinAndExtendsTheBinAsBBoxExtend) {
  constexpr std::size_t kBins = 16;
  for (const std::size_t n : {std::size_t{1}, std::size_t{37}, std::size_t{5001}}) {
    for (const int bins : {8, 11, 16}) {
      SCOPED_TRACE(testing::Message() << n << " references, " << bins << " bins");
      const std::vector<Ref> refs = random_refs(n, static_cast<unsigned>(n + 7));
      const float lo[3] = {-10.0f, -9.0f, -11.0f};
      const float scale[3] = {bins / 20.0f, bins / 19.0f, bins / 21.0f};
      std::array<std::array<BBox, kBins>, 3> expected_bounds{}, bounds{};
      std::array<std::array<std::size_t, kBins>, 3> expected_count{}, count{};
      for (const Ref& r : refs) {
        const Vec3f c = r.bounds.center();
        for (int axis = 0; axis < 3; ++axis) {
          const int b = centroid_bin(c[axis], lo[axis], scale[axis], bins);
          expected_bounds[axis][b].extend(r.bounds);
          ++expected_count[axis][b];
        }
      }
      bin_all_axes<kBins>(std::span<const Ref>(refs), lo, scale, bins, bounds, count);
      for (int axis = 0; axis < 3; ++axis)
        for (int b = 0; b < bins; ++b) {
          EXPECT_EQ(count[axis][b], expected_count[axis][b]) << "axis " << axis << " bin " << b;
          for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(same_bits(bounds[axis][b].lower[k], expected_bounds[axis][b].lower[k])) << axis << " " << b;
            EXPECT_TRUE(same_bits(bounds[axis][b].upper[k], expected_bounds[axis][b].upper[k])) << axis << " " << b;
          }
        }
    }
  }
}

TEST(BinAllAxes, InParallelChunksGivesTheBinsOfOnePassForAnyThreadCount) {
  constexpr std::size_t kBins = 16;
  for (const std::size_t n : {2 * kBinningChunk, std::size_t{5001}, std::size_t{40000}}) {
    SCOPED_TRACE(n);
    const std::vector<Ref> refs = random_refs(n, static_cast<unsigned>(n));
    const float lo[3] = {-10.0f, -9.0f, -11.0f}, scale[3] = {0.8f, 0.7f, 0.75f};
    std::array<std::array<BBox, kBins>, 3> one_bounds{}, chunk_bounds{};
    std::array<std::array<std::size_t, kBins>, 3> one_count{}, chunk_count{};
    bin_all_axes<kBins>(std::span<const Ref>(refs), lo, scale, 16, one_bounds, one_count);
    for (const int threads : {1, 2}) {
      SCOPED_TRACE(threads);
      tbb::task_arena(threads).execute([&] {
        bin_all_axes_in_chunks<kBins>(std::span<const Ref>(refs), lo, scale, 16, chunk_bounds, chunk_count);
      });
      std::size_t total = 0;
      for (int axis = 0; axis < 3; ++axis)
        for (std::size_t b = 0; b < kBins; ++b) {
          EXPECT_EQ(chunk_count[axis][b], one_count[axis][b]) << "axis " << axis << " bin " << b;
          total += chunk_count[axis][b];
          for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(same_float(chunk_bounds[axis][b].lower[k], one_bounds[axis][b].lower[k])) << axis << " " << b;
            EXPECT_TRUE(same_float(chunk_bounds[axis][b].upper[k], one_bounds[axis][b].upper[k])) << axis << " " << b;
          }
        }
      EXPECT_EQ(total, 3 * n) << "every reference binned once per axis";
    }
  }
}


// The bins of random references, binned as a node of the builder would be.
template <std::size_t Bins>
void bin_randomly(std::size_t n, unsigned seed, int bins, std::array<std::array<BBox, Bins>, 3>& bounds,
                  std::array<std::array<std::size_t, Bins>, 3>& count) {
  const std::vector<Ref> refs = random_refs(n, seed);
  const float lo[3] = {-10.0f, -9.0f, -11.0f};
  const float scale[3] = {static_cast<float>(bins) / 21.0f, static_cast<float>(bins) / 19.0f,
                          static_cast<float>(bins) / 23.0f};
  bounds = {};
  count = {};
  bin_all_axes<Bins>(std::span<const Ref>(refs), lo, scale, bins, bounds, count);
}

TEST(BestSplitOfBins, SweepingTheThreeAxesAtOnceChoosesTheSplitOfTheSweepAxisByAxisToTheBit) {
  constexpr std::size_t kBins = 32;
  int compared = 0;
  for (const std::size_t n : {std::size_t{2}, std::size_t{9}, std::size_t{40}, std::size_t{700}, std::size_t{5000}})
    for (const int bins : {8, 16, 32})
      for (const int granularity : {1, 4, 8})
        for (unsigned seed = 1; seed <= 4; ++seed) {
          SCOPED_TRACE(::testing::Message() << n << " refs, " << bins << " bins, granularity " << granularity);
          std::array<std::array<BBox, kBins>, 3> bounds;
          std::array<std::array<std::size_t, kBins>, 3> count;
          bin_randomly<kBins>(n, seed, bins, bounds, count);
          // Some of the bins emptied and NaN-boxed, some axes not splittable.
          if (seed == 2) bounds[1][3] = BBox{};
          if (seed == 3) bounds[2][1].upper.x = std::numeric_limits<float>::quiet_NaN();
          const bool splittable[3] = {seed != 4, true, seed % 2 == 1};
          const ObjectSplit got = best_split_of_bins<kBins>(bounds, count, splittable, bins, granularity, n);
          const ObjectSplit want = best_split_of_bins_by_axis<kBins>(bounds, count, splittable, bins, granularity, n);
          ASSERT_EQ(got.axis, want.axis);
          if (want.axis < 0) continue;
          ++compared;
          EXPECT_EQ(got.bin, want.bin);
          EXPECT_TRUE(same_bits(got.cost, want.cost)) << got.cost << " " << want.cost;
          for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(same_bits(got.left.lower[k], want.left.lower[k]));
            EXPECT_TRUE(same_bits(got.left.upper[k], want.left.upper[k]));
            EXPECT_TRUE(same_bits(got.right.lower[k], want.right.lower[k]));
            EXPECT_TRUE(same_bits(got.right.upper[k], want.right.upper[k]));
          }
        }
  EXPECT_GT(compared, 150);
}

// Equal costs everywhere: eight equal boxes, one per bin, cost as much cut
// at any plane, on either splittable axis. The first axis's split is
// chosen, and on it the first plane.
TEST(BestSplitOfBins, OfEqualCostsTheFirstAxisAndTheFirstPlaneAreChosen) {
  constexpr std::size_t kBins = 16;
  std::array<std::array<BBox, kBins>, 3> bounds{};
  std::array<std::array<std::size_t, kBins>, 3> count{};
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < 8; ++b) {
      bounds[axis][b] = BBox{{0, 0, 0}, {1, 1, 1}};
      count[axis][b] = 1;
    }
  const bool splittable[3] = {false, true, true};
  for (const auto& split : {best_split_of_bins<kBins>(bounds, count, splittable, 8, 1, 8),
                            best_split_of_bins_by_axis<kBins>(bounds, count, splittable, 8, 1, 8)}) {
    EXPECT_EQ(split.axis, 1);
    EXPECT_EQ(split.bin, 0);  // left: bin 0 alone
    EXPECT_EQ(split.cost, 3.0f * 1 + 3.0f * 7);
  }
}

}  // namespace
}  // namespace raybench::bvh2_build
