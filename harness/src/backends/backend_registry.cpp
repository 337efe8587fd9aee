// The registry of backend families. Each family registers itself from its
// own file (RAYBENCH_BACKEND_FAMILY, backend.h); this file knows none of them.
#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "backends/backend.h"
#include "io/error.h"
#include "raybench/bvh/bvh2_builders.h"

namespace raybench {
namespace {

struct Family {
  std::string name;
  int order;
  BackendFactory make;
  BackendNames names;
};

// Built while the program starts, by the families' registrars, in whatever
// order the linker placed their files; kept sorted by (order, name). A
// function-local static, so it exists before the first registrar runs.
std::vector<Family>& families() {
  static std::vector<Family> list;
  return list;
}

std::string known_families() {
  std::vector<std::string> known;
  for (const Family& f : families()) known.push_back(f.name);
  return fmt::format("known families: {}; see 'raybench backends'", fmt::join(known, ", "));
}

}  // namespace

bool register_backend_family(std::string family, int order, BackendFactory make, BackendNames names) {
  std::vector<Family>& list = families();
  for (const Family& f : list)
    if (f.name == family) throw std::logic_error(fmt::format("backend family '{}' registered twice", family));
  const auto at = std::find_if(list.begin(), list.end(), [&](const Family& f) {
    return f.order > order || (f.order == order && f.name > family);
  });
  list.insert(at, Family{std::move(family), order, make, names});
  return true;
}

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
  throw InputError("", fmt::format("unknown backend '{}' ({})", name, known_families()));
}

std::vector<BackendInfo> list_backends() {
  std::vector<BackendInfo> out;
  for (const Family& f : families()) {
    auto names = f.names();
    out.insert(out.end(), names.begin(), names.end());
  }
  return out;
}

std::vector<std::string> expand_backend_patterns(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::vector<BackendInfo> all;
  for (const std::string& name : names) {
    if (name.size() < 2 || name.compare(name.size() - 2, 2, ":*") != 0) {
      out.push_back(name);
      continue;
    }
    const std::string family = name.substr(0, name.size() - 2);
    const auto known = std::find_if(families().begin(), families().end(), [&](const Family& f) { return f.name == family; });
    if (known == families().end())
      throw InputError("", fmt::format("unknown backend family '{}' in '{}' ({})", family, name, known_families()));
    if (all.empty()) all = list_backends();
    const std::size_t before = out.size();
    for (const BackendInfo& b : all)
      if (b.variant && b.name.rfind(family + ":", 0) == 0) out.push_back(b.name);
    if (out.size() == before)
      throw InputError("", fmt::format("backend pattern '{}': {} has no kernel variants to expand; name its backends "
                                       "(see 'raybench backends')",
                                       name, family));
  }
  return out;
}

std::string backend_accuracy_class(const std::string& name) {
  // A plugin's class is what the library reports (loaded once per process):
  // its name lists no class.
  if (name.rfind("plugin:", 0) == 0) return make_backend(name)->accuracy_class();
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
