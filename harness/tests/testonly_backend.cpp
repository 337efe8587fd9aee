// A backend family added the documented way: this one file, nothing else
// edited (backend_registration_test.cpp checks that the harness sees it).
// It tests every triangle for every ray with Möller–Trumbore: no tree, only
// for tests.
#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "backends/backend.h"
#include "io/error.h"
#include "raybench/prim/triangle_mt.h"

namespace raybench {
namespace {

class BruteForceBackend final : public Backend {
 public:
  explicit BruteForceBackend(std::string name) : name_(std::move(name)) {}
  const std::string& name() const override { return name_; }
  void build(const Scene& scene) override {
    triangles_.clear();
    for (const Triangle& t : scene.triangles) triangles_.push_back(MollerTrumbore::prepare(t));
  }
  std::size_t memory_bytes() const override { return triangles_.size() * sizeof(MollerTrumbore::Prepared); }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = closest(rays[i]);
  }
  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = closest(rays[i]).hit();
  }

 private:
  Hit closest(const Ray& ray) const {
    Hit best;
    if (!is_traceable(ray)) return best;
    const Ray r = with_nonnegative_tnear(ray);
    for (std::size_t p = 0; p < triangles_.size(); ++p) {
      TriangleHit h{};
      if (MollerTrumbore::intersect(MollerTrumbore::precompute(r), std::min(best.t, r.tfar), triangles_[p], h) &&
          h.t < best.t)
        best = {h.t, static_cast<std::int32_t>(p), h.u, h.v};
    }
    return best;
  }

  std::string name_;
  std::vector<MollerTrumbore::Prepared> triangles_;
};

std::unique_ptr<Backend> make_testonly(const std::string& name, const std::vector<std::string>& options,
                                       const BackendConfig&) {
  if (!options.empty()) throw InputError("", fmt::format("backend '{}': testonly takes no options", name));
  return std::make_unique<BruteForceBackend>(name);
}

std::vector<BackendInfo> testonly_names() {
  return {{"testonly", "every triangle for every ray (a test of backend registration)", "fast"}};
}

}  // namespace

RAYBENCH_BACKEND_FAMILY("testonly", 1000, make_testonly, testonly_names);

}  // namespace raybench
