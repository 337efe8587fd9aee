// Specification of the packet traversal (bvh/wide_bvh_packet.h): every ray
// gets exactly the answer of the single-ray traversal, the Hit bit for bit
// and the occlusion bit, whether it was traced in a packet or alone; and
// coherent rays (a camera's rays in 4x2 pixel blocks) are traced in packets.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_util.h"
#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/wide_bvh_batch.h"
#include "raybench/bvh/wide_bvh_packet.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

// The test mesh: the sphere cluster, plus a copy of half of it, and 11
// more copies of every 16th triangle: more than a leaf holds, so those
// copies tie exactly (the same t) across leaves with the same box, where
// only the visiting order decides which one a ray reports: the packet must
// keep the tie the single ray keeps.
std::vector<Triangle> scene_with_ties() {
  std::vector<Triangle> tris = testing::sphere_cluster();
  const std::size_t n = tris.size();
  for (std::size_t i = 0; i < n; i += 2) tris.push_back(tris[i]);
  for (std::size_t i = 0; i < n; i += 16)
    for (int copy = 0; copy < 11; ++copy) tris.push_back(tris[i]);
  return tris;
}

// A pinhole camera's rays at the mesh, W x H pixels in 4x2 blocks (8
// consecutive rays: one block), from `eye`. The middle column's direction
// has x = 0 exactly: rays with a zero component sit inside packets.
std::vector<Ray> camera_rays(Vec3f eye, int width, int height) {
  std::vector<Ray> rays;
  for (int by = 0; by < height; by += 2)
    for (int bx = 0; bx < width; bx += 4)
      for (int y = by; y < by + 2; ++y)
        for (int x = bx; x < bx + 4; ++x) {
          Ray r;
          r.org = eye;
          const float sx = static_cast<float>(x - width / 2) / static_cast<float>(width);
          const float sy = static_cast<float>(y - height / 2) / static_cast<float>(height);
          const Vec3f to = Vec3f{0, 0, 0} - eye;
          r.dir = Vec3f{to.x + sx * 8.0f, to.y + sy * 8.0f, to.z};
          if (x == width / 2) r.dir.x = 0.0f;
          rays.push_back(r);
        }
  return rays;
}

template <typename Leaf>
Bvh8 build(const std::vector<Triangle>& tris) {
  return build_wide_bvh<8, Leaf>(tris, Bvh2Builder::kBinnedSah, Bvh2Reinsertion::kLight);
}

// Shadow rays from the closest hits of `primary`, toward `light`, in the
// same order; a miss makes a ray with an empty interval (a screened-out ray).
template <typename Leaf>
std::vector<Ray> shadow_rays(const Bvh8& bvh, const std::vector<Ray>& primary, Vec3f light) {
  std::vector<Hit> hits(primary.size());
  intersect_wide_batch<Leaf, SlabFma>(bvh, primary, hits);
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < primary.size(); ++i) {
    Ray r;
    if (!hits[i].hit()) {
      r.tfar = -kInf;
      rays.push_back(r);
      continue;
    }
    r.org = primary[i].org + primary[i].dir * (hits[i].t * 0.999f);
    const Vec3f to = light - r.org;
    r.dir = normalize(to);
    r.tfar = length(to);
    rays.push_back(r);
  }
  return rays;
}

// The rays of `primary` cut short just before their closest hit: they enter
// the leaf that holds it, whose triangle lies beyond their tfar, so they
// miss it (and occlude nothing there).
template <typename Leaf>
std::vector<Ray> cut_short(const Bvh8& bvh, std::vector<Ray> primary) {
  std::vector<Hit> hits(primary.size());
  intersect_wide_batch<Leaf, SlabFma>(bvh, primary, hits);
  for (std::size_t i = 0; i < primary.size(); ++i)
    if (hits[i].hit()) primary[i].tfar = hits[i].t * 0.9999f;
  return primary;
}

// Every kind of ray the traversals must agree on, coherent and not, with
// odd rays planted inside packets: NaN, infinite and zero directions, a NaN
// origin, an empty interval, a tnear beyond the mesh; and coherent rays
// that end just before their first surface.
template <typename Leaf>
std::vector<Ray> every_ray(const Bvh8& bvh, const std::vector<Triangle>& tris) {
  const std::vector<Ray> camera = camera_rays({0.5f, 0.3f, 9.0f}, 64, 48);
  std::vector<Ray> rays = camera;
  const std::vector<Ray> inside = camera_rays({0.1f, 0.05f, 0.2f}, 32, 16);  // inside the unit sphere
  rays.insert(rays.end(), inside.begin(), inside.end());
  const std::vector<Ray> shadow = shadow_rays<Leaf>(bvh, camera, {3.0f, 6.0f, 4.0f});
  rays.insert(rays.end(), shadow.begin(), shadow.end());
  const std::vector<Ray> short_of_hits = cut_short<Leaf>(bvh, camera);
  rays.insert(rays.end(), short_of_hits.begin(), short_of_hits.end());
  for (std::string_view kind : testing::kRayKinds) {
    const std::vector<Ray> more = testing::rays_at(tris, kind, 2000, 7);
    rays.insert(rays.end(), more.begin(), more.end());
  }
  for (std::size_t i = 5; i < 3072; i += 97) {
    switch (i % 6) {
      case 0: rays[i].dir.y = kNan; break;
      case 1: rays[i].dir = {0, 0, 0}; break;
      case 2: rays[i].org.x = kNan; break;
      case 3: rays[i].tfar = rays[i].tnear - 1.0f; break;
      case 4: rays[i].tnear = 100.0f; break;
      default: rays[i].dir.z = kInf; break;
    }
  }
  return rays;
}

template <typename Leaf>
void expect_same_answers(const char* leaves) {
  SCOPED_TRACE(leaves);
  const std::vector<Triangle> tris = scene_with_ties();
  const Bvh8 bvh = build<Leaf>(tris);
  // Leaves of several packs among them (the tied copies share a box): both
  // traversals test a leaf's packs in the same order. The watertight
  // leaves hold one pack each (collapse_bvh2).
  std::size_t several_packs = 0;
  for (const WideNode<8>& node : bvh.nodes)
    for (std::uint32_t child : node.child)
      several_packs += child != Bvh8::kEmptyChild && (child & Bvh8::kLeafBit) && Bvh8::pack_count(child) > 1;
  if constexpr (Leaf::kLeaves == WideLeaves::kVertices) {
    EXPECT_EQ(several_packs, 0u);
  } else {
    EXPECT_GT(several_packs, 0u);
  }
  const std::vector<Ray> rays = every_ray<Leaf>(bvh, tris);
  std::vector<Hit> single(rays.size()), packet(rays.size());
  intersect_wide_batch<Leaf, SlabFma>(bvh, rays, single);
  intersect_packet_batch<Leaf>(bvh, rays, packet);
  std::vector<std::uint8_t> single_occ(rays.size(), 9), packet_occ(rays.size(), 9);
  occluded_wide_batch<Leaf, SlabFma>(bvh, rays, single_occ);
  occluded_packet_batch<Leaf>(bvh, rays, packet_occ);
  std::size_t hits = 0, occluded = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_EQ(std::memcmp(&single[i], &packet[i], sizeof(Hit)), 0)
        << "ray " << i << ": single t=" << single[i].t << " prim=" << single[i].prim << ", packet t=" << packet[i].t
        << " prim=" << packet[i].prim;
    ASSERT_EQ(single_occ[i], packet_occ[i]) << "ray " << i;
    hits += single[i].hit();
    occluded += single_occ[i];
  }
  // Neither all hits nor all misses: the comparison has something to compare.
  EXPECT_GT(hits, rays.size() / 4);
  EXPECT_LT(hits, rays.size());
  EXPECT_GT(occluded, rays.size() / 4);
}

TEST(WideBvhPacket, AnswersEveryRayAsTheSingleRayTraversalWithMollerTrumboreLeaves) {
  expect_same_answers<WideMollerTrumbore>("mt");
}
TEST(WideBvhPacket, AnswersEveryRayAsTheSingleRayTraversalWithEdgeLeaves) {
  expect_same_answers<WideMollerTrumboreEdges>("mt_edges");
}
TEST(WideBvhPacket, AnswersEveryRayAsTheSingleRayTraversalWithWatertightLeaves) {
  expect_same_answers<Bvh8Watertight>("watertight");
}

// Every batch length and offset (the tails of every length 1 to
// kPacketRays - 1, 31 with AVX-512, and packets that start anywhere), on the
// coherent camera rays.
TEST(WideBvhPacket, TailsOfEveryLengthAnswerAsSingleRays) {
  const std::vector<Triangle> tris = scene_with_ties();
  const Bvh8 bvh = build<WideMollerTrumbore>(tris);
  const std::vector<Ray> rays = camera_rays({0.5f, 0.3f, 9.0f}, 16, 8);
  for (std::size_t first = 0; first < 8; ++first)
    for (std::size_t n = 1; n <= kPacketRays + 1 && first + n <= rays.size(); ++n) {
      const std::span<const Ray> part(rays.data() + first, n);
      std::vector<Hit> single(n), packet(n);
      intersect_wide_batch<WideMollerTrumbore, SlabFma>(bvh, part, single);
      intersect_packet_batch<WideMollerTrumbore>(bvh, part, packet);
      std::vector<std::uint8_t> single_occ(n), packet_occ(n);
      occluded_wide_batch<WideMollerTrumbore, SlabFma>(bvh, part, single_occ);
      occluded_packet_batch<WideMollerTrumbore>(bvh, part, packet_occ);
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(std::memcmp(&single[i], &packet[i], sizeof(Hit)), 0) << "first " << first << " n " << n << " ray " << i;
        ASSERT_EQ(single_occ[i], packet_occ[i]) << "first " << first << " n " << n << " ray " << i;
      }
    }
}

TEST(WideBvhPacket, AnEmptyTreeMissesEveryRay) {
  const Bvh8 bvh = build<WideMollerTrumbore>({});
  const std::vector<Ray> rays = camera_rays({0, 0, 9}, 8, 2);
  std::vector<Hit> hits(rays.size(), Hit{1.0f, 3, 0, 0});
  std::vector<std::uint8_t> occ(rays.size(), 1);
  intersect_packet_batch<WideMollerTrumbore>(bvh, rays, hits);
  occluded_packet_batch<WideMollerTrumbore>(bvh, rays, occ);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_FALSE(hits[i].hit());
    EXPECT_EQ(occ[i], 0);
  }
}

// The grouping: a camera's 4x2 blocks go together (except the rays with a
// zero direction component, traced alone); rays in every direction do not.
TEST(WideBvhPacket, CoherentBlocksFormPacketsAndScatteredRaysDoNot) {
  const std::vector<Triangle> tris = scene_with_ties();
  const Bvh8 bvh = build<WideMollerTrumbore>(tris);
  const auto packet_rays = [&](const std::vector<Ray>& rays) {
    std::size_t in_packets = 0;
    for (std::size_t first = 0; first + kPacketRays <= rays.size(); first += kPacketRays)
      in_packets += static_cast<std::size_t>(std::popcount(packet_lanes(&rays[first], kPacketRays, bvh.bounds)));
    return static_cast<double>(in_packets) / static_cast<double>(rays.size());
  };
  // A camera of 0.19 degrees per pixel (a renderer's are finer still).
  const std::vector<Ray> camera = camera_rays({0.5f, 0.3f, 9.0f}, 256, 192);
  if (!kHaveAvx2) {  // no SIMD packets: every ray alone (the answers above are still checked)
    EXPECT_EQ(packet_rays(camera), 0.0);
    return;
  }
  // Not all: the middle column's rays, x = 0, go alone; a group that
  // straddles two octants (across the image's middle row and column) forms
  // a packet on each side.
  EXPECT_GT(packet_rays(camera), 0.95);
  EXPECT_LT(packet_rays(camera), 1.0);
  // Scattered rays: a rare lead finds two companions among the group's
  // other rays (15 or 7; among 31, about four times as often: 2 % here).
  const double rare = kPacketRays <= 16 ? 0.01 : 0.03;
  EXPECT_LT(packet_rays(testing::rays_at(tris, "inside", 4096, 3)), rare);
  EXPECT_LT(packet_rays(testing::rays_at(tris, "random", 4096, 3)), rare);
}

}  // namespace
}  // namespace raybench
