#include "backends/bvh_options.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "backends/backend.h"
#include "io/error.h"

namespace raybench {

void append_analytic_seed_names(std::vector<BackendInfo>& out, std::string_view family) {
  const auto add = [&](std::string_view option, std::string_view kernel, std::string_view instead_of, std::string_view what) {
    out.push_back({fmt::format("{}:{}", family, option),
                   fmt::format("{} judging {} with the seed note's test as written ({} instead of {}), so that its "
                               "failures show at scene level; any {} name takes :{}",
                               family, what, kernel, instead_of, family, option),
                   "epsilon"});
  };
  add(kSphereSeed, "sphere_seed", "sphere_precise", "analytic spheres");
  add(kBoxSeed, "slab_seed", "slab", "analytic boxes");
  add(kObbSeed, "obb_seed", "obb", "analytic oriented boxes");
}

BvhOptions parse_bvh_options(const std::string& name, std::string_view family, const std::vector<std::string>& options,
                             std::span<const std::string_view> tests, std::string_view example) {
  const std::string valid = fmt::format(
      "triangle tests: {}; builders: {}; box tests: {}, {}; tree: {}; analytic primitives' seed tests: {}, {}, {}{}",
      fmt::join(tests, ", "), bvh2_builder_names(), kRobustBoxes, kPlainBoxes, kReinsertOption, kSphereSeed, kBoxSeed,
      kObbSeed, family == "bvh8" ? fmt::format("; traversal: {}", kPacketTraversal) : std::string());
  BvhOptions out;
  for (const std::string& o : options) {
    const std::optional<Bvh2Builder> as_builder = parse_bvh2_builder(o);
    const bool is_test = std::find(tests.begin(), tests.end(), o) != tests.end();
    const bool is_boxes = o == kRobustBoxes || o == kPlainBoxes;
    bool* const seed = o == kSphereSeed ? &out.analytic.sphere_seed
                       : o == kBoxSeed  ? &out.analytic.box_seed
                       : o == kObbSeed  ? &out.analytic.obb_seed
                                        : nullptr;
    if (o == kPacketTraversal) {
      if (family != "bvh8")
        throw InputError("", fmt::format("backend '{}': the packet traversal is bvh8's only; use bvh8:{}", name, o));
      if (out.packet) throw InputError("", fmt::format("backend '{}': option '{}' given twice", name, o));
      out.packet = true;
      continue;
    }
    if (seed) {
      if (*seed) throw InputError("", fmt::format("backend '{}': option '{}' given twice", name, o));
      *seed = true;
      continue;
    }
    if (!is_boxes && o != kReinsertOption && !as_builder && !is_test)
      throw InputError("", fmt::format("backend '{}': unknown option '{}' ({})", name, o, valid));
    if ((is_boxes && out.robust_boxes) || (o == kReinsertOption && out.reinsert) || (as_builder && out.builder) ||
        (is_test && out.test))
      throw InputError("", fmt::format("backend '{}': {} takes a triangle test, a builder, a box test ('{}' or '{}') "
                                       "and '{}', each at most once, in any order, e.g. {} ({})",
                                       name, family, kRobustBoxes, kPlainBoxes, kReinsertOption, example, valid));
    if (is_boxes) out.robust_boxes = o == kRobustBoxes;
    else if (o == kReinsertOption) out.reinsert = true;
    else if (as_builder) out.builder = as_builder;
    else out.test = o;
  }
  return out;
}

}  // namespace raybench
