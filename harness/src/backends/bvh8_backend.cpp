// Our 8-wide BVH: a BVH2 (binned SAH by default, TBB-parallel), collapsed to
// 8-wide nodes, traversed with one AVX2 slab test per node and leaves of 8
// triangles tested at once. Options, in any order, each at most once:
//   a triangle test: mt (Möller–Trumbore, simd/triangle8.h, the default) or
//     watertight (Woop et al. 2013, simd/triangle8_watertight.h);
//   robust: the conservative 8-wide box test (Ize's padding), so that
//     bvh8:watertight:robust leaks no ray through the tree either;
//   a builder from raybench/bvh/bvh2_builders.h ("bvh8:sweep", "bvh8:lbvh").
#include <optional>

#include <fmt/format.h>

#include "backends/backend_families.h"
#include "error.h"
#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/bvh8_traverse.h"

namespace raybench {
namespace {

template <typename Leaf, typename BoxTest>
class Bvh8Backend final : public Backend {
 public:
  Bvh8Backend(std::string name, Bvh2Builder builder) : name_(std::move(name)), builder_(builder) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    Bvh2BuildOptions options;
    options.leaf_granularity = 8;  // leaves are tested 8 triangles at once
    bvh_ = collapse_to_bvh8(build_bvh2(scene.triangles, builder_, options), scene.triangles, Leaf::kLeaves);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  // Bvh8::sah_cost, of the 8-wide tree traced: node visits and 8-triangle
  // pack tests cost 1 each (computed here, outside the timed build).
  double sah_cost() const override { return bvh_.sah_cost(); }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      hits[i] = is_traceable(rays[i]) ? intersect_bvh8<Leaf, BoxTest>(bvh_, with_nonnegative_tnear(rays[i])) : Hit{};
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      occluded[i] = is_traceable(rays[i]) && occluded_bvh8<Leaf, BoxTest>(bvh_, with_nonnegative_tnear(rays[i]));
  }

 private:
  std::string name_;
  Bvh2Builder builder_;
  Bvh8 bvh_;
};

}  // namespace

std::unique_ptr<Backend> make_bvh8_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig&) {
  const std::string valid = fmt::format("triangle tests: mt, watertight; robust; builders: {}", bvh2_builder_names());
  std::optional<std::string> test;
  std::optional<Bvh2Builder> builder;
  bool robust = false;
  for (const std::string& o : options) {
    const std::optional<Bvh2Builder> as_builder = parse_bvh2_builder(o);
    const bool is_test = o == "mt" || o == "watertight";
    if (!is_test && !as_builder && o != "robust")
      throw InputError("", fmt::format("backend '{}': unknown option '{}' ({})", name, o, valid));
    if ((is_test && test) || (as_builder && builder) || (o == "robust" && robust))
      throw InputError("", fmt::format("backend '{}': bvh8 takes a triangle test, 'robust' and a builder, each at most "
                                       "once, in any order, e.g. bvh8:watertight:robust:sweep ({})",
                                       name, valid));
    if (as_builder) builder = as_builder;
    else if (is_test) test = o;
    else robust = true;
  }
  const Bvh2Builder b = builder.value_or(Bvh2Builder::kBinnedSah);
  if (test.value_or("mt") == "watertight") {
    if (robust) return std::make_unique<Bvh8Backend<Bvh8Watertight, SlabRobust>>(name, b);
    return std::make_unique<Bvh8Backend<Bvh8Watertight, Slab>>(name, b);
  }
  if (robust) return std::make_unique<Bvh8Backend<Bvh8MollerTrumbore, SlabRobust>>(name, b);
  return std::make_unique<Bvh8Backend<Bvh8MollerTrumbore, Slab>>(name, b);
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
  out.push_back({"bvh8:watertight", "bvh8 with 8-wide watertight leaves (Woop, Benthin & Wald 2013) [watertight]", "watertight"});
  out.push_back({"bvh8:watertight:robust",
                 "bvh8:<test>:robust traverses with the conservative 8-wide box test: no ray leaks through the tree",
                 "watertight"});
  return out;
}

}  // namespace raybench
