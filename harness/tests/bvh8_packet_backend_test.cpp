// Specification of the bvh8:packet names (docs/backends.md, "bvh8:packet"):
// which names exist, the one-line errors for those that cannot (another width,
// the conservative box test, the option twice), that a packet name answers
// through the backend interface bit for bit as the same name without :packet,
// and that a run skips it, with a note, on scenes with analytic primitives.
// The traversal itself is specified in kernels/tests/wide_bvh_packet_test.cpp.
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "rays/rayset.h"
#include "rays/screening.h"
#include "scene/scene.h"
#include "suite/suite_run.h"
#include "test_util.h"

namespace raybench {
namespace {

std::string error_of(const std::string& name) {
  return testing::input_error_of([&] { make_backend(name); });
}

void expect_one_line_error_saying(const std::string& name, const std::string& says) {
  const std::string message = error_of(name);
  EXPECT_NE(message.find(says), std::string::npos) << name << ": " << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << name << ": " << message;
}

TEST(Bvh8PacketNames, OnlyBvh8TracesPacketsAndTheErrorNamesIt) {
  for (const char* name : {"bvh4:packet", "bvh2:packet", "bvh4:mt_edges:packet", "bvh2:watertight:packet"})
    expect_one_line_error_saying(name, "the packet traversal is bvh8's only; use bvh8:packet");
}

// The packet traversal has the plain box test (slab_fma) only; watertight
// leaves take the conservative box test by default, so they need the plain
// one named.
TEST(Bvh8PacketNames, TheConservativeBoxTestIsAnErrorAskingForPlainBoxes) {
  for (const char* name : {"bvh8:packet:robust", "bvh8:robust:packet", "bvh8:packet:watertight",
                           "bvh8:watertight:packet", "bvh8:packet:watertight:robust", "bvh8:packet:mt_edges:robust"})
    expect_one_line_error_saying(name, "the packet traversal takes the plain box test only (slab_fma); add :plain_boxes");
}

TEST(Bvh8PacketNames, PacketGivenTwiceIsAnError) {
  expect_one_line_error_saying("bvh8:packet:packet", "option 'packet' given twice");
  expect_one_line_error_saying("bvh8:packet:mt_edges:packet", "option 'packet' given twice");
}

TEST(Bvh8PacketNames, PacketCombinesWithEveryPlainBoxNameInAnyOrder) {
  for (const char* name : {"bvh8:packet", "bvh8:packet:watertight:plain_boxes", "bvh8:watertight:plain_boxes:packet",
                           "bvh8:packet:mt_edges", "bvh8:mt:packet", "bvh8:packet:plain_boxes", "bvh8:sweep:packet",
                           "bvh8:packet:sbvh:reinsert"})
    EXPECT_EQ(make_backend(name)->name(), name);
  // The box test, not the traversal, decides the accuracy class.
  EXPECT_EQ(backend_accuracy_class("bvh8:packet:watertight:plain_boxes"), "fast");
  EXPECT_EQ(backend_accuracy_class("bvh8:packet"), backend_accuracy_class("bvh8"));
}

bool same_bits(const Hit& a, const Hit& b) {
  return std::bit_cast<std::uint32_t>(a.t) == std::bit_cast<std::uint32_t>(b.t) && a.prim == b.prim &&
         std::bit_cast<std::uint32_t>(a.u) == std::bit_cast<std::uint32_t>(b.u) &&
         std::bit_cast<std::uint32_t>(a.v) == std::bit_cast<std::uint32_t>(b.v);
}

// Rays of the kinds a run traces, coherent and not, and the invalid and
// direction-scaling ones (NaN, Inf, |d| from 1e-20 to 1e20) screened as the
// harness screens them, so that empty rays sit inside packets. 4099 rays per
// kind: the last packet is partial whatever its width.
std::vector<std::vector<Ray>> rays_of_every_kind(const Scene& scene) {
  const RayGenerator generator(scene);
  std::vector<std::vector<Ray>> out;
  for (RaySetKind kind : {RaySetKind::kPrimary, RaySetKind::kPrimaryTiled, RaySetKind::kShadow, RaySetKind::kShadowTiled,
                          RaySetKind::kDiffuse, RaySetKind::kUniform, RaySetKind::kInvalid,
                          RaySetKind::kDirectionScaling, RaySetKind::kAxisParallel}) {
    RaySetSpec spec;
    spec.kind = kind;
    spec.count = 4099;
    out.push_back(screen_rays(generator.generate(spec)).rays);
  }
  return out;
}

// The guarantee: a packet name is its single-ray name traced in packets, the
// same Hit to the bit (t, primitive, u, v) and the same occlusion, for every
// leaf kind the packet traversal takes.
TEST(Bvh8PacketNames, APacketNameAnswersBitForBitAsItsSingleRayName) {
  const Scene scene = load_scene("proc:terrain_spheres_small");
  const std::vector<std::vector<Ray>> ray_sets = rays_of_every_kind(scene);
  for (const auto& [packet_name, single_name] :
       std::vector<std::pair<std::string, std::string>>{{"bvh8:packet", "bvh8"},
                                                        {"bvh8:packet:watertight:plain_boxes", "bvh8:watertight:plain_boxes"},
                                                        {"bvh8:packet:mt_edges", "bvh8:mt_edges"}}) {
    const std::unique_ptr<Backend> packet = make_backend(packet_name), single = make_backend(single_name);
    packet->build(scene);
    single->build(scene);
    std::size_t hits_seen = 0, occluded_seen = 0;
    for (const std::vector<Ray>& rays : ray_sets) {
      std::vector<Hit> packet_hits(rays.size()), single_hits(rays.size());
      packet->intersect(rays, packet_hits);
      single->intersect(rays, single_hits);
      std::vector<std::uint8_t> packet_occluded(rays.size(), 7), single_occluded(rays.size(), 9);
      packet->occluded(rays, packet_occluded);
      single->occluded(rays, single_occluded);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        ASSERT_TRUE(same_bits(packet_hits[i], single_hits[i]))
            << packet_name << " ray " << i << ": prim " << packet_hits[i].prim << " t " << packet_hits[i].t << ", "
            << single_name << ": prim " << single_hits[i].prim << " t " << single_hits[i].t;
        ASSERT_EQ(packet_occluded[i], single_occluded[i]) << packet_name << " ray " << i;
        hits_seen += single_hits[i].hit();
        occluded_seen += single_occluded[i] != 0;
      }
    }
    // The comparison means something: the rays hit and are blocked often.
    EXPECT_GT(hits_seen, 5000u) << single_name;
    EXPECT_GT(occluded_seen, 5000u) << single_name;
  }
}

// bvh8:packet models triangles only (no mixed form): a run skips it on a
// scene with analytic primitives, once, with the capability note the run
// prints and records as skipped.<scene>.<backend>, and traces bvh8 there.
TEST(Bvh8PacketNames, ARunSkipsItOnScenesWithAnalyticPrimitivesWithANote) {
  const Scene analytic = load_scene("proc:terrain_spheres_analytic_small");
  std::vector<SkippedBackend> skipped;
  EXPECT_EQ(backends_for_scene({"bvh8", "bvh8:packet", "bvh8:packet"}, analytic, skipped),
            std::vector<std::string>{"bvh8"});
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_EQ(skipped[0].backend, "bvh8:packet");
  EXPECT_EQ(skipped[0].reason,
            "backend 'bvh8:packet' models triangles only; scene 'terrain_spheres_analytic_small' has spheres");
  skipped.clear();
  EXPECT_EQ(backends_for_scene({"bvh8:packet"}, load_scene("proc:terrain_spheres_small"), skipped),
            std::vector<std::string>{"bvh8:packet"});
  EXPECT_TRUE(skipped.empty());
}

}  // namespace
}  // namespace raybench
