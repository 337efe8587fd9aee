#include "scene.h"

#include <cstring>

namespace raybench {

BBox Scene::bounds() const {
  BBox b;
  for (const Triangle& t : triangles) b.extend(triangle_bounds(t));
  return b;
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
