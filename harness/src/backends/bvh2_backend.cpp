// Our binary BVH (binned SAH) with a ray-triangle test chosen by name from
// raybench/variants.h: "bvh2" uses the first entry, "bvh2:<test>" any of them;
// a "robust" option ("bvh2:watertight:robust") traverses with the
// conservative box test (SlabRobust), which never culls a box the exact ray
// touches, so a watertight triangle test stays watertight through the tree.
#include <tuple>

#include <fmt/format.h>

#include "backends/backend_families.h"
#include "error.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/variants.h"

namespace raybench {
namespace {

template <typename Test, typename BoxTest>
class Bvh2Backend final : public Backend {
 public:
  explicit Bvh2Backend(std::string name) : name_(std::move(name)) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    bvh_ = build_bvh2_binned_sah(scene.triangles);
    prepared_.clear();
    prepared_.reserve(bvh_.prim_ids.size());
    for (std::uint32_t id : bvh_.prim_ids) prepared_.push_back(Test::prepare(scene.triangles[id]));
  }

  std::size_t memory_bytes() const override {
    return bvh_.memory_bytes() + prepared_.size() * sizeof(typename Test::Prepared);
  }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      hits[i] = is_traceable(rays[i]) ? intersect_bvh2<Test, BoxTest>(bvh_, prepared_, with_nonnegative_tnear(rays[i])) : Hit{};
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      occluded[i] = is_traceable(rays[i]) && occluded_bvh2<Test, BoxTest>(bvh_, prepared_, with_nonnegative_tnear(rays[i]));
  }

 private:
  std::string name_;
  Bvh2 bvh_;
  std::vector<typename Test::Prepared> prepared_;
};

}  // namespace

std::unique_ptr<Backend> make_bvh2_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig&) {
  std::string wanted = std::string(std::tuple_element_t<0, TriangleTests>::name);
  bool robust = false, test_named = false;
  for (const std::string& o : options) {
    if (o == "robust" && !robust) {
      robust = true;
    } else if (!test_named && o != "robust") {
      wanted = o;
      test_named = true;
    } else {
      throw InputError("", fmt::format("backend '{}': bvh2 takes a triangle test and optionally 'robust', "
                                       "e.g. bvh2:watertight:robust", name));
    }
  }
  std::unique_ptr<Backend> made;
  std::string known;
  for_each_variant<TriangleTests>([&](auto test) {
    using Test = decltype(test);
    known += (known.empty() ? "" : ", ") + std::string(Test::name);
    if (Test::name != wanted) return;
    if (robust) made = std::make_unique<Bvh2Backend<Test, SlabRobust>>(name);
    else made = std::make_unique<Bvh2Backend<Test, Slab>>(name);
  });
  if (!made) throw InputError("", fmt::format("backend '{}': unknown triangle test '{}' (known: {})", name, wanted, known));
  return made;
}

std::vector<BackendInfo> bvh2_backend_names() {
  std::vector<BackendInfo> out{{"bvh2", "our binary BVH, binned SAH build, with the default triangle test"}};
  for_each_variant<TriangleTests>([&](auto test) {
    using Test = decltype(test);
    out.push_back({"bvh2:" + std::string(Test::name), fmt::format("bvh2 with {} [{}]", Test::description, to_string(Test::accuracy)),
                   std::string(to_string(Test::accuracy))});
  });
  out.push_back({"bvh2:watertight:robust", "bvh2:<test>:robust traverses with the conservative box test (slab_robust)",
                 "watertight"});
  return out;
}

}  // namespace raybench
