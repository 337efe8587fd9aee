#include "rayset.h"

#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/parallel_for.h>

#include "error.h"
#include "random.h"
#include "raybench/bvh/bvh2_traverse.h"
#include "raybench/math/offset_ray.h"

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

}  // namespace

constexpr RaySetKind kAllKinds[] = {RaySetKind::kPrimary,           RaySetKind::kDiffuse,         RaySetKind::kShadow,
                                    RaySetKind::kUniform,           RaySetKind::kClosedInsideRandom, RaySetKind::kSharedEdgeAimed,
                                    RaySetKind::kVertexAimed};

std::string to_string(RaySetKind kind) {
  switch (kind) {
    case RaySetKind::kPrimary: return "primary";
    case RaySetKind::kDiffuse: return "diffuse";
    case RaySetKind::kShadow: return "shadow";
    case RaySetKind::kUniform: return "uniform";
    case RaySetKind::kClosedInsideRandom: return "closed-inside-random";
    case RaySetKind::kSharedEdgeAimed: return "shared-edge-aimed";
    case RaySetKind::kVertexAimed: return "vertex-aimed";
  }
  return "?";
}

bool is_must_hit(RaySetKind kind) {
  return kind == RaySetKind::kClosedInsideRandom || kind == RaySetKind::kSharedEdgeAimed || kind == RaySetKind::kVertexAimed;
}

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

Query query_of(RaySetKind kind) { return kind == RaySetKind::kShadow ? Query::kOccluded : Query::kIntersect; }

RayGenerator::RayGenerator(const Scene& scene) : scene_(scene), bounds_(scene.bounds()) {
  bvh_ = build_bvh2_binned_sah(scene.triangles);
  prepared_.reserve(bvh_.prim_ids.size());
  for (std::uint32_t id : bvh_.prim_ids) prepared_.push_back(MollerTrumbore::prepare(scene.triangles[id]));
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

std::vector<Ray> RayGenerator::generate(const RaySetSpec& spec) const {
  const Camera camera = spec.camera.value_or(default_camera());
  switch (spec.kind) {
    case RaySetKind::kPrimary: return primary(spec, camera);
    case RaySetKind::kDiffuse:
    case RaySetKind::kShadow: return from_primary_hits(spec, camera);
    case RaySetKind::kUniform: return uniform(spec);
    case RaySetKind::kClosedInsideRandom:
    case RaySetKind::kSharedEdgeAimed:
    case RaySetKind::kVertexAimed: return must_hit(spec);
  }
  return {};
}

// A jittered W x H grid in scanline order (coherent, as a renderer issues
// them): W = ceil(sqrt(N * aspect)), and the last row is partly filled.
std::vector<Ray> RayGenerator::primary(const RaySetSpec& spec, const Camera& camera) const {
  std::vector<Ray> rays(spec.count);
  const auto width = static_cast<std::size_t>(std::ceil(std::sqrt(spec.count * static_cast<double>(camera.aspect))));
  const std::size_t height = width == 0 ? 0 : (spec.count + width - 1) / width;
  tbb::parallel_for(std::size_t{0}, spec.count, [&](std::size_t i) {
    Rng rng(spec.seed, stream_of(RaySetKind::kPrimary), i);
    const double sx = (static_cast<double>(i % width) + rng.next_double()) / width;
    const double sy = (static_cast<double>(i / width) + rng.next_double()) / height;
    rays[i] = camera_ray(camera, sx, sy);
  });
  return rays;
}

// One ray per primary hit, primary rays through uniformly random pixels,
// drawn in blocks until `count` hits are found.
std::vector<Ray> RayGenerator::from_primary_hits(const RaySetSpec& spec, const Camera& camera) const {
  const Vec3f light = spec.light.value_or(default_light());
  const std::uint64_t stream = stream_of(spec.kind);
  std::vector<Ray> out;
  out.reserve(spec.count);
  const std::size_t block = std::max<std::size_t>(spec.count, 1024);
  const std::size_t max_candidates = 64 * block;
  std::vector<Ray> candidates(block);
  std::vector<std::uint8_t> made(block);
  for (std::size_t first = 0; out.size() < spec.count; first += block) {
    if (first >= max_candidates)
      throw InputError(scene_.name, fmt::format("the camera sees almost nothing of the scene ({} of {} primary rays hit); "
                                                "set a camera for it in the suite manifest", out.size(), first));
    tbb::parallel_for(std::size_t{0}, block, [&](std::size_t j) {
      made[j] = 0;
      Rng rng(spec.seed, stream, first + j);
      const Ray primary = camera_ray(camera, rng.next_double(), rng.next_double());
      const Hit hit = intersect_bvh2<MollerTrumbore>(bvh_, prepared_, primary);
      if (!hit.hit()) return;
      const Triangle& tri = scene_.triangles[hit.prim];
      const Eigen::Vector3d v0 = to_eigen(tri.v0), v1 = to_eigen(tri.v1), v2 = to_eigen(tri.v2);
      Eigen::Vector3d n = (v1 - v0).cross(v2 - v0);
      if (!(n.norm() > 0.0)) return;  // zero-area triangle: no normal to bounce around
      n.normalize();
      if (n.dot(to_eigen(primary.dir)) > 0.0) n = -n;  // face the incoming ray
      // The hit point from barycentrics (more accurate than org + t dir), then
      // offset off the surface on the side the primary ray came from.
      const Eigen::Vector3d p = (1.0 - hit.u - hit.v) * v0 + hit.u * v1 + hit.v * v2;
      Ray r;
      r.org = offset_ray_origin(to_vec(p), to_vec(n));
      if (spec.kind == RaySetKind::kDiffuse) {
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
        if (!(distance > 0.0)) return;
        r.dir = to_vec(to_light / distance);
        r.tfar = static_cast<float>(distance);
      }
      candidates[j] = r;
      made[j] = 1;
    });
    for (std::size_t j = 0; j < block && out.size() < spec.count; ++j)
      if (made[j]) out.push_back(candidates[j]);
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
    const double z = 2.0 * rng.next_double() - 1.0, phi = 2.0 * std::numbers::pi * rng.next_double();
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d origin = center + radius * Eigen::Vector3d(s * std::cos(phi), z, s * std::sin(phi));
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
// one of these rays must hit.
std::vector<Ray> RayGenerator::must_hit(const RaySetSpec& spec) const {
  if (!spec.inside || !(spec.inside->radius > 0.0f))
    throw InputError(scene_.name, fmt::format("ray set '{}' needs a closed mesh with a ball inside it: declare "
                                              "inside = {{ center = [x, y, z], radius = r }} for the scene in the suite manifest",
                                              to_string(spec.kind)));
  std::vector<Ray> rays(spec.count);
  const std::size_t triangles = scene_.triangles.size();
  tbb::parallel_for(std::size_t{0}, spec.count, [&](std::size_t i) {
    Rng rng(spec.seed, stream_of(spec.kind), i);
    // Uniform in the ball: a uniform direction times radius * cbrt(u).
    const double z = 2.0 * rng.next_double() - 1.0, phi = 2.0 * std::numbers::pi * rng.next_double();
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d unit(s * std::cos(phi), z, s * std::sin(phi));
    const Eigen::Vector3d origin = to_eigen(spec.inside->center) + unit * (spec.inside->radius * std::cbrt(rng.next_double()));
    Ray r;
    r.org = to_vec(origin);
    if (spec.kind == RaySetKind::kClosedInsideRandom) {
      const double z2 = 2.0 * rng.next_double() - 1.0, phi2 = 2.0 * std::numbers::pi * rng.next_double();
      const double s2 = std::sqrt(std::max(0.0, 1.0 - z2 * z2));
      r.dir = to_vec(Eigen::Vector3d(s2 * std::cos(phi2), z2, s2 * std::sin(phi2)));
    } else {
      const Triangle& t = scene_.triangles[rng.next_u64() % triangles];
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

}  // namespace raybench
