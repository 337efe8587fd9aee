// Our wide BVHs: a BVH2 (binned SAH by default, TBB-parallel), collapsed to
// 8-wide (bvh8: AVX2) or 4-wide (bvh4: SSE) nodes, traversed with one SIMD
// slab test per node and leaves of packs of up to W triangles, a pack tested
// at once (bvh8: up to 4 packs per leaf, wide_bvh.h).
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
//   reinsert: the BVH2 fully optimised by reinsertion before the collapse
//     (bvh2_reinsertion.h), not only by the default build's one batch;
//   sphere_seed, box_seed, obb_seed: the seed notes' tests for analytic
//     primitives instead of SpherePrecise, Slab, Obb (issue 31).
// Scenes with analytic primitives: the families are registered through
// backends/mixed_bvh_backends.h, which pairs each backend made here with one
// wide tree over all primitives (raybench/bvh/mixed_wide_bvh.h) for such
// scenes. Nothing else in this file changed: a triangle-only scene is
// traced by WideBvhBackend, compiled as before.
#include <algorithm>
#include <span>

#include <fmt/format.h>

#include "backends/backend.h"
#include "backends/bvh_options.h"
#include "backends/mixed_bvh_backends.h"
#include "io/error.h"
#include "raybench/bvh/bvh2_builders.h"
#include "raybench/bvh/wide_bvh_batch.h"
#include "raybench/bvh/wide_bvh_packet.h"

namespace raybench {
namespace {

// Packet: intersect and occluded trace coherent rays in packets (kPacketRays
// wide, SlabFma only).
template <int W, typename Leaf, typename BoxTest, bool Packet = false>
class WideBvhBackend final : public Backend {
 public:
  WideBvhBackend(std::string name, Bvh2Builder builder, Bvh2Reinsertion reinsertion)
      : name_(std::move(name)), builder_(builder), reinsertion_(reinsertion) {}

  const std::string& name() const override { return name_; }

  void build(const Scene& scene) override {
    bvh_ = {};  // the old tree freed first, as Embree releases its old scene first
    bvh_ = build_wide_bvh<W, Leaf>(scene.triangles, builder_, reinsertion_);
  }

  std::size_t memory_bytes() const override { return bvh_.memory_bytes(); }

  // WideBvh::sah_cost, of the wide tree traced: node visits and W-triangle
  // pack tests cost 1 each (computed here, outside the timed build).
  double sah_cost() const override { return bvh_.sah_cost(); }

  // The same code as the in-tree plugin wrapping bvh8 (bvh/wide_bvh_batch.h).
  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if constexpr (Packet) intersect_packet_batch<Leaf>(bvh_, rays, hits);
    else intersect_wide_batch<Leaf, BoxTest>(bvh_, rays, hits);
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    if constexpr (Packet) occluded_packet_batch<Leaf>(bvh_, rays, occluded);
    else occluded_wide_batch<Leaf, BoxTest>(bvh_, rays, occluded);
  }

 private:
  std::string name_;
  Bvh2Builder builder_;
  Bvh2Reinsertion reinsertion_;
  WideBvh<W> bvh_;
};

template <int W, typename Leaf>
std::unique_ptr<Backend> make_with_box_test(const std::string& name, Bvh2Builder builder, Bvh2Reinsertion reinsertion,
                                            bool robust, bool packet) {
  if constexpr (W == 8) {
    if (packet) {
      if (robust)
        throw InputError("", fmt::format("backend '{}': the packet traversal takes the plain box test only (slab_fma); "
                                         "add :{}", name, kPlainBoxes));
      return std::make_unique<WideBvhBackend<8, Leaf, SlabFma, true>>(name, builder, reinsertion);
    }
  }
  if (robust) return std::make_unique<WideBvhBackend<W, Leaf, SlabRobustRay>>(name, builder, reinsertion);
  return std::make_unique<WideBvhBackend<W, Leaf, SlabFma>>(name, builder, reinsertion);
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
  const Bvh2Reinsertion reinsertion = parsed.reinsertion();
  if constexpr (W == 8) {
    if (parsed.test == kWatertightTest) return make_with_box_test<8, Bvh8Watertight>(name, b, reinsertion, parsed.robust(), parsed.packet);
  }
  if (parsed.test.value_or("mt") == "mt_edges") return make_with_box_test<W, WideMollerTrumboreEdges>(name, b, reinsertion, parsed.robust(), parsed.packet);
  return make_with_box_test<W, WideMollerTrumbore>(name, b, reinsertion, parsed.robust(), parsed.packet);
}

template <int W>
std::vector<BackendInfo> wide_backend_names() {
  const std::string family = fmt::format("bvh{}", W);
  std::vector<BackendInfo> out{
      {family, fmt::format("{}-wide BVH collapsed from bvh2, {} node and leaf tests, Moller-Trumbore leaves of up to "
                           "{} packs of {}",
                           W, kHaveAvx2 ? (W == 8 ? "AVX2" : "SSE") : "scalar fallback",
                           default_leaf_packs<W>(WideLeaves::kMollerTrumbore), W)}};
  for (Bvh2Builder b : kBvh2Builders) {
    if (b == Bvh2Builder::kBinnedSah) continue;  // the default: plain "bvh8"
    out.push_back({family + ":" + std::string(to_string(b)),
                   fmt::format("{} from a BVH2 built by {}; any {} name takes :<builder>", family, description(b), family)});
  }
  out.push_back({fmt::format("{}:{}", family, kReinsertOption),
                 fmt::format("{} from a BVH2 fully optimised by reinsertion (Bittner et al. 2013, 8 parallel batches instead of one); any "
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
  if constexpr (W == 8) {
    out.push_back({"bvh8:packet",
                   fmt::format("bvh8 tracing coherent consecutive rays in packets of {} ({}: a frustum test per node, "
                               "per-ray masks, single rays where rays diverge), the same answers as bvh8 bit for bit; "
                               "triangle scenes only; any bvh8 name with the plain box test takes :packet",
                               kPacketRays, !kHaveAvx2 ? "without AVX2 every ray alone" : kPacketRays == 32 ? "AVX-512" : "AVX2")});
  }
  out.push_back({family + ":robust", fmt::format("{} with the conservative {}-wide box test (slab_robust_ray); any {} "
                                                 "name takes :robust or :plain_boxes (slab_fma, the default) for its box test",
                                                 family, W, family)});
  return out;
}

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

}  // namespace

RAYBENCH_BVH_FAMILY_WITH_ANALYTIC("bvh8", 300, make_bvh8_backend, bvh8_backend_names);
RAYBENCH_BVH_FAMILY_WITH_ANALYTIC("bvh4", 400, make_bvh4_backend, bvh4_backend_names);

}  // namespace raybench
