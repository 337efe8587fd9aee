// Which backends can trace which scenes (Capabilities, backends/backend.h):
// the primitive types a scene has against those a backend models.
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "backends/backend.h"
#include "raybench/prim/primitives.h"

namespace raybench {
namespace {

constexpr PrimitiveKind kKinds[] = {PrimitiveKind::kTriangle, PrimitiveKind::kSphere, PrimitiveKind::kBox,
                                    PrimitiveKind::kOrientedBox};

std::string_view plural(PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::kTriangle: return "triangles";
    case PrimitiveKind::kSphere: return "spheres";
    case PrimitiveKind::kBox: return "boxes";
    case PrimitiveKind::kOrientedBox: return "oriented boxes";
  }
  return "?";
}

bool models(const Capabilities& c, PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::kTriangle: return c.triangles;
    case PrimitiveKind::kSphere: return c.spheres;
    case PrimitiveKind::kBox: return c.boxes;
    case PrimitiveKind::kOrientedBox: return c.oriented_boxes;
  }
  return false;
}

bool has(const Scene& scene, PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::kTriangle: return !scene.triangles.empty();
    case PrimitiveKind::kSphere: return !scene.spheres.empty();
    case PrimitiveKind::kBox: return !scene.boxes.empty();
    case PrimitiveKind::kOrientedBox: return !scene.obbs.empty();
  }
  return false;
}

// The kinds `wanted` selects, in prim-id order, as "a", "a and b", "a, b and c".
template <typename Wanted>
std::string kinds_named(Wanted wanted, std::size_t* count = nullptr) {
  std::vector<std::string_view> names;
  for (PrimitiveKind k : kKinds)
    if (wanted(k)) names.push_back(plural(k));
  if (count) *count = names.size();
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += fmt::format("{}{}", i == 0 ? "" : i + 1 == names.size() ? " and " : ", ", names[i]);
  return out;
}

}  // namespace

std::string missing_primitive_types(const Capabilities& capabilities, const Scene& scene) {
  return kinds_named([&](PrimitiveKind k) { return has(scene, k) && !models(capabilities, k); });
}

std::string capability_problem(const Backend& backend, const Scene& scene) {
  const Capabilities c = backend.capabilities();
  const std::string missing = missing_primitive_types(c, scene);
  if (missing.empty()) return "";
  std::size_t count = 0;
  const std::string modelled = kinds_named([&](PrimitiveKind k) { return models(c, k); }, &count);
  return fmt::format("backend '{}' models {}{}; scene '{}' has {}", backend.name(),
                     count == 0 ? "no primitive type" : modelled, count == 1 ? " only" : "", scene.name, missing);
}

}  // namespace raybench
