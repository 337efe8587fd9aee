// Ray-set generation (rays/rayset.h): every kind, from camera rays to the
// extreme-case sets of ../shared/EXTREMES.md (case numbers G.. given at
// each), computed in double from counter-based random numbers
// (scene/random.h) and rounded to float, so a ray set depends only on
// (scene, kind, count, seed, camera, light), never on the thread count
// (across machines, as far as their libm's sin and cos agree).
#include "rays/rayset.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/parallel_for.h>

#include "io/error.h"
#include "rays/analytic_targets.h"
#include "scene/random.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "raybench/math/offset_ray.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/sphere_precise.h"

namespace raybench {
namespace {

Eigen::Vector3d to_eigen(Vec3f v) { return {v.x, v.y, v.z}; }
Vec3f to_vec(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

// The camera's ray through image position (sx, sy) in [0,1)^2, sy downwards.
Ray camera_ray(const Camera& c, double sx, double sy) {
  const Eigen::Vector3d eye = to_eigen(c.position);
  const Eigen::Vector3d forward = (to_eigen(c.look_at) - eye).normalized();
  const Eigen::Vector3d right = forward.cross(to_eigen(c.up)).normalized();
  const Eigen::Vector3d up = right.cross(forward);
  const double half_w = std::tan(c.fov_degrees * std::numbers::pi / 360.0);
  const double half_h = half_w / c.aspect;
  const Eigen::Vector3d d = (forward + right * ((2.0 * sx - 1.0) * half_w) + up * ((1.0 - 2.0 * sy) * half_h)).normalized();
  Ray r;
  r.org = c.position;
  r.dir = to_vec(d);
  return r;
}

// Orthonormal basis around unit n: Duff et al., "Building an Orthonormal
// Basis, Revisited", JCGT 2017.
void basis(const Eigen::Vector3d& n, Eigen::Vector3d& b1, Eigen::Vector3d& b2) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  b1 = {1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x()};
  b2 = {b, sign + n.y() * n.y() * a, -n.y()};
}

std::uint64_t stream_of(RaySetKind kind) { return hash_string(to_string(kind).c_str()); }

// A uniform direction on the unit sphere (uniform z and azimuth: Archimedes).
Eigen::Vector3d uniform_direction(Rng& rng) {
  const double z = 2.0 * rng.next_double() - 1.0, phi = 2.0 * std::numbers::pi * rng.next_double();
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), z, s * std::sin(phi)};
}

}  // namespace

constexpr RaySetKind kAllKinds[] = {
    RaySetKind::kPrimary,          RaySetKind::kDiffuse,         RaySetKind::kShadow,          RaySetKind::kUniform,
    RaySetKind::kPrimaryTiled,     RaySetKind::kShadowTiled,
    RaySetKind::kClosedInsideRandom, RaySetKind::kSharedEdgeAimed, RaySetKind::kVertexAimed,   RaySetKind::kTinyTriangles,
    RaySetKind::kGrazing,          RaySetKind::kDegenerateTriangles, RaySetKind::kAxisParallel, RaySetKind::kBehindOrigin,
    RaySetKind::kInvalid,          RaySetKind::kDirectionScaling, RaySetKind::kBvhConservative, RaySetKind::kReintersection,
    RaySetKind::kControlRandom,    RaySetKind::kFarOrigin};

std::string to_string(RaySetKind kind) {
  switch (kind) {
    case RaySetKind::kPrimary: return "primary";
    case RaySetKind::kDiffuse: return "diffuse";
    case RaySetKind::kShadow: return "shadow";
    case RaySetKind::kUniform: return "uniform";
    case RaySetKind::kPrimaryTiled: return "primary-tiled";
    case RaySetKind::kShadowTiled: return "shadow-tiled";
    case RaySetKind::kClosedInsideRandom: return "closed-inside-random";
    case RaySetKind::kSharedEdgeAimed: return "shared-edge-aimed";
    case RaySetKind::kVertexAimed: return "vertex-aimed";
    case RaySetKind::kTinyTriangles: return "tiny-triangles";
    case RaySetKind::kGrazing: return "grazing";
    case RaySetKind::kDegenerateTriangles: return "degenerate-triangles";
    case RaySetKind::kAxisParallel: return "axis-parallel-signed-zero";
    case RaySetKind::kBehindOrigin: return "behind-origin";
    case RaySetKind::kInvalid: return "invalid-rays";
    case RaySetKind::kDirectionScaling: return "direction-scaling";
    case RaySetKind::kBvhConservative: return "bvh-conservative";
    case RaySetKind::kReintersection: return "reintersection";
    case RaySetKind::kControlRandom: return "control-random";
    case RaySetKind::kFarOrigin: return "far-origin";
  }
  return "?";
}

bool is_must_hit(RaySetKind kind) {
  return kind == RaySetKind::kClosedInsideRandom || kind == RaySetKind::kSharedEdgeAimed || kind == RaySetKind::kVertexAimed;
}

bool has_sources(RaySetKind kind) {
  return kind == RaySetKind::kDiffuse || kind == RaySetKind::kShadow || kind == RaySetKind::kShadowTiled ||
         kind == RaySetKind::kReintersection;
}

bool has_exact_count(RaySetKind kind) { return kind != RaySetKind::kShadowTiled; }

std::string to_string(Query query) { return query == Query::kIntersect ? "intersect" : "occluded"; }

std::vector<std::string> rayset_kind_names() {
  std::vector<std::string> names;
  for (RaySetKind k : kAllKinds) names.push_back(to_string(k));
  return names;
}

RaySetKind parse_rayset_kind(const std::string& name) {
  for (RaySetKind k : kAllKinds)
    if (to_string(k) == name) return k;
  throw InputError("", fmt::format("unknown ray set '{}' (known: {})", name, fmt::join(rayset_kind_names(), ", ")));
}

Query query_of(RaySetKind kind) {
  return kind == RaySetKind::kShadow || kind == RaySetKind::kShadowTiled ? Query::kOccluded : Query::kIntersect;
}

RayGenerator::RayGenerator(const Scene& scene) : scene_(scene), bounds_(scene.bounds()) {
  if (scene.has_analytic()) {
    // Our mixed BVH2 (bvh/mixed_bvh2.h) with the fixed surface tests:
    // SpherePrecise, Slab, Obb beside Möller–Trumbore.
    mixed_ = build_mixed_bvh2<MollerTrumbore>(scene.primitives());
    return;
  }
  bvh_ = build_bvh2_binned_sah(scene.triangles);
  prepared_.reserve(bvh_.prim_ids.size());
  for (std::uint32_t id : bvh_.prim_ids) prepared_.push_back(MollerTrumbore::prepare(scene.triangles[id]));
}

Hit RayGenerator::closest_hit(const Ray& ray) const {
  if (scene_.has_analytic()) return intersect_mixed_bvh2<MollerTrumbore>(mixed_, ray);
  return intersect_bvh2<MollerTrumbore>(bvh_, prepared_, ray);
}

Camera RayGenerator::default_camera() const {
  // Look at the box's centre from above and to the side, as close as possible
  // with all eight corners inside the frame (plus a 5 % margin): corner c at
  // lateral offset x and depth offset z needs distance d >= |x| / tan(half fov) - z.
  Camera c;
  const Eigen::Vector3d center = to_eigen(bounds_.center());
  const Eigen::Vector3d forward = -Eigen::Vector3d(0.6, 0.45, 1.0).normalized();
  const Eigen::Vector3d right = forward.cross(to_eigen(c.up)).normalized();
  const Eigen::Vector3d up = right.cross(forward);
  const double tan_w = std::tan(c.fov_degrees * std::numbers::pi / 360.0), tan_h = tan_w / c.aspect;
  double distance = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1 ? bounds_.upper : bounds_.lower).x, (corner & 2 ? bounds_.upper : bounds_.lower).y,
                            (corner & 4 ? bounds_.upper : bounds_.lower).z);
    const Eigen::Vector3d q = p - center;
    const double z = q.dot(forward);
    distance = std::max({distance, std::fabs(q.dot(right)) * 1.05 / tan_w - z, std::fabs(q.dot(up)) * 1.05 / tan_h - z});
  }
  c.position = to_vec(center - forward * distance);
  c.look_at = to_vec(center);
  return c;
}

Vec3f RayGenerator::default_light() const {
  const Eigen::Vector3d center = to_eigen(bounds_.center());
  const double radius = 0.5 * to_eigen(bounds_.extent()).norm();
  return to_vec(center + Eigen::Vector3d(-0.4, 1.0, 0.25).normalized() * (2.0 * radius));
}

std::uint64_t RayGenerator::key(const RaySetSpec& spec) const {
  const Camera c = spec.camera.value_or(default_camera());
  const Vec3f l = spec.light.value_or(default_light());
  std::uint64_t h = mix64(scene_.content_hash() ^ kRayGeneratorVersion);
  const InsideBall b = spec.inside.value_or(InsideBall{});
  for (float f : {c.position.x, c.position.y, c.position.z, c.look_at.x, c.look_at.y, c.look_at.z, c.up.x, c.up.y,
                  c.up.z, c.fov_degrees, c.aspect, l.x, l.y, l.z, b.center.x, b.center.y, b.center.z, b.radius})
    h = mix64(h ^ std::bit_cast<std::uint32_t>(f));
  return mix64(h ^ mix64(stream_of(spec.kind) ^ mix64(spec.count ^ mix64(spec.seed))));
}

std::vector<Ray> RayGenerator::generate(const RaySetSpec& spec, std::vector<std::int32_t>* sources) const {
  const Camera camera = spec.camera.value_or(default_camera());
  if (sources) sources->assign(spec.count, kNoHit);
  switch (spec.kind) {
    case RaySetKind::kPrimary: return primary(spec, camera);
    case RaySetKind::kPrimaryTiled: return primary_tiled(spec, camera);
    case RaySetKind::kShadowTiled: return shadow_tiled(spec, camera, sources);
    case RaySetKind::kDiffuse:
    case RaySetKind::kShadow:
    case RaySetKind::kReintersection: return from_primary_hits(spec, camera, sources);
    case RaySetKind::kUniform: return uniform(spec);
    case RaySetKind::kClosedInsideRandom:
    case RaySetKind::kSharedEdgeAimed:
    case RaySetKind::kVertexAimed: return must_hit(spec);
    default: return extreme(spec);
  }
}

namespace {

// The primary grid of N rays: W = ceil(sqrt(N * aspect)) columns and as many
// rows as N needs; the last row is partly filled.
struct PixelGrid {
  std::size_t width = 0, height = 0, count = 0;
  PixelGrid(std::size_t n, float aspect)
      : width(static_cast<std::size_t>(std::ceil(std::sqrt(n * static_cast<double>(aspect))))),
        height(width == 0 ? 0 : (n + width - 1) / width),
        count(n) {}
};

// The ray through pixel i (in scanline order) of the grid, jittered by the
// pixel's own random numbers: the same ray whatever order the pixels come in.
Ray pixel_ray(const RaySetSpec& spec, const Camera& camera, const PixelGrid& grid, std::size_t i) {
  Rng rng(spec.seed, stream_of(RaySetKind::kPrimary), i);
  const double sx = (static_cast<double>(i % grid.width) + rng.next_double()) / grid.width;
  const double sy = (static_cast<double>(i / grid.width) + rng.next_double()) / grid.height;
  return camera_ray(camera, sx, sy);
}

// The grid's scanline pixel indices in tile order: 8x8 tiles in scanline
// order of tiles; inside a tile the bits of the position k = 0..63 give
// x = k0 + 2 k1 + 4 k4 and y = k2 + 2 k3 + 4 k5, so 8 consecutive pixels form
// a 4x2 block, 16 a 4x4 block, 32 an 8x4 half tile and 64 the tile. Pixels
// outside the grid (partial tiles at the right and bottom, the partial last
// row) are skipped: every pixel exactly once.
std::vector<std::size_t> tiled_pixel_order(const PixelGrid& grid) {
  constexpr std::size_t kTile = 8;
  std::vector<std::size_t> order;
  order.reserve(grid.count);
  for (std::size_t ty = 0; ty < grid.height; ty += kTile)
    for (std::size_t tx = 0; tx < grid.width; tx += kTile)
      for (std::size_t k = 0; k < kTile * kTile; ++k) {
        const std::size_t x = tx + (k & 1) + (k >> 1 & 1) * 2 + (k >> 4 & 1) * 4;
        const std::size_t y = ty + (k >> 2 & 1) + (k >> 3 & 1) * 2 + (k >> 5 & 1) * 4;
        if (x < grid.width && y * grid.width + x < grid.count) order.push_back(y * grid.width + x);
      }
  return order;
}

}  // namespace

// A jittered W x H grid in scanline order (coherent, as a renderer issues
// them): W = ceil(sqrt(N * aspect)), and the last row is partly filled.
std::vector<Ray> RayGenerator::primary(const RaySetSpec& spec, const Camera& camera) const {
  std::vector<Ray> rays(spec.count);
  const PixelGrid grid(spec.count, camera.aspect);
  tbb::parallel_for(std::size_t{0}, spec.count, [&](std::size_t i) { rays[i] = pixel_ray(spec, camera, grid, i); });
  return rays;
}

// primary's rays, bit for bit, in tiled_pixel_order: a permutation of primary.
std::vector<Ray> RayGenerator::primary_tiled(const RaySetSpec& spec, const Camera& camera) const {
  const PixelGrid grid(spec.count, camera.aspect);
  const std::vector<std::size_t> order = tiled_pixel_order(grid);
  std::vector<Ray> rays(order.size());
  tbb::parallel_for(std::size_t{0}, order.size(), [&](std::size_t k) { rays[k] = pixel_ray(spec, camera, grid, order[k]); });
  return rays;
}

// One shadow ray (as secondary_ray makes them for `shadow`) from each hit of
// the primary-tiled rays, in their order. Pixels that miss, or whose hit has
// no usable normal, give no ray: the set holds at most spec.count rays.
std::vector<Ray> RayGenerator::shadow_tiled(const RaySetSpec& spec, const Camera& camera,
                                            std::vector<std::int32_t>* sources) const {
  const Vec3f light = spec.light.value_or(default_light());
  const std::vector<Ray> pixels = primary_tiled(spec, camera);
  std::vector<Ray> candidates(pixels.size());
  std::vector<std::int32_t> candidate_sources(pixels.size(), kNoHit);
  std::vector<std::uint8_t> made(pixels.size(), 0);
  tbb::parallel_for(std::size_t{0}, pixels.size(), [&](std::size_t k) {
    const Hit hit = closest_hit(pixels[k]);
    if (!hit.hit()) return;
    Rng unused(spec.seed, stream_of(RaySetKind::kShadowTiled), k);  // shadow rays draw no random numbers
    if (!secondary_ray(RaySetKind::kShadow, pixels[k], hit, light, unused, k, candidates[k])) return;
    candidate_sources[k] = hit.prim;
    made[k] = 1;
  });
  std::vector<Ray> out;
  out.reserve(pixels.size());
  if (sources) sources->clear();
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    if (!made[k]) continue;
    out.push_back(candidates[k]);
    if (sources) sources->push_back(candidate_sources[k]);
  }
  if (out.empty() && spec.count > 0)
    throw InputError(scene_.name, fmt::format("the camera sees nothing of the scene (none of {} primary-tiled rays hit); "
                                              "set a camera for it in the suite manifest", pixels.size()));
  return out;
}

bool RayGenerator::secondary_ray(RaySetKind kind, const Ray& primary, const Hit& hit, Vec3f light, Rng& rng,
                                 std::size_t index, Ray& out) const {
  Eigen::Vector3d n, p;
  if (static_cast<std::size_t>(hit.prim) < scene_.triangles.size()) {
    const Triangle& tri = scene_.triangles[hit.prim];
    const Eigen::Vector3d v0 = to_eigen(tri.v0), v1 = to_eigen(tri.v1), v2 = to_eigen(tri.v2);
    n = (v1 - v0).cross(v2 - v0);
    if (!(n.norm() > 0.0)) return false;  // zero-area triangle: no normal to bounce around
    n.normalize();
    // The hit point from barycentrics (more accurate than org + t dir).
    p = (1.0 - hit.u - hit.v) * v0 + hit.u * v1 + hit.v * v2;
  } else {
    // An analytic hit: org + t dir moved onto the surface (t's rounding
    // would otherwise leave it off by more than the offset below), and
    // the outward normal there.
    const Eigen::Vector3d org = to_eigen(primary.org), dir = to_eigen(primary.dir);
    const SurfacePoint s =
        nearest_surface_point(scene_.primitives(), static_cast<std::size_t>(hit.prim), org + static_cast<double>(hit.t) * dir, org, dir);
    p = s.point;
    n = s.normal;
  }
  // Offset off the surface on the side the primary ray came from (the
  // inside, for a camera inside a sphere or box).
  if (n.dot(to_eigen(primary.dir)) > 0.0) n = -n;  // face the incoming ray
  Ray r;
  r.org = offset_ray_origin(to_vec(p), to_vec(n));
  // Reintersection (G18): odd rays toward a random point of the bounds,
  // which may lie behind the surface; even rays like diffuse ones.
  if (kind == RaySetKind::kReintersection && index % 2 == 1) {
    const Eigen::Vector3d target = to_eigen(bounds_.lower) + Eigen::Vector3d(rng.next_double(), rng.next_double(),
                                                                             rng.next_double()).cwiseProduct(to_eigen(bounds_.extent()));
    const Eigen::Vector3d d = target - to_eigen(r.org);
    if (!(d.norm() > 0.0)) return false;
    r.dir = to_vec(d.normalized());
  } else if (kind != RaySetKind::kShadow) {
    // Cosine-weighted hemisphere (Malley's method).
    const double r1 = rng.next_double(), phi = 2.0 * std::numbers::pi * rng.next_double();
    const double radius = std::sqrt(r1);
    Eigen::Vector3d b1, b2;
    basis(n, b1, b2);
    const Eigen::Vector3d d = (b1 * (radius * std::cos(phi)) + b2 * (radius * std::sin(phi)) + n * std::sqrt(1.0 - r1)).normalized();
    r.dir = to_vec(d);
  } else {
    const Eigen::Vector3d to_light = to_eigen(light) - to_eigen(r.org);
    const double distance = to_light.norm();
    if (!(distance > 0.0)) return false;
    r.dir = to_vec(to_light / distance);
    r.tfar = static_cast<float>(distance);
  }
  out = r;
  return true;
}

// One ray per primary hit, primary rays through uniformly random pixels,
// drawn in blocks until `count` hits are found.
std::vector<Ray> RayGenerator::from_primary_hits(const RaySetSpec& spec, const Camera& camera,
                                                 std::vector<std::int32_t>* sources) const {
  const Vec3f light = spec.light.value_or(default_light());
  const std::uint64_t stream = stream_of(spec.kind);
  std::vector<Ray> out;
  out.reserve(spec.count);
  const std::size_t block = std::max<std::size_t>(spec.count, 1024);
  const std::size_t max_candidates = 64 * block;
  std::vector<Ray> candidates(block);
  std::vector<std::int32_t> candidate_sources(block);
  std::vector<std::uint8_t> made(block);
  if (sources) sources->clear();
  for (std::size_t first = 0; out.size() < spec.count; first += block) {
    if (first >= max_candidates)
      throw InputError(scene_.name, fmt::format("the camera sees almost nothing of the scene ({} of {} primary rays hit); "
                                                "set a camera for it in the suite manifest", out.size(), first));
    tbb::parallel_for(std::size_t{0}, block, [&](std::size_t j) {
      made[j] = 0;
      Rng rng(spec.seed, stream, first + j);
      const Ray primary = camera_ray(camera, rng.next_double(), rng.next_double());
      const Hit hit = closest_hit(primary);
      if (!hit.hit()) return;
      if (!secondary_ray(spec.kind, primary, hit, light, rng, first + j, candidates[j])) return;
      candidate_sources[j] = hit.prim;
      made[j] = 1;
    });
    for (std::size_t j = 0; j < block && out.size() < spec.count; ++j) {
      if (!made[j]) continue;
      out.push_back(candidates[j]);
      if (sources) sources->push_back(candidate_sources[j]);
    }
  }
  return out;
}

// Origins uniform on a sphere 1.5 times the bounding sphere, each aimed at a
// uniformly random point of the bounding box.
std::vector<Ray> RayGenerator::uniform(const RaySetSpec& spec) const {
  std::vector<Ray> rays(spec.count);
  const Eigen::Vector3d center = to_eigen(bounds_.center());
  const Eigen::Vector3d lower = to_eigen(bounds_.lower), extent = to_eigen(bounds_.extent());
  const double radius = 1.5 * 0.5 * extent.norm();
  tbb::parallel_for(std::size_t{0}, spec.count, [&](std::size_t i) {
    Rng rng(spec.seed, stream_of(RaySetKind::kUniform), i);
    const Eigen::Vector3d origin = center + radius * uniform_direction(rng);
    const Eigen::Vector3d target = lower + Eigen::Vector3d(rng.next_double(), rng.next_double(), rng.next_double()).cwiseProduct(extent);
    Ray r;
    r.org = to_vec(origin);
    r.dir = to_vec((target - origin).normalized());
    rays[i] = r;
  });
  return rays;
}

// G01-G03 of ../shared/EXTREMES.md: origins uniform in the declared inside
// ball; G01 uniform directions, G02 aimed at float lerp(a, b, s) on a random
// edge of a random triangle, G03 at a random vertex. On a closed mesh every
// one of these rays must hit. The random primitive may be analytic: G02 then
// aims at a box's or OBB's edge (a sphere's surface point), G03 at a corner
// (a sphere's axis-extreme point).
std::vector<Ray> RayGenerator::must_hit(const RaySetSpec& spec) const {
  if (!spec.inside || !(spec.inside->radius > 0.0f))
    throw InputError(scene_.name, fmt::format("ray set '{}' needs a closed mesh with a ball inside it: declare "
                                              "inside = {{ center = [x, y, z], radius = r }} for the scene in the suite manifest",
                                              to_string(spec.kind)));
  std::vector<Ray> rays(spec.count);
  const PrimitiveSpans prims = scene_.primitives();
  const std::size_t primitives = prims.size();  // the triangle count in a triangle scene, as before
  tbb::parallel_for(std::size_t{0}, spec.count, [&](std::size_t i) {
    Rng rng(spec.seed, stream_of(spec.kind), i);
    // Uniform in the ball: a uniform direction times radius * cbrt(u).
    const Eigen::Vector3d unit = uniform_direction(rng);
    const Eigen::Vector3d origin = to_eigen(spec.inside->center) + unit * (spec.inside->radius * std::cbrt(rng.next_double()));
    Ray r;
    r.org = to_vec(origin);
    if (spec.kind == RaySetKind::kClosedInsideRandom) {
      r.dir = to_vec(uniform_direction(rng));
    } else if (const std::size_t id = rng.next_u64() % primitives; id >= prims.triangles.size()) {
      const Vec3f target = spec.kind == RaySetKind::kSharedEdgeAimed ? random_edge_point(prims, id, rng) : random_corner(prims, id, rng);
      r.dir = target - r.org;
    } else {
      const Triangle& t = scene_.triangles[id];
      const Vec3f corners[3] = {t.v0, t.v1, t.v2};
      const auto corner = rng.next_u64() % 3;
      Vec3f target = corners[corner];
      if (spec.kind == RaySetKind::kSharedEdgeAimed) {
        const float along = static_cast<float>(rng.next_double());
        target = corners[corner] + (corners[(corner + 1) % 3] - corners[corner]) * along;  // the float lerp
      }
      r.dir = target - r.org;  // unnormalised on purpose: d = target - o, as G02/G03 define it
    }
    rays[i] = r;
  });
  return rays;
}


namespace {

// A point of the triangle with every barycentric coordinate >= margin.
Eigen::Vector3d interior_point(const Triangle& t, Rng& rng, double margin) {
  double b1 = rng.next_double(), b2 = rng.next_double();
  if (b1 + b2 > 1.0) b1 = 1.0 - b1, b2 = 1.0 - b2;
  const double scale = 1.0 - 3.0 * margin;
  b1 = margin + scale * b1;
  b2 = margin + scale * b2;
  return (1.0 - b1 - b2) * to_eigen(t.v0) + b1 * to_eigen(t.v1) + b2 * to_eigen(t.v2);
}

double longest_edge(const Triangle& t) {
  return std::max({(to_eigen(t.v1) - to_eigen(t.v0)).norm(), (to_eigen(t.v2) - to_eigen(t.v1)).norm(),
                   (to_eigen(t.v0) - to_eigen(t.v2)).norm()});
}

// G15's corruptions of a valid ray, cycled through by ray index.
Ray invalidate(Ray r, std::size_t i) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  constexpr std::size_t kFieldPatterns = 6 * 3;  // each of org.xyz and dir.xyz: NaN, +Inf, -Inf
  const std::size_t pattern = i % (kFieldPatterns + 6);
  if (pattern < kFieldPatterns) {
    float* fields[6] = {&r.org.x, &r.org.y, &r.org.z, &r.dir.x, &r.dir.y, &r.dir.z};
    const float values[3] = {kNaN, kInf, -kInf};
    *fields[pattern / 3] = values[pattern % 3];
    return r;
  }
  switch (pattern - kFieldPatterns) {
    case 0: r.tnear = kNaN; break;
    case 1: r.tfar = kNaN; break;
    case 2: r.tnear = 2.0f, r.tfar = 1.0f; break;  // empty interval
    case 3: r.dir = {0.0f, 0.0f, 0.0f}; break;
    case 4: r.org.x = 4.0e18f; break;  // beyond Embree's range (kLargestTraceableCoordinate)
    default: r.dir = {-0.0f, -0.0f, -0.0f}; break;
  }
  return r;
}

// G09's ray at `target`: direction pattern i % 26 of {-1, 0, +1}^3 minus the
// zero vector, each zero +0 or -0. The origin shares the target's
// coordinates along the zero components, so it lies exactly on the slab
// planes through the target (a vertex or corner: a corner of every box
// holding it; or a point of the surface).
Ray axis_parallel_ray(std::size_t i, Vec3f t, double radius, Rng& rng) {
  const std::size_t k = i % 26, code = k < 13 ? k : k + 1;
  const int c[3] = {static_cast<int>(code % 3) - 1, static_cast<int>(code / 3 % 3) - 1, static_cast<int>(code / 9) - 1};
  float d[3], o[3];
  const float tc[3] = {t.x, t.y, t.z};
  const double distance = radius * (0.5 + rng.next_double());
  for (int a = 0; a < 3; ++a) {
    const bool negative_zero = rng.next_u64() % 2;
    d[a] = c[a] == 0 ? (negative_zero ? -0.0f : 0.0f) : static_cast<float>(c[a]);
    o[a] = c[a] == 0 ? tc[a] : static_cast<float>(tc[a] - distance * c[a]);
  }
  Ray r;
  r.org = {o[0], o[1], o[2]};
  r.dir = {d[0], d[1], d[2]};
  return r;
}

// The extreme ray sets that aim at a triangle, aimed at analytic primitive
// `id` instead (issue 31). `center`, `radius`: the scene's bounding sphere.
Ray analytic_extreme_ray(RaySetKind kind, std::size_t i, const PrimitiveSpans& prims, std::size_t id, Rng& rng,
                         const Eigen::Vector3d& center, double radius) {
  const double size = std::max(primitive_size(prims, id), 1e-30);
  Ray r;
  switch (kind) {
    case RaySetKind::kTinyTriangles:
    case RaySetKind::kDegenerateTriangles: {
      // A surface point (10 % from a face's edges), from outside its tangent
      // plane, 1 to 10 sizes away (plus one unit for odd rays): the first
      // surface the ray meets on this primitive is at that point.
      const SurfacePoint s = random_surface_point(prims, id, rng, 0.1);
      Eigen::Vector3d w = uniform_direction(rng);
      if (w.dot(s.normal) < 0.0) w = -w;
      const double distance = size * (1.0 + 9.0 * rng.next_double()) + (i % 2 ? 1.0 : 0.0);
      r.org = to_vec(s.point + distance * w);
      r.dir = to_vec(s.point) - r.org;
      break;
    }
    case RaySetKind::kGrazing: {
      // At 1e-2 ... 1e-6 rad to the surface where the ray meets it: a
      // sphere's ray passes its centre at r cos(alpha) (alpha to the tangent
      // plane where it enters: near-tangent, rounding decides below ~3e-4); a
      // box's or OBB's ray reaches a face point at alpha to the face, from
      // outside or from inside at random, as for a triangle's two sides.
      const double alpha = std::pow(10.0, -2.0 - static_cast<double>(i % 5));
      const double phi = 2.0 * std::numbers::pi * rng.next_double();
      Eigen::Vector3d b1, b2;
      if (prims.kind(id) == PrimitiveKind::kSphere) {
        const Sphere& sphere = prims.spheres[prims.local(id)];
        const Eigen::Vector3d u = uniform_direction(rng);
        basis(u, b1, b2);
        const Eigen::Vector3d d = std::cos(phi) * b1 + std::sin(phi) * b2;
        const Eigen::Vector3d closest = to_eigen(sphere.center) + std::fabs(static_cast<double>(sphere.radius)) * std::cos(alpha) * u;
        r.org = to_vec(closest - 2.0 * size * d);
        r.dir = to_vec(d);
      } else {
        const SurfacePoint s = random_surface_point(prims, id, rng, 0.1);
        basis(s.normal, b1, b2);
        const Eigen::Vector3d d = std::cos(alpha) * (std::cos(phi) * b1 + std::sin(phi) * b2) +
                                  std::sin(alpha) * (rng.next_u64() % 2 ? s.normal : Eigen::Vector3d(-s.normal));
        r.org = to_vec(s.point - 2.0 * size * d);
        r.dir = to_vec(d);
      }
      break;
    }
    case RaySetKind::kAxisParallel: {
      const Vec3f target = i % 3 == 0 ? random_corner(prims, id, rng) : to_vec(random_surface_point(prims, id, rng, 0.0).point);
      r = axis_parallel_ray(i, target, radius, rng);
      break;
    }
    case RaySetKind::kBehindOrigin: {
      // Away from a surface point, out of its tangent plane: the convex
      // primitive lies wholly behind the origin (at t < 0).
      const SurfacePoint s = random_surface_point(prims, id, rng, 0.1);
      Eigen::Vector3d away = uniform_direction(rng);
      if (away.dot(s.normal) < 0.0) away = -away;
      r.org = to_vec(s.point + size * (1.0 + rng.next_double()) * away);
      r.dir = to_vec(away);
      break;
    }
    case RaySetKind::kBvhConservative: {
      // Corners (a sphere's axis-extreme points, where it touches its
      // bounding box) and float points of edges, from outside the scene.
      const Vec3f target = i % 2 ? random_edge_point(prims, id, rng) : random_corner(prims, id, rng);
      r.org = to_vec(center + 1.5 * radius * uniform_direction(rng));
      r.dir = target - r.org;
      break;
    }
    default: break;
  }
  return r;
}

// Whether an extreme kind aims at a random primitive (the others use only the scene's bounds).
bool aims_at_primitive(RaySetKind kind) {
  return kind == RaySetKind::kTinyTriangles || kind == RaySetKind::kDegenerateTriangles || kind == RaySetKind::kGrazing ||
         kind == RaySetKind::kAxisParallel || kind == RaySetKind::kBehindOrigin || kind == RaySetKind::kBvhConservative;
}

}  // namespace

// The extreme ray sets of ../shared/EXTREMES.md that work on any scene. Each
// ray depends only on (seed, kind, index), like every other ray set.
std::vector<Ray> RayGenerator::extreme(const RaySetSpec& spec) const {
  std::vector<Ray> rays(spec.count);
  const PrimitiveSpans prims = scene_.primitives();
  const std::size_t primitives = prims.size();  // the triangle count in a triangle scene, as before
  const Eigen::Vector3d lower = to_eigen(bounds_.lower), extent = to_eigen(bounds_.extent());
  const Eigen::Vector3d center = to_eigen(bounds_.center());
  const double radius = std::max(0.5 * extent.norm(), 1e-30);
  const auto random_point_in_bounds = [&](Rng& rng) {
    return Eigen::Vector3d(lower + Eigen::Vector3d(rng.next_double(), rng.next_double(), rng.next_double()).cwiseProduct(extent));
  };
  const auto outside_origin = [&](Rng& rng) { return Eigen::Vector3d(center + 1.5 * radius * uniform_direction(rng)); };
  tbb::parallel_for(std::size_t{0}, spec.count, [&](std::size_t i) {
    Rng rng(spec.seed, stream_of(spec.kind), i);
    const std::size_t id = rng.next_u64() % primitives;
    const bool analytic = id >= prims.triangles.size();
    if (analytic && aims_at_primitive(spec.kind)) {
      rays[i] = analytic_extreme_ray(spec.kind, i, prims, id, rng, center, radius);
      return;
    }
    static const Triangle kUnused{};  // the kinds below that read `tri` were handled above for analytic ids
    const Triangle& tri = analytic ? kUnused : scene_.triangles[id];
    Ray r;
    switch (spec.kind) {
      case RaySetKind::kTinyTriangles:
      case RaySetKind::kDegenerateTriangles: {
        // From a random direction, 1 to 10 triangle sizes away (and at least
        // one unit, so tiny triangles are seen from a normal distance too).
        const Eigen::Vector3d target = interior_point(tri, rng, 0.1);
        const double distance = std::max(longest_edge(tri), 1e-30) * (1.0 + 9.0 * rng.next_double()) + (i % 2 ? 1.0 : 0.0);
        r.org = to_vec(target - distance * uniform_direction(rng));
        r.dir = to_vec(target) - r.org;
        break;
      }
      case RaySetKind::kGrazing: {
        const Eigen::Vector3d v0 = to_eigen(tri.v0), e1 = to_eigen(tri.v1) - v0, e2 = to_eigen(tri.v2) - v0;
        Eigen::Vector3d n = e1.cross(e2);
        if (!(n.norm() > 0.0)) n = Eigen::Vector3d::UnitY();  // degenerate: no plane to graze
        n.normalize();
        Eigen::Vector3d b1, b2;
        basis(n, b1, b2);
        const double alpha = std::pow(10.0, -2.0 - static_cast<double>(i % 5));  // 1e-2 ... 1e-6 rad
        const double phi = 2.0 * std::numbers::pi * rng.next_double();
        const Eigen::Vector3d d = std::cos(alpha) * (std::cos(phi) * b1 + std::sin(phi) * b2) +
                                  std::sin(alpha) * (rng.next_u64() % 2 ? n : Eigen::Vector3d(-n));
        const Eigen::Vector3d target = interior_point(tri, rng, 0.1);
        r.org = to_vec(target - 2.0 * std::max(longest_edge(tri), 1e-30) * d);
        r.dir = to_vec(d);
        break;
      }
      case RaySetKind::kAxisParallel: {
        const Eigen::Vector3d target = i % 3 == 0 ? to_eigen(tri.v0) : interior_point(tri, rng, 0.0);
        r = axis_parallel_ray(i, to_vec(target), radius, rng);
        break;
      }
      case RaySetKind::kBehindOrigin: {
        const Eigen::Vector3d target = interior_point(tri, rng, 0.1);
        const Eigen::Vector3d away = uniform_direction(rng);
        r.org = to_vec(target + std::max(longest_edge(tri), 1e-30) * (1.0 + rng.next_double()) * away);
        r.dir = to_vec(away);
        break;
      }
      case RaySetKind::kInvalid: {
        r.org = to_vec(outside_origin(rng));
        r.dir = to_vec((random_point_in_bounds(rng) - to_eigen(r.org)).normalized());
        r = invalidate(r, i);
        break;
      }
      case RaySetKind::kDirectionScaling: {
        const Eigen::Vector3d o = outside_origin(rng);
        const double length = std::pow(10.0, std::array<double, 5>{-20, -7, 0, 7, 20}[i % 5]);
        r.org = to_vec(o);
        r.dir = to_vec((random_point_in_bounds(rng) - o).normalized() * length);
        break;
      }
      case RaySetKind::kBvhConservative: {
        const Vec3f corners[3] = {tri.v0, tri.v1, tri.v2};
        const auto corner = rng.next_u64() % 3;
        Vec3f target = corners[corner];
        if (i % 2) target = corners[corner] + (corners[(corner + 1) % 3] - corners[corner]) * static_cast<float>(rng.next_double());
        r.org = to_vec(outside_origin(rng));
        r.dir = target - r.org;
        break;
      }
      case RaySetKind::kControlRandom: {
        r.org = to_vec(random_point_in_bounds(rng));
        r.dir = to_vec(uniform_direction(rng));
        break;
      }
      case RaySetKind::kFarOrigin: {
        const double distance = std::pow(10.0, 5.0 + static_cast<double>(i % 3));  // 1e5, 1e6, 1e7 units
        const Eigen::Vector3d o = center + distance * uniform_direction(rng);
        r.org = to_vec(o);
        r.dir = to_vec((random_point_in_bounds(rng) - o).normalized());
        break;
      }
      default: break;
    }
    rays[i] = r;
  });
  return rays;
}

}  // namespace raybench
