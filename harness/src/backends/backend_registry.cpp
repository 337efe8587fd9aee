#include <functional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "backends/backend.h"
#include "backends/backend_families.h"
#include "io/error.h"
#include "raybench/bvh/bvh2_builders.h"

namespace raybench {
namespace {

struct Family {
  std::string name;
  std::function<std::unique_ptr<Backend>(const std::string&, const std::vector<std::string>&, const BackendConfig&)> make;
  std::function<std::vector<BackendInfo>()> names;
};

// The one list of backend families.
const std::vector<Family>& families() {
  static const std::vector<Family> list = {
      {"embree", make_embree_backend, embree_backend_names},
      {"bvh2", make_bvh2_backend, bvh2_backend_names},
      {"bvh8", make_bvh8_backend, bvh8_backend_names},
      {"bvh4", make_bvh4_backend, bvh4_backend_names},
      {"reference", make_reference_backend, reference_backend_names},
  };
  return list;
}

}  // namespace

std::unique_ptr<Backend> make_backend(const std::string& name, const BackendConfig& config) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t colon = name.find(':', start);
    parts.push_back(name.substr(start, colon - start));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  for (const Family& f : families()) {
    if (f.name == parts[0]) return f.make(name, {parts.begin() + 1, parts.end()}, config);
  }
  std::vector<std::string> known;
  for (const Family& f : families()) known.push_back(f.name);
  throw InputError("", fmt::format("unknown backend '{}' (known families: {}; see 'raybench backends')", name,
                                   fmt::join(known, ", ")));
}

std::vector<BackendInfo> list_backends() {
  std::vector<BackendInfo> out;
  for (const Family& f : families()) {
    auto names = f.names();
    out.insert(out.end(), names.begin(), names.end());
  }
  return out;
}

std::string backend_accuracy_class(const std::string& name) {
  const std::vector<BackendInfo> all = list_backends();
  // A builder option or 'reinsert' (bvh2_builders.h) changes the tree, not
  // the accuracy class, and may stand anywhere: "bvh2:lbvh:mt_seed" and
  // "bvh2:reinsert:mt_seed" are in the class of "bvh2:mt_seed". Drop it
  // before looking the name up.
  std::string wanted;
  std::size_t start = 0;
  for (;;) {
    const std::size_t colon = name.find(':', start);
    const std::string part = name.substr(start, colon - start);
    if (start == 0 || !is_bvh2_tree_option(part)) wanted += (start == 0 ? "" : ":") + part;
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  for (;;) {
    for (const BackendInfo& b : all)
      if (b.name == wanted) return b.accuracy;
    const std::size_t colon = wanted.rfind(':');
    if (colon == std::string::npos) return "fast";
    wanted.resize(colon);
  }
}

}  // namespace raybench
