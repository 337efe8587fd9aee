// Our 8-wide BVH: a BVH2 (binned SAH by default, TBB-parallel), collapsed to
// 8-wide nodes, traversed with one AVX2 slab test per node and leaves of 8
// triangles tested at once (Möller–Trumbore, simd/triangle8.h). "bvh8" or
// "bvh8:mt"; a builder option from raybench/bvh/bvh2_builders.h picks the
// BVH2 builder ("bvh8:sweep", "bvh8:mt:lbvh"), in any order.
#include <optional>

#include <fmt/format.h>

#include "backends/backend_families.h"
#include "error.h"
#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/bvh8_traverse.h"

namespace raybench {
namespace {

class Bvh8Backend final : public Backend {
 public:
  Bvh8Backend(std::string name, Bvh2Builder builder) : name_(std::move(name)), builder_(builder) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    Bvh2BuildOptions options;
    options.leaf_granularity = 8;  // leaves are tested 8 triangles at once
    bvh_ = collapse_to_bvh8(build_bvh2(scene.triangles, builder_, options), scene.triangles);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  // Bvh8::sah_cost, of the 8-wide tree traced: node visits and 8-triangle
  // pack tests cost 1 each (computed here, outside the timed build).
  double sah_cost() const override { return bvh_.sah_cost(); }

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
  Bvh2Builder builder_;
  Bvh8 bvh_;
};

}  // namespace

std::unique_ptr<Backend> make_bvh8_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig&) {
  const std::string valid = fmt::format("triangle tests: mt; builders: {}", bvh2_builder_names());
  bool test_named = false;
  std::optional<Bvh2Builder> builder;
  for (const std::string& o : options) {
    const std::optional<Bvh2Builder> as_builder = parse_bvh2_builder(o);
    if (o != "mt" && !as_builder)
      throw InputError("", fmt::format("backend '{}': unknown option '{}' ({})", name, o, valid));
    if ((o == "mt" && test_named) || (as_builder && builder))
      throw InputError("", fmt::format("backend '{}': bvh8 takes a triangle test and a builder, each at most once, "
                                       "in any order, e.g. bvh8:mt:sweep ({})",
                                       name, valid));
    if (as_builder) builder = as_builder;
    else test_named = true;
  }
  return std::make_unique<Bvh8Backend>(name, builder.value_or(Bvh2Builder::kBinnedSah));
}

std::vector<BackendInfo> bvh8_backend_names() {
  std::vector<BackendInfo> out{{"bvh8", std::string("8-wide BVH collapsed from bvh2, ") +
                                            (kHaveAvx2 ? "AVX2" : "scalar fallback") +
                                            " node and leaf tests, Moller-Trumbore leaves of 8"}};
  for (Bvh2Builder b : kBvh2Builders) {
    if (b == Bvh2Builder::kBinnedSah) continue;  // the default: plain "bvh8"
    out.push_back({"bvh8:" + std::string(to_string(b)),
                   fmt::format("bvh8 from a BVH2 built by {}; any bvh8 name takes :<builder>", description(b))});
  }
  return out;
}

}  // namespace raybench
