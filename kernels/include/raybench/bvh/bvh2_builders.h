// The one list of BVH2 builders, selectable by name: backends take a builder
// option ("bvh2:sweep", "bvh8:lbvh") parsed here, and tests run over
// kBvh2Builders, so adding a builder is its source file, an enum value and a
// line in each switch below.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "raybench/bvh/bvh2.h"
#include "raybench/bvh/bvh2_reinsertion.h"

namespace raybench {

enum class Bvh2Builder {
  kBinnedSah,  // the default: fast, near the sweep's quality
  kSweepSah,   // the quality reference
  kLbvh,       // fastest to build, lowest quality
  kSbvh,       // spatial splits: a triangle may be in several leaves
};

inline constexpr std::array<Bvh2Builder, 4> kBvh2Builders = {Bvh2Builder::kBinnedSah, Bvh2Builder::kSweepSah,
                                                             Bvh2Builder::kLbvh, Bvh2Builder::kSbvh};

// The option name: "binned", "sweep", "lbvh", "sbvh".
constexpr std::string_view to_string(Bvh2Builder b) {
  switch (b) {
    case Bvh2Builder::kBinnedSah: return "binned";
    case Bvh2Builder::kSweepSah: return "sweep";
    case Bvh2Builder::kLbvh: return "lbvh";
    case Bvh2Builder::kSbvh: return "sbvh";
  }
  return "?";
}

constexpr std::string_view description(Bvh2Builder b) {
  switch (b) {
    case Bvh2Builder::kBinnedSah: return "binned SAH (16 bins, TBB-parallel)";
    case Bvh2Builder::kSweepSah: return "full-sweep SAH (every centroid split, the quality reference)";
    case Bvh2Builder::kLbvh: return "LBVH (63-bit Morton codes, splits at the highest differing bit)";
    case Bvh2Builder::kSbvh: return "SBVH (binned SAH with spatial splits, Stich et al. 2009; at most 1.5x references)";
  }
  return "?";
}

// Whether the builder may place a triangle in several leaves (spatial
// splits): prim_ids then repeats it, and its leaves' boxes together cover it.
constexpr bool splits_triangles(Bvh2Builder b) {
  switch (b) {
    case Bvh2Builder::kSbvh: return true;
    case Bvh2Builder::kBinnedSah:
    case Bvh2Builder::kSweepSah:
    case Bvh2Builder::kLbvh: return false;
  }
  return false;
}

// The builder named `name` (as to_string spells it), or nothing.
constexpr std::optional<Bvh2Builder> parse_bvh2_builder(std::string_view name) {
  for (Bvh2Builder b : kBvh2Builders)
    if (to_string(b) == name) return b;
  return std::nullopt;
}

// The backend option that optimises the built tree fully by reinsertion
// ("bvh2:reinsert", "bvh8:sweep:reinsert"): Bvh2Reinsertion::kFull instead
// of the default build's kLight.
inline constexpr std::string_view kReinsertOption = "reinsert";

// Whether a backend option changes only the tree (a builder, or reinsertion),
// not what a ray hits: the accuracy class looks through it.
constexpr bool is_bvh2_tree_option(std::string_view option) {
  return option == kReinsertOption || parse_bvh2_builder(option).has_value();
}

// "binned, sweep, lbvh, sbvh": for help texts and error messages.
inline std::string bvh2_builder_names() {
  std::string out;
  for (Bvh2Builder b : kBvh2Builders) out += (out.empty() ? "" : ", ") + std::string(to_string(b));
  return out;
}

// The tree of `builder`, then options.reinsertion's reinsertion
// optimisation (bvh2_reinsertion.h), within the same depth bound.
inline Bvh2 build_bvh2(std::span<const Triangle> triangles, Bvh2Builder builder, const Bvh2BuildOptions& options = {}) {
  Bvh2 bvh = [&] {
    switch (builder) {
      case Bvh2Builder::kSweepSah: return build_bvh2_sweep_sah(triangles, options);
      case Bvh2Builder::kLbvh: return build_bvh2_lbvh(triangles, options);
      case Bvh2Builder::kSbvh: return build_bvh2_sbvh(triangles, options);
      case Bvh2Builder::kBinnedSah: break;
    }
    return build_bvh2_binned_sah(triangles, options);
  }();
  optimize_bvh2_after_build(bvh, options);
  return bvh;
}

}  // namespace raybench
