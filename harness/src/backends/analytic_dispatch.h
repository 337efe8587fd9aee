// A backend made of two, chosen per scene in build(): one that traces
// triangle-only scenes and one that traces scenes with analytic primitives
// (issue 31). Our BVH families are made so (backends/bvh2_backend.cpp,
// wide_bvh_backend.cpp, mixed_bvh_backends.h): a triangle-only scene is
// then traced by the very class, compiled in the very translation unit as
// before analytic primitives existed, so its instructions are the same (in
// one class holding both paths, or beside the mixed instantiations, the
// compiler inlined and allocated registers otherwise). The price is one more
// virtual call per batch of rays. Being every family's outer object, it
// also applies the run's memory policy (BackendConfig::huge_pages) to the
// builds of both.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "backends/backend.h"

namespace raybench {

class AnalyticDispatchBackend final : public Backend {
 public:
  using Make = std::function<std::unique_ptr<Backend>()>;

  // `triangles` traces triangle-only scenes; `analytic` makes the backend
  // for scenes with analytic primitives when one is first built;
  // `capabilities` is what the pair models; `huge_pages` is the memory
  // policy (raybench/bvh/huge_pages.h's set_huge_pages) set before each build.
  AnalyticDispatchBackend(std::unique_ptr<Backend> triangles, Capabilities capabilities, Make analytic,
                          bool huge_pages);

  const std::string& name() const override { return triangles_->name(); }
  Capabilities capabilities() const override { return capabilities_; }
  // A scene with analytic primitives is built by the analytic backend (made
  // then, the triangle backend's tree freed first by building it an empty
  // scene), any other by the triangle backend (the analytic one dropped
  // first), as Embree releases its old scene before building a new one.
  void build(const Scene& scene) override;
  // These ask the backend of the scene built last (the triangle one before
  // any build).
  std::size_t memory_bytes() const override { return active_->memory_bytes(); }
  double sah_cost() const override { return active_->sah_cost(); }
  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override { active_->intersect(rays, hits); }
  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    active_->occluded(rays, occluded);
  }

 private:
  std::unique_ptr<Backend> triangles_;
  Capabilities capabilities_;
  Make make_analytic_;
  std::unique_ptr<Backend> analytic_;  // while the last scene built has analytic primitives
  Backend* active_;
  bool huge_pages_;
};

}  // namespace raybench
