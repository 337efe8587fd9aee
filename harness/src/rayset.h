// Ray sets: generated deterministically from (scene, kind, count, seed,
// camera, light), stored as .npy, and traced identically by every backend.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "raybench/bvh/bvh2.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle_mt.h"
#include "scene.h"

namespace raybench {

enum class RaySetKind { kPrimary, kDiffuse, kShadow, kUniform };

// Which query a ray set is traced with.
enum class Query { kIntersect, kOccluded };

std::string to_string(RaySetKind kind);
std::string to_string(Query query);
// Throws InputError for an unknown name.
RaySetKind parse_rayset_kind(const std::string& name);
std::vector<std::string> rayset_kind_names();
Query query_of(RaySetKind kind);

// A pinhole camera; y is up unless `up` says otherwise.
struct Camera {
  Vec3f position, look_at, up{0, 1, 0};
  float fov_degrees = 50.0f;  // horizontal
  float aspect = 4.0f / 3.0f;
};

struct RaySetSpec {
  RaySetKind kind = RaySetKind::kPrimary;
  std::size_t count = 0;
  std::uint64_t seed = 1;
  std::optional<Camera> camera;  // default: frames the scene's bounds from outside
  std::optional<Vec3f> light;    // shadow rays' point light; default: above the scene
};

// Bumped whenever generation changes, so stored ray sets are never reused
// across generator versions.
inline constexpr int kRayGeneratorVersion = 2;

// Makes ray sets for one scene. Diffuse and shadow rays start at primary
// hits, found with our BVH2 (built once here).
class RayGenerator {
 public:
  explicit RayGenerator(const Scene& scene);

  // Throws InputError when the camera sees (almost) nothing of the scene, so
  // that diffuse or shadow rays cannot be made.
  std::vector<Ray> generate(const RaySetSpec& spec) const;

  Camera default_camera() const;
  Vec3f default_light() const;
  // A key over everything the rays depend on, for naming stored files.
  std::uint64_t key(const RaySetSpec& spec) const;

 private:
  std::vector<Ray> primary(const RaySetSpec& spec, const Camera& camera) const;
  std::vector<Ray> from_primary_hits(const RaySetSpec& spec, const Camera& camera) const;
  std::vector<Ray> uniform(const RaySetSpec& spec) const;

  const Scene& scene_;
  BBox bounds_;
  Bvh2 bvh_;
  std::vector<MollerTrumbore::Prepared> prepared_;
};

}  // namespace raybench
