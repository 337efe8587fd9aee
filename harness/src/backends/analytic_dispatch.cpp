#include "backends/analytic_dispatch.h"

#include <utility>

#include "raybench/bvh/huge_pages.h"

namespace raybench {

AnalyticDispatchBackend::AnalyticDispatchBackend(std::unique_ptr<Backend> triangles, Capabilities capabilities,
                                                 Make analytic, bool huge_pages)
    : triangles_(std::move(triangles)),
      capabilities_(capabilities),
      make_analytic_(std::move(analytic)),
      active_(triangles_.get()),
      huge_pages_(huge_pages) {}

void AnalyticDispatchBackend::build(const Scene& scene) {
  set_huge_pages(huge_pages_);  // process-wide, so set by every build: the policy of the backend building
  if (scene.has_analytic()) {
    if (!analytic_) {
      Scene empty;
      empty.name = scene.name;
      triangles_->build(empty);
      analytic_ = make_analytic_();
    }
    active_ = analytic_.get();
  } else {
    analytic_.reset();
    active_ = triangles_.get();
  }
  active_->build(scene);
}

}  // namespace raybench
