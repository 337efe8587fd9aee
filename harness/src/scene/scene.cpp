#include "scene/scene.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "io/error.h"

namespace raybench {

BBox Scene::bounds() const {
  BBox b;
  for (const Triangle& t : triangles) b.extend(triangle_bounds(t));
  return b;
}

void check_scene_coordinates(const Scene& scene, const std::string& where) {
  for (std::size_t i = 0; i < scene.triangles.size(); ++i) {
    const Triangle& t = scene.triangles[i];
    for (const Vec3f& v : {t.v0, t.v1, t.v2}) {
      for (const float c : {v.x, v.y, v.z}) {
        if (std::isfinite(c) && std::fabs(c) <= kMaxSceneCoordinate) continue;
        char value[32];
        std::snprintf(value, sizeof value, "%g", static_cast<double>(c));
        throw InputError(where, std::string("triangle ") + std::to_string(i) + " has a coordinate " +
                                    (std::isfinite(c) ? "of " : "that is not finite: ") + value +
                                    "; coordinates must be finite and within +-1e18 (box areas must stay finite in float)");
      }
    }
  }
}

std::uint64_t Scene::content_hash() const {
  // FNV-1a over the raw float bits: cheap, stable across runs and machines.
  std::uint64_t h = 0xcbf29ce484222325ull;
  const auto* bytes = reinterpret_cast<const unsigned char*>(triangles.data());
  const std::size_t n = triangles.size() * sizeof(Triangle);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= bytes[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

}  // namespace raybench
