// Scene helpers (scene/scene.h): its bounds, and the coordinate check that
// refuses a vertex that is not finite or beyond kMaxSceneCoordinate, naming
// the triangle, and an analytic primitive whose box is, naming it.
#include "scene/scene.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "io/error.h"

namespace raybench {

BBox Scene::bounds() const {
  BBox b;
  const PrimitiveSpans all = primitives();
  for (std::size_t i = 0; i < all.size(); ++i) b.extend(all.bounds(i));
  return b;
}

std::string describe_primitives(const Scene& scene) {
  const auto count = [](std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
  };
  std::string out = count(scene.triangles.size(), "triangle", "triangles");
  if (!scene.spheres.empty()) out += ", " + count(scene.spheres.size(), "sphere", "spheres");
  if (!scene.boxes.empty()) out += ", " + count(scene.boxes.size(), "box", "boxes");
  if (!scene.obbs.empty()) out += ", " + count(scene.obbs.size(), "oriented box", "oriented boxes");
  return out;
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
  // An analytic primitive's box (primitives.h) holds all of it: a sphere's
  // centre +- radius, an oriented box's reach; NaN fails the comparison.
  const PrimitiveSpans all = scene.primitives();
  for (std::size_t id = all.first_sphere(); id < all.size(); ++id) {
    const BBox b = all.bounds(id);
    for (const float c : {b.lower.x, b.lower.y, b.lower.z, b.upper.x, b.upper.y, b.upper.z}) {
      if (std::fabs(c) <= kMaxSceneCoordinate) continue;
      char value[32];
      std::snprintf(value, sizeof value, "%g", static_cast<double>(c));
      throw InputError(where, std::string(to_string(all.kind(id))) + " " + std::to_string(all.local(id)) +
                                  " (prim " + std::to_string(id) + ") reaches a coordinate " +
                                  (std::isfinite(c) ? "of " : "that is not finite: ") + value +
                                  "; coordinates must be finite and within +-1e18 (box areas must stay finite in float)");
    }
  }
}

std::uint64_t Scene::content_hash() const {
  // FNV-1a over the raw float bits: cheap, stable across runs and machines.
  std::uint64_t h = 0xcbf29ce484222325ull;
  const auto add = [&](const void* data, std::size_t n) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= bytes[i];
      h *= 0x100000001b3ull;
    }
  };
  add(triangles.data(), triangles.size() * sizeof(Triangle));
  // A triangle-only scene hashes as before, so its stored ray sets stay valid;
  // each analytic array adds its count first, so moving a primitive from one
  // array to the next changes the hash.
  if (has_analytic()) {
    for (std::size_t n : {spheres.size(), boxes.size(), obbs.size()}) add(&n, sizeof n);
    add(spheres.data(), spheres.size() * sizeof(Sphere));
    add(boxes.data(), boxes.size() * sizeof(BBox));
    add(obbs.data(), obbs.size() * sizeof(OrientedBox));
  }
  return h;
}

}  // namespace raybench
