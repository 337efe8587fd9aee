// Our 8-wide BVH: binned-SAH BVH2 (TBB-parallel), collapsed to 8-wide nodes,
// traversed with one AVX2 slab test per node and leaves of 8 triangles tested
// at once (Möller–Trumbore, simd/triangle8.h). "bvh8" or "bvh8:mt".
#include <fmt/format.h>

#include "backends/backend_families.h"
#include "error.h"
#include "raybench/bvh/bvh8_traverse.h"

namespace raybench {
namespace {

class Bvh8Backend final : public Backend {
 public:
  explicit Bvh8Backend(std::string name) : name_(std::move(name)) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    Bvh2BuildOptions options;
    options.leaf_granularity = 8;  // leaves are tested 8 triangles at once
    bvh_ = collapse_to_bvh8(build_bvh2_binned_sah(scene.triangles, options), scene.triangles);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      hits[i] = is_traceable(rays[i]) ? intersect_bvh8(bvh_, with_nonnegative_tnear(rays[i])) : Hit{};
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      occluded[i] = is_traceable(rays[i]) && occluded_bvh8(bvh_, with_nonnegative_tnear(rays[i]));
  }

 private:
  std::string name_;
  Bvh8 bvh_;
};

}  // namespace

std::unique_ptr<Backend> make_bvh8_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig&) {
  if (options.size() > 1 || (options.size() == 1 && options[0] != "mt"))
    throw InputError("", fmt::format("backend '{}': bvh8 has one triangle test so far, mt (bvh8 or bvh8:mt)", name));
  return std::make_unique<Bvh8Backend>(name);
}

std::vector<BackendInfo> bvh8_backend_names() {
  return {{"bvh8", std::string("8-wide BVH collapsed from bvh2, ") + (kHaveAvx2 ? "AVX2" : "scalar fallback") +
                       " node and leaf tests, Moller-Trumbore leaves of 8"}};
}

}  // namespace raybench
