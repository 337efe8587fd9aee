#include "backends/bvh_options.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "error.h"
#include "raybench/bvh/bvh2_reinsertion.h"

namespace raybench {

int BvhOptions::reinsertion_passes() const { return reinsert ? Bvh2ReinsertionOptions{}.passes : 0; }

BvhOptions parse_bvh_options(const std::string& name, std::string_view family, const std::vector<std::string>& options,
                             std::span<const std::string_view> tests, std::string_view example) {
  const std::string valid = fmt::format("triangle tests: {}; builders: {}; traversal: robust; tree: {}",
                                        fmt::join(tests, ", "), bvh2_builder_names(), kReinsertOption);
  BvhOptions out;
  for (const std::string& o : options) {
    const std::optional<Bvh2Builder> as_builder = parse_bvh2_builder(o);
    const bool is_test = std::find(tests.begin(), tests.end(), o) != tests.end();
    if (o != "robust" && o != kReinsertOption && !as_builder && !is_test)
      throw InputError("", fmt::format("backend '{}': unknown option '{}' ({})", name, o, valid));
    if ((o == "robust" && out.robust) || (o == kReinsertOption && out.reinsert) || (as_builder && out.builder) ||
        (is_test && out.test))
      throw InputError("", fmt::format("backend '{}': {} takes a triangle test, a builder, 'robust' and '{}', each "
                                       "at most once, in any order, e.g. {} ({})",
                                       name, family, kReinsertOption, example, valid));
    if (o == "robust") out.robust = true;
    else if (o == kReinsertOption) out.reinsert = true;
    else if (as_builder) out.builder = as_builder;
    else out.test = o;
  }
  return out;
}

}  // namespace raybench
