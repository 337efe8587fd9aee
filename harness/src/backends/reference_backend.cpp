// "reference": the exact referee (referee/referee.h) as a backend, so that it
// runs wherever a backend runs (raybench trace, run) and its answers can be
// stored and compared like any other. It is the truth of the accuracy report
// and slow on purpose: every candidate primitive is judged exactly. It models
// every primitive type (analytic ones as surfaces, prim/analytic_hit.h).
#include <cmath>

#include <fmt/format.h>

#include "backends/backend.h"
#include "io/error.h"
#include "referee/referee.h"

namespace raybench {
namespace {

class ReferenceBackend final : public Backend {
 public:
  explicit ReferenceBackend(std::string name) : name_(std::move(name)) {}

  const std::string& name() const override { return name_; }

  Capabilities capabilities() const override {
    Capabilities c;
    c.spheres = c.boxes = c.oriented_boxes = true;
    return c;
  }

  void build(const Scene& scene) override {
    scene_ = scene;  // the referee keeps a reference: own the primitives
    referee_ = std::make_unique<Referee>(scene_);
  }

  std::size_t memory_bytes() const override {
    return referee_ ? referee_->memory_bytes() + scene_.triangles.size() * sizeof(Triangle) +
                          scene_.spheres.size() * sizeof(Sphere) + scene_.boxes.size() * sizeof(BBox) +
                          scene_.obbs.size() * sizeof(OrientedBox)
                    : 0;
  }

  // t is the float nearest the exact t (barring a double-rounding tie); u, v are the barycentrics of the
  // exact hit point, computed in double (approximate), for triangles; 0 for analytic hits.
  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const RefereeVerdict v = referee_->judge(rays[i]);
      hits[i] = {};
      if (!v.hit()) continue;
      hits[i].t = static_cast<float>(v.t);
      hits[i].prim = v.prim;
      if (static_cast<std::size_t>(v.prim) < scene_.triangles.size())
        barycentrics(rays[i], scene_.triangles[v.prim], v.t, hits[i]);
    }
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = referee_->judge(rays[i]).hit();
  }

 private:
  static void barycentrics(const Ray& ray, const Triangle& tri, double t, Hit& hit) {
    const double p[3] = {ray.org.x + t * ray.dir.x, ray.org.y + t * ray.dir.y, ray.org.z + t * ray.dir.z};
    const double e1[3] = {tri.v1.x - double(tri.v0.x), tri.v1.y - double(tri.v0.y), tri.v1.z - double(tri.v0.z)};
    const double e2[3] = {tri.v2.x - double(tri.v0.x), tri.v2.y - double(tri.v0.y), tri.v2.z - double(tri.v0.z)};
    const double q[3] = {p[0] - tri.v0.x, p[1] - tri.v0.y, p[2] - tri.v0.z};
    const auto dot = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), q1 = dot(q, e1), q2 = dot(q, e2);
    const double det = d11 * d22 - d12 * d12;
    if (!(det > 0.0)) return;
    hit.u = static_cast<float>((d22 * q1 - d12 * q2) / det);
    hit.v = static_cast<float>((d11 * q2 - d12 * q1) / det);
  }

  std::string name_;
  Scene scene_;
  std::unique_ptr<Referee> referee_;
};

std::unique_ptr<Backend> make_reference_backend(const std::string& name, const std::vector<std::string>& options,
                                                const BackendConfig&) {
  if (!options.empty())
    throw InputError("", fmt::format("backend '{}': the reference backend takes no options", name));
  return std::make_unique<ReferenceBackend>(name);
}

std::vector<BackendInfo> reference_backend_names() {
  return {{"reference", "exact referee: our BVH2 with conservative traversal, every candidate (triangle, sphere, box, OBB) judged in exact arithmetic (CGAL, GMP, MPFR)",
           "exact"}};
}

}  // namespace

RAYBENCH_BACKEND_FAMILY("reference", 900, make_reference_backend, reference_backend_names);

}  // namespace raybench
