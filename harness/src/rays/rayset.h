// Ray sets: generated deterministically from (scene, kind, count, seed,
// camera, light), stored as .npy, and traced identically by every backend.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "raybench/bvh/bvh2.h"
#include "raybench/bvh/mixed_bvh2.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle_mt.h"
#include "scene/random.h"
#include "scene/scene.h"

namespace raybench {

enum class RaySetKind {
  kPrimary,
  kDiffuse,
  kShadow,
  kUniform,
  // Coherent orders (issue 32): the primary pixels in screen tiles, and
  // shadow rays from their hits in the same order.
  kPrimaryTiled,  // primary's jittered pixels, reordered: 8x8 tiles of 4x2 blocks
  kShadowTiled,   // one shadow ray per hit of primary-tiled, in its order
  // Must-hit ray sets of ../shared/EXTREMES.md, for closed meshes that
  // declare a ball inside them: every ray must hit, a miss is a leak.
  kClosedInsideRandom,  // G01: origins in the ball, uniform directions
  kSharedEdgeAimed,     // G02: origins in the ball, aimed at a float point of a random edge
  kVertexAimed,         // G03: origins in the ball, aimed at a random vertex
  // Extreme ray sets of ../shared/EXTREMES.md that need no inside ball.
  kTinyTriangles,        // G05: aimed at interior points (10 % barycentric margin) of random triangles
  kGrazing,              // G07: at 1e-2 ... 1e-6 rad to a random triangle's plane, aimed inside it
  kDegenerateTriangles,  // G08: as G05; on zero-area triangles the aim point lies on the segment
  kAxisParallel,         // G09: 26 sign/zero direction patterns with +0 and -0, origins on slab planes
  kBehindOrigin,         // G14: a random triangle lies behind the origin (at t < 0)
  kInvalid,              // G15: NaN or Inf in one field, NaN interval, tnear > tfar, d = 0, beyond Embree's range
  kDirectionScaling,     // G16: uniform rays with |d| in 1e-20, 1e-7, 1, 1e7, 1e20
  kBvhConservative,      // G17: from outside, aimed at vertices and float points of edges
  kReintersection,       // G18: from primary hits, half into the normal hemisphere, half toward random points
  kControlRandom,        // G20: origins uniform in the scene bounds, uniform directions
  kFarOrigin,            // origins 1e5, 1e6, 1e7 units from the scene, aimed at random points of its bounds
};

// Which query a ray set is traced with.
enum class Query { kIntersect, kOccluded };

std::string to_string(RaySetKind kind);
std::string to_string(Query query);
// Throws InputError for an unknown name.
RaySetKind parse_rayset_kind(const std::string& name);
std::vector<std::string> rayset_kind_names();
Query query_of(RaySetKind kind);
// True for the must-hit kinds (G01-G03): they need RaySetSpec::inside.
bool is_must_hit(RaySetKind kind);
// True for rays that start on a surface (diffuse, shadow, reintersection):
// they have a source primitive, and hitting it again is a self-intersection.
bool has_sources(RaySetKind kind);
// False for shadow-tiled: one ray per hit of the N primary-tiled rays, so a
// set asked for N rays holds at most N. Every other kind has exactly N.
bool has_exact_count(RaySetKind kind);

// A pinhole camera; y is up unless `up` says otherwise.
struct Camera {
  Vec3f position, look_at, up{0, 1, 0};
  float fov_degrees = 50.0f;  // horizontal
  float aspect = 4.0f / 3.0f;
};

// A ball strictly inside a closed mesh: origins of the must-hit ray sets.
struct InsideBall {
  Vec3f center;
  float radius = 0.0f;
};

struct RaySetSpec {
  RaySetKind kind = RaySetKind::kPrimary;
  std::size_t count = 0;
  std::uint64_t seed = 1;
  std::optional<Camera> camera;  // default: frames the scene's bounds from outside
  std::optional<Vec3f> light;    // shadow rays' point light; default: above the scene
  std::optional<InsideBall> inside{};  // required by the must-hit kinds
};

// Bumped whenever generation changes, so stored ray sets are never reused
// across generator versions.
inline constexpr int kRayGeneratorVersion = 3;

// Makes ray sets for one scene. Diffuse and shadow rays start at primary
// hits, found with our BVH2 (built once here): over the triangles with
// Möller-Trumbore for a triangle scene; over every primitive's box for a scene
// with analytic primitives (issue 31), whose leaves test triangles as before
// and spheres, boxes and OBBs as surfaces (prim/analytic_hit.h: SpherePrecise,
// Slab, Obb). The sets that aim at triangles aim at every primitive: a
// random primitive id over all of them, and for an analytic one a point of
// its surface, a corner, an edge or a tangent (rays/analytic_targets.h). A
// scene without analytic primitives gets exactly the rays it always got.
class RayGenerator {
 public:
  explicit RayGenerator(const Scene& scene);

  // Throws InputError when the camera sees (almost) nothing of the scene, so
  // that diffuse or shadow rays cannot be made.
  // `sources`, when given, receives for every ray the primitive (global id,
  // raybench/prim/primitives.h) it starts from (secondary rays: diffuse,
  // shadow, reintersection), or kNoHit.
  std::vector<Ray> generate(const RaySetSpec& spec, std::vector<std::int32_t>* sources = nullptr) const;

  Camera default_camera() const;
  Vec3f default_light() const;
  // A key over everything the rays depend on, for naming stored files.
  std::uint64_t key(const RaySetSpec& spec) const;

 private:
  std::vector<Ray> primary(const RaySetSpec& spec, const Camera& camera) const;
  std::vector<Ray> primary_tiled(const RaySetSpec& spec, const Camera& camera) const;
  std::vector<Ray> shadow_tiled(const RaySetSpec& spec, const Camera& camera, std::vector<std::int32_t>* sources) const;
  // The secondary ray of `kind` (diffuse, shadow, reintersection) leaving
  // `hit` of `primary`; `index` is the candidate's number (reintersection
  // alternates on it) and `rng` draws the bounce. False when the hit has no
  // usable normal or the direction is undefined: no ray.
  bool secondary_ray(RaySetKind kind, const Ray& primary, const Hit& hit, Vec3f light, Rng& rng, std::size_t index,
                     Ray& out) const;
  std::vector<Ray> from_primary_hits(const RaySetSpec& spec, const Camera& camera, std::vector<std::int32_t>* sources) const;
  std::vector<Ray> uniform(const RaySetSpec& spec) const;
  std::vector<Ray> must_hit(const RaySetSpec& spec) const;
  std::vector<Ray> extreme(const RaySetSpec& spec) const;
  // The primary hit: MT over triangles, or every type over all primitives.
  Hit closest_hit(const Ray& ray) const;

  const Scene& scene_;
  BBox bounds_;
  Bvh2 bvh_;  // over the triangles of a triangle-only scene
  std::vector<MollerTrumbore::Prepared> prepared_;  // its triangles in leaf order
  MixedBvh2<MollerTrumbore> mixed_;  // over every primitive, when the scene has analytic ones
};

}  // namespace raybench
