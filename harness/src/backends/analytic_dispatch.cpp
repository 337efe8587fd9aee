#include "backends/analytic_dispatch.h"

#include <utility>

namespace raybench {

AnalyticDispatchBackend::AnalyticDispatchBackend(std::unique_ptr<Backend> triangles, Capabilities capabilities,
                                                 Make analytic)
    : triangles_(std::move(triangles)),
      capabilities_(capabilities),
      make_analytic_(std::move(analytic)),
      active_(triangles_.get()) {}

void AnalyticDispatchBackend::build(const Scene& scene) {
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
