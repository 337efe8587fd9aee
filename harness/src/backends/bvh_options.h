// The options our BVH backends take after their family name (bvh2, bvh8,
// bvh4): a triangle test, a builder (raybench/bvh/bvh2_builders.h), a box
// test ('robust' or 'plain_boxes'), 'reinsert', 'packet' (bvh8's packet
// traversal of coherent rays), and the seed-faithful tests
// of analytic primitives ('sphere_seed', 'box_seed', 'obb_seed': SphereSeed,
// SlabSeed, ObbSeed instead of SpherePrecise, Slab, Obb in the leaves of a
// scene with analytic primitives, raybench/bvh/mixed_leaf.h), each at most
// once, in any order. One parser, so the families accept and reject names
// alike.
//
// The box test decides whether a watertight triangle test stays watertight
// through the tree: the plain slab test culls, by rounding, boxes that a ray
// through a shared vertex or edge touches (bvh8 with watertight leaves and
// plain boxes misses 4.8 % of proc:sphere's vertex-aimed rays); the
// conservative one never does. So a name with the watertight test and no box
// test ("bvh8:watertight") gets the conservative one: a backend named
// watertight leaks no ray. "plain_boxes" names the fast, leaky combination;
// "robust" with the watertight test is accepted and changes nothing.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/analytic_test_choice.h"

namespace raybench {

inline constexpr std::string_view kWatertightTest = "watertight";  // prim/triangle_watertight.h's name
inline constexpr std::string_view kRobustBoxes = "robust";
inline constexpr std::string_view kPlainBoxes = "plain_boxes";
inline constexpr std::string_view kSphereSeed = "sphere_seed";  // prim/sphere_seed.h's name
inline constexpr std::string_view kBoxSeed = "box_seed";        // SlabSeed (prim/aabb_slab_seed.h) as the box primitives' test
inline constexpr std::string_view kObbSeed = "obb_seed";        // prim/obb_seed.h's name
inline constexpr std::string_view kPacketTraversal = "packet";  // bvh8 only: raybench/bvh/wide_bvh_packet.h

struct BvhOptions {
  std::optional<std::string> test;  // one of the family's triangle tests, if named
  std::optional<Bvh2Builder> builder;
  std::optional<bool> robust_boxes;  // true: 'robust', false: 'plain_boxes'; unset: neither named
  bool reinsert = false;
  bool packet = false;  // 'packet': coherent rays traced in packets (bvh8 only)
  AnalyticTestChoice analytic;  // the tests of analytic primitives (scenes that have them)

  Bvh2Builder builder_or_default() const { return builder.value_or(Bvh2Builder::kBinnedSah); }
  // Traversal with the conservative box test: when 'robust' is named, or
  // with the watertight triangle test unless 'plain_boxes' is named.
  bool robust() const { return robust_boxes.value_or(test == kWatertightTest); }
  // Bvh2BuildOptions::reinsertion for these options: the full optimisation
  // with 'reinsert', else the default build's light batch.
  Bvh2Reinsertion reinsertion() const { return reinsert ? Bvh2Reinsertion::kFull : Bvh2Reinsertion::kLight; }
};

struct BackendInfo;

// Appends the names of `family` with each seed-faithful test of analytic
// primitives ("bvh2:sphere_seed", ...), for `raybench backends`: accuracy
// class epsilon, as every seed-faithful backend; not kernel variants of the
// family ("bvh2:*" names triangle tests).
void append_analytic_seed_names(std::vector<BackendInfo>& out, std::string_view family);

// Parses `options` of backend `name` of `family`, whose triangle tests are
// `tests`; `example` is a valid name shown when an option repeats. Throws
// InputError naming the option and listing what is valid.
BvhOptions parse_bvh_options(const std::string& name, std::string_view family, const std::vector<std::string>& options,
                             std::span<const std::string_view> tests, std::string_view example);

}  // namespace raybench
