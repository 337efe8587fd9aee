#include "backends/mixed_bvh_backends.h"

#include <array>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "backends/analytic_dispatch.h"
#include "backends/bvh_options.h"
#include "io/error.h"
#include "raybench/bvh/mixed_bvh2.h"
#include "raybench/bvh/mixed_wide_bvh.h"
#include "raybench/bvh/wide_bvh_batch.h"
#include "raybench/prim/aabb_slab_fma.h"
#include "raybench/prim/aabb_slab_robust.h"
#include "raybench/prim/aabb_slab_robust_ray.h"
#include "raybench/variants.h"

namespace raybench {
namespace {

enum class OurBvhFamily { kBvh2, kBvh8, kBvh4 };

// Analytic primitives enter the tree by their boxes, which only the binned
// builder takes (build_bvh2_binned_sah over BBox): the others refuse in one line.
void require_binned_builder(const std::string& backend, const Scene& scene, Bvh2Builder builder) {
  if (builder != Bvh2Builder::kBinnedSah)
    throw InputError("", fmt::format("backend '{}' cannot build scene '{}': its analytic primitives are built over "
                                     "their boxes by the binned builder only; drop ':{}'",
                                     backend, scene.name, to_string(builder)));
}

// bvh2 for scenes with analytic primitives.
template <typename Test, typename BoxTest>
class MixedBvh2Backend final : public Backend {
 public:
  MixedBvh2Backend(std::string name, Bvh2Builder builder, const Bvh2BuildOptions& options, AnalyticTestChoice analytic)
      : name_(std::move(name)), builder_(builder), options_(options), analytic_(analytic) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    require_binned_builder(name_, scene, builder_);
    bvh_ = {};  // the old tree freed first
    bvh_ = build_mixed_bvh2<Test>(scene.primitives(), options_, analytic_);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  // Bvh2::sah_cost: inner nodes and single primitive tests cost 1 each.
  double sah_cost() const override { return bvh_.bvh.sah_cost(); }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      hits[i] = intersect_mixed_bvh2<Test, BoxTest>(bvh_, rays[i]);  // screened rays (backend.h)
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      occluded[i] = occluded_mixed_bvh2<Test, BoxTest>(bvh_, rays[i]);
  }

 private:
  std::string name_;
  Bvh2Builder builder_;
  Bvh2BuildOptions options_;
  AnalyticTestChoice analytic_;
  MixedBvh2<Test> bvh_;
};

// bvh8, bvh4 for scenes with analytic primitives.
template <int W, typename Leaf, typename BoxTest>
class MixedWideBvhBackend final : public Backend {
 public:
  MixedWideBvhBackend(std::string name, Bvh2Builder builder, Bvh2Reinsertion reinsertion, AnalyticTestChoice analytic)
      : name_(std::move(name)), builder_(builder), reinsertion_(reinsertion), analytic_(analytic) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    require_binned_builder(name_, scene, builder_);
    bvh_ = {};  // the old tree freed first
    bvh_ = build_mixed_wide_bvh<W, Leaf>(scene.primitives(), reinsertion_, analytic_);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  // WideBvh::sah_cost: node visits and pack tests cost 1 each, whatever
  // primitives a pack holds.
  double sah_cost() const override { return bvh_.sah_cost(); }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    intersect_wide_batch<MixedWideLeaf<Leaf>, BoxTest>(bvh_, rays, hits);
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    occluded_wide_batch<MixedWideLeaf<Leaf>, BoxTest>(bvh_, rays, occluded);
  }

 private:
  std::string name_;
  Bvh2Builder builder_;
  Bvh2Reinsertion reinsertion_;
  AnalyticTestChoice analytic_;
  MixedWideBvh<W> bvh_;
};

template <int W, typename Leaf>
std::unique_ptr<Backend> make_wide(bool robust, const std::string& name, Bvh2Builder builder, Bvh2Reinsertion reinsertion,
                                   AnalyticTestChoice analytic) {
  if (robust) return std::make_unique<MixedWideBvhBackend<W, Leaf, SlabRobustRay>>(name, builder, reinsertion, analytic);
  return std::make_unique<MixedWideBvhBackend<W, Leaf, SlabFma>>(name, builder, reinsertion, analytic);
}

// The wide backends' triangle leaves.
enum class MixedWideLeaves { kMollerTrumbore, kMollerTrumboreEdges, kWatertight /* 8 wide only */ };

template <int W>
std::unique_ptr<Backend> make_wide_of_width(MixedWideLeaves leaves, bool robust, const std::string& name,
                                            Bvh2Builder builder, Bvh2Reinsertion reinsertion, AnalyticTestChoice analytic) {
  switch (leaves) {
    case MixedWideLeaves::kMollerTrumbore:
      return make_wide<W, WideMollerTrumbore>(robust, name, builder, reinsertion, analytic);
    case MixedWideLeaves::kMollerTrumboreEdges:
      return make_wide<W, WideMollerTrumboreEdges>(robust, name, builder, reinsertion, analytic);
    case MixedWideLeaves::kWatertight:
      if constexpr (W == 8) return make_wide<8, Bvh8Watertight>(robust, name, builder, reinsertion, analytic);
      break;
  }
  throw std::logic_error("make_mixed: watertight leaves are 8 wide only");
}

std::unique_ptr<Backend> make_bvh2(const std::string& name, std::string_view test, bool robust, Bvh2Builder builder,
                                   const Bvh2BuildOptions& options, AnalyticTestChoice analytic) {
  std::unique_ptr<Backend> made;
  for_each_variant<TriangleTests>([&](auto variant) {
    using Test = decltype(variant);
    if (Test::name != test) return;
    if (robust) made = std::make_unique<MixedBvh2Backend<Test, SlabRobust>>(name, builder, options, analytic);
    else made = std::make_unique<MixedBvh2Backend<Test, Slab>>(name, builder, options, analytic);
  });
  if (!made) throw std::logic_error(fmt::format("make_mixed: no triangle test '{}'", test));
  return made;
}

Capabilities every_type() {
  Capabilities c;
  c.spheres = c.boxes = c.oriented_boxes = true;
  return c;
}

// The family of OurBvhFamily: its name, its triangle tests (the options its
// factory parses: bvh_options.h), its factory and names as registered.
struct Family {
  std::string_view name;
  BackendFactory make = nullptr;
  BackendNames names = nullptr;
};
std::array<Family, 3>& families() {
  static std::array<Family, 3> f{{{"bvh2"}, {"bvh8"}, {"bvh4"}}};
  return f;
}

std::vector<std::string_view> triangle_tests(OurBvhFamily family) {
  if (family == OurBvhFamily::kBvh2) {
    std::vector<std::string_view> tests;
    for_each_variant<TriangleTests>([&](auto test) { tests.push_back(decltype(test)::name); });
    return tests;
  }
  if (family == OurBvhFamily::kBvh8) return {"mt", "mt_edges", "watertight"};
  return {"mt", "mt_edges"};
}

// The options the family's factory has just accepted.
BvhOptions parse(OurBvhFamily family, const std::string& name, const std::vector<std::string>& options) {
  const std::string_view family_name = families()[static_cast<std::size_t>(family)].name;
  return parse_bvh_options(name, family_name, options, triangle_tests(family), family_name);
}

// The mixed backend of those options: the same triangle test, box test,
// builder and reinsertion, and the analytic tests they choose.
std::unique_ptr<Backend> make_mixed(OurBvhFamily family, const std::string& name,
                                    const std::vector<std::string>& options) {
  const std::vector<std::string_view> tests = triangle_tests(family);
  const BvhOptions parsed = parse(family, name, options);
  const Bvh2Builder builder = parsed.builder_or_default();
  if (family == OurBvhFamily::kBvh2) {
    Bvh2BuildOptions build_options;
    build_options.reinsertion = parsed.reinsertion();
    const std::string test = parsed.test.value_or(std::string(tests.front()));
    return make_bvh2(name, test, parsed.robust(), builder, build_options, parsed.analytic);
  }
  const MixedWideLeaves leaves = parsed.test == kWatertightTest                ? MixedWideLeaves::kWatertight
                                 : parsed.test.value_or("mt") == "mt_edges" ? MixedWideLeaves::kMollerTrumboreEdges
                                                                            : MixedWideLeaves::kMollerTrumbore;
  if (family == OurBvhFamily::kBvh8)
    return make_wide_of_width<8>(leaves, parsed.robust(), name, builder, parsed.reinsertion(), parsed.analytic);
  return make_wide_of_width<4>(leaves, parsed.robust(), name, builder, parsed.reinsertion(), parsed.analytic);
}

template <OurBvhFamily F>
std::unique_ptr<Backend> make_with_analytic(const std::string& name, const std::vector<std::string>& options,
                                            const BackendConfig& config) {
  std::unique_ptr<Backend> triangles = families()[static_cast<std::size_t>(F)].make(name, options, config);
  // Only the binned builder takes primitive boxes: with another the pair
  // models triangles only, and the run skips it on scenes with analytic
  // primitives (its build() of one refuses it).
  // The packet traversal has no mixed form: bvh8:packet models triangles
  // only, and the run skips it on such scenes with a note, as above.
  const BvhOptions parsed = parse(F, name, options);
  const bool analytic = parsed.builder_or_default() == Bvh2Builder::kBinnedSah && !parsed.packet;
  return std::make_unique<AnalyticDispatchBackend>(std::move(triangles), analytic ? every_type() : Capabilities{},
                                                   [name, options] { return make_mixed(F, name, options); },
                                                   config.huge_pages);
}

template <OurBvhFamily F>
std::vector<BackendInfo> names_with_analytic() {
  const Family& family = families()[static_cast<std::size_t>(F)];
  std::vector<BackendInfo> out = family.names();
  if (!out.empty())
    out.front().description += F == OurBvhFamily::kBvh2
                                   ? "; analytic spheres, boxes and OBBs in the same tree (sphere_precise, slab, obb)"
                                   : "; analytic spheres, boxes and OBBs in the same leaves after their triangles, "
                                     "tested one by one (sphere_precise, slab, obb)";
  append_analytic_seed_names(out, family.name);
  return out;
}

}  // namespace

bool register_bvh_family_with_analytic(std::string name, int order, BackendFactory make, BackendNames names) {
  const OurBvhFamily family = name == "bvh2"   ? OurBvhFamily::kBvh2
                              : name == "bvh8" ? OurBvhFamily::kBvh8
                              : name == "bvh4" ? OurBvhFamily::kBvh4
                                               : throw std::logic_error("register_bvh_family_with_analytic: not ours: " + name);
  Family& f = families()[static_cast<std::size_t>(family)];
  f.make = make;
  f.names = names;
  switch (family) {
    case OurBvhFamily::kBvh2:
      return register_backend_family(std::string(f.name), order, make_with_analytic<OurBvhFamily::kBvh2>,
                                     names_with_analytic<OurBvhFamily::kBvh2>);
    case OurBvhFamily::kBvh8:
      return register_backend_family(std::string(f.name), order, make_with_analytic<OurBvhFamily::kBvh8>,
                                     names_with_analytic<OurBvhFamily::kBvh8>);
    case OurBvhFamily::kBvh4:
      return register_backend_family(std::string(f.name), order, make_with_analytic<OurBvhFamily::kBvh4>,
                                     names_with_analytic<OurBvhFamily::kBvh4>);
  }
  throw std::logic_error("register_bvh_family_with_analytic: unknown family");
}

}  // namespace raybench
