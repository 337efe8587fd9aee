// Our wide BVHs: a BVH2 (binned SAH by default, TBB-parallel), collapsed to
// 8-wide (bvh8: AVX2) or 4-wide (bvh4: SSE) nodes, traversed with one SIMD
// slab test per node and leaves of up to W triangles tested at once.
// Options, in any order, each at most once:
//   a triangle test: mt (Möller–Trumbore in its stored-normal form,
//     prim/triangle_mt_normal.h, simd/wide_triangle.h; the default),
//     mt_edges (the same test with the normal recomputed per test from
//     leaves a quarter smaller, prim/triangle_mt_edges.h: for scenes whose
//     leaves do not fit in the caches)
//     or, 8 wide only, watertight (Woop et al. 2013, simd/triangle8_watertight.h);
//   a box test: robust, the conservative wide box test (Ize's padding folded
//     into the ray, prim/aabb_slab_robust_ray.h), which culls no box the
//     exact ray touches, or plain_boxes, SlabFma (prim/aabb_slab_fma.h: one
//     fused multiply-add per plane). Unnamed: robust with the watertight
//     leaves, so that bvh8:watertight leaks no ray through the tree either
//     (bvh8:watertight:plain_boxes is the fast, leaky combination:
//     backends/bvh_options.h), plain_boxes with the others;
//   a builder from raybench/bvh/bvh2_builders.h ("bvh8:sweep", "bvh4:lbvh");
//   reinsert: the BVH2 optimised by reinsertion before the collapse
//     (bvh2_reinsertion.h).
#include <algorithm>
#include <span>

#include <fmt/format.h>

#include "backends/backend_families.h"
#include "backends/bvh_options.h"
#include "io/error.h"
#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/wide_bvh_traverse.h"

namespace raybench {
namespace {

template <int W, typename Leaf, typename BoxTest>
class WideBvhBackend final : public Backend {
 public:
  WideBvhBackend(std::string name, Bvh2Builder builder, int reinsertion_passes)
      : name_(std::move(name)), builder_(builder), reinsertion_passes_(reinsertion_passes) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    Bvh2BuildOptions options;
    // The quality builds (spatial splits, reinsertion) build the BVH2 with
    // small leaves, scored as scalar tests: the collapse then gathers subtrees
    // of up to W triangles into packs where the wide tree's SAH says so
    // (wide_bvh_collapse.cpp), which fills nodes better. Measured on Sponza:
    // 4-10 % more rays/s, for 1.8x the build time. The default build keeps
    // leaves of up to W triangles (the SAH counts them in packs of W), as
    // fast to build as Embree's medium build.
    const bool quality = builder_ == Bvh2Builder::kSbvh || reinsertion_passes_ > 0;
    options.leaf_granularity = quality ? 1 : W;
    options.max_leaf_size = W;  // a BVH2 leaf fits one pack
    options.reinsertion_passes = reinsertion_passes_;
    // Any-hit traversal visits the children in lane order: the smallest box
    // first for the default build, the most likely to end the ray per cost
    // first for the quality builds (WideLaneOrder::kOcclusion).
    // Measured on shadow rays, one thread, interleaved: smallest first made
    // the default build 1.21x faster on Sponza, 1.01x on Conference, but
    // bvh8:reinsert 0.89x and 0.93x, bvh8:sbvh:reinsert 1.01x and 0.97x
    // (against the BVH2's order). The occlusion order against the BVH2's,
    // the quality builds with and without watertight leaves, 11 scenes (44
    // rows): geometric mean +2.9 %, 38 rows faster, Sponza-Dabrovic +5 to
    // +18 %, Sponza +3 to +10 %, Conference +4 to +7 %, but Lucy -9 to
    // -13 %. On the default build it was -18 % on Sponza (+15 % on
    // Sponza-Dabrovic, the mean unchanged): smallest first stays there.
    const WideLaneOrder lanes = quality ? WideLaneOrder::kOcclusion : WideLaneOrder::kByArea;
    bvh_ = {};  // the old tree freed first, as Embree releases its old scene first
    bvh_ = collapse_bvh2<W>(build_bvh2(scene.triangles, builder_, options), scene.triangles, Leaf::kLeaves, lanes);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  // WideBvh::sah_cost, of the wide tree traced: node visits and W-triangle
  // pack tests cost 1 each (computed here, outside the timed build).
  double sah_cost() const override { return bvh_.sah_cost(); }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    // Leaves that do not carry their triangles report pack slots, mapped
    // to triangles here, after the batch (traverse_wide's PackSlots).
    constexpr bool kSlots = !Leaf::kPrimsInPack;
    for (std::size_t i = 0; i < rays.size(); ++i)
      hits[i] = is_traceable(rays[i]) ? traverse_wide<false, Leaf, BoxTest, kSlots>(bvh_, with_nonnegative_tnear(rays[i]))
                                      : Hit{};
    if constexpr (kSlots)
      for (Hit& h : hits)
        if (h.hit()) h.prim = bvh_.pack_prims[static_cast<std::uint32_t>(h.prim)];
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i)
      occluded[i] = is_traceable(rays[i]) && occluded_wide<Leaf, BoxTest>(bvh_, with_nonnegative_tnear(rays[i]));
  }

 private:
  std::string name_;
  Bvh2Builder builder_;
  int reinsertion_passes_;
  WideBvh<W> bvh_;
};

template <int W, typename Leaf>
std::unique_ptr<Backend> make_with_box_test(const std::string& name, Bvh2Builder builder, int reinsertion_passes,
                                            bool robust) {
  if (robust) return std::make_unique<WideBvhBackend<W, Leaf, SlabRobustRay>>(name, builder, reinsertion_passes);
  return std::make_unique<WideBvhBackend<W, Leaf, SlabFma>>(name, builder, reinsertion_passes);
}

template <int W>
std::unique_ptr<Backend> make_wide_backend(const std::string& name, const std::vector<std::string>& options) {
  // Watertight leaves are 8 wide only: say so rather than "unknown option".
  if (W != 8 && std::find(options.begin(), options.end(), "watertight") != options.end())
    throw InputError("", fmt::format("backend '{}': watertight leaves are 8 wide only; use bvh8:watertight", name));
  static constexpr std::string_view kTests8[] = {"mt", "mt_edges", "watertight"}, kTests4[] = {"mt", "mt_edges"};
  const std::string family = fmt::format("bvh{}", W);
  const BvhOptions parsed = parse_bvh_options(
      name, family, options, W == 8 ? std::span<const std::string_view>(kTests8) : std::span<const std::string_view>(kTests4),
      family + (W == 8 ? ":watertight:sweep:reinsert" : ":robust:sweep:reinsert"));
  const Bvh2Builder b = parsed.builder_or_default();
  const int passes = parsed.reinsertion_passes();
  if constexpr (W == 8) {
    if (parsed.test == kWatertightTest) return make_with_box_test<8, Bvh8Watertight>(name, b, passes, parsed.robust());
  }
  if (parsed.test.value_or("mt") == "mt_edges") return make_with_box_test<W, WideMollerTrumboreEdges>(name, b, passes, parsed.robust());
  return make_with_box_test<W, WideMollerTrumbore>(name, b, passes, parsed.robust());
}

template <int W>
std::vector<BackendInfo> wide_backend_names() {
  const std::string family = fmt::format("bvh{}", W);
  std::vector<BackendInfo> out{
      {family, fmt::format("{}-wide BVH collapsed from bvh2, {} node and leaf tests, Moller-Trumbore leaves of {}", W,
                           kHaveAvx2 ? (W == 8 ? "AVX2" : "SSE") : "scalar fallback", W)}};
  for (Bvh2Builder b : kBvh2Builders) {
    if (b == Bvh2Builder::kBinnedSah) continue;  // the default: plain "bvh8"
    out.push_back({family + ":" + std::string(to_string(b)),
                   fmt::format("{} from a BVH2 built by {}; any {} name takes :<builder>", family, description(b), family)});
  }
  out.push_back({fmt::format("{}:{}", family, kReinsertOption),
                 fmt::format("{} from a BVH2 optimised by reinsertion (Bittner et al. 2013, in parallel batches); any "
                             "{} name takes :{}",
                             family, family, kReinsertOption)});
  out.push_back({family + ":mt_edges",
                 fmt::format("{} with leaves of v0 and two edges, the normal recomputed per test (mt_edges): a quarter "
                             "less leaf memory, for scenes whose leaves do not fit in the caches",
                             family)});
  if constexpr (W == 8) {
    out.push_back({"bvh8:watertight",
                   "bvh8 with 8-wide watertight leaves (Woop, Benthin & Wald 2013), traversed with the conservative "
                   "8-wide box test (slab_robust_ray): no ray leaks through the tree [watertight]",
                   "watertight"});
    out.push_back({"bvh8:watertight:plain_boxes",
                   "bvh8:watertight traversed with the plain box test (slab_fma): faster, but it leaks rays aimed at "
                   "shared vertices and edges through the box test [fast]",
                   "fast"});
    out.push_back({"bvh8:watertight:robust",
                   "the same as bvh8:watertight (its name until the watertight leaves took the conservative box test by "
                   "default)",
                   "watertight"});
  }
  out.push_back({family + ":robust", fmt::format("{} with the conservative {}-wide box test (slab_robust_ray); any {} "
                                                 "name takes :robust or :plain_boxes (slab_fma, the default) for its box test",
                                                 family, W, family)});
  return out;
}

}  // namespace

std::unique_ptr<Backend> make_bvh8_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig&) {
  return make_wide_backend<8>(name, options);
}
std::vector<BackendInfo> bvh8_backend_names() { return wide_backend_names<8>(); }

std::unique_ptr<Backend> make_bvh4_backend(const std::string& name, const std::vector<std::string>& options,
                                           const BackendConfig&) {
  return make_wide_backend<4>(name, options);
}
std::vector<BackendInfo> bvh4_backend_names() { return wide_backend_names<4>(); }

}  // namespace raybench
