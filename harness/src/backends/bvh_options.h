// The options our BVH backends take after their family name (bvh2, bvh8,
// bvh4): a triangle test, a builder (raybench/bvh/bvh2_builders.h),
// 'robust' traversal and 'reinsert', each at most once, in any order. One
// parser, so the families accept and reject names alike.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "raybench/bvh/bvh2_builders.h"

namespace raybench {

struct BvhOptions {
  std::optional<std::string> test;  // one of the family's triangle tests, if named
  std::optional<Bvh2Builder> builder;
  bool robust = false;
  bool reinsert = false;

  Bvh2Builder builder_or_default() const { return builder.value_or(Bvh2Builder::kBinnedSah); }
  // Bvh2BuildOptions::reinsertion_passes for these options.
  int reinsertion_passes() const;
};

// Parses `options` of backend `name` of `family`, whose triangle tests are
// `tests`; `example` is a valid name shown when an option repeats. Throws
// InputError naming the option and listing what is valid.
BvhOptions parse_bvh_options(const std::string& name, std::string_view family, const std::vector<std::string>& options,
                             std::span<const std::string_view> tests, std::string_view example);

}  // namespace raybench
