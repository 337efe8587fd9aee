// The only file that includes Embree. Embree 3 (Debian libembree-dev),
// single-ray API: rtcIntersect1 for closest hit, rtcOccluded1 for any hit.
//
// Every primitive type of a scene (raybench/prim/primitives.h) is modelled
// natively, one Embree geometry per type, attached only when the scene has
// that type, under a fixed geometry id: 0 triangles, 1 spheres, 2 boxes,
// 3 oriented boxes. A hit's global prim id is the first id of its type plus
// Embree's primID; analytic hits report u = v = 0 (prim/analytic_hit.h).
// - Triangles: RTC_GEOMETRY_TYPE_TRIANGLE.
// - Spheres: RTC_GEOMETRY_TYPE_SPHERE_POINT (FLOAT4 x y z |r|: Embree drops
//   a negative radius), Embree's own test; `embree:disc` uses DISC_POINT.
// - Boxes and oriented boxes: RTC_GEOMETRY_TYPE_USER, whose callbacks run
//   our scalar surface tests (analytic_hit.h: Slab, Obb) behind Embree's BVH
//   over widened bounds (user_bounds); their cost is part of what is measured.
// Embree's sphere and disc semantics as embree_analytic_test.cpp pins them
// (closed at tnear, tangent hits, the near root's cancellation):
// docs/backends.md, "Analytic primitives in Embree".
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sys/types.h>
#include <cstring>
#include <vector>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "backends/backend.h"
#include "backends/embree_backend.h"
#include "io/error.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/analytic_hit.h"
#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/primitives.h"

namespace raybench {
namespace {

// A ray whose interval (max(tnear, 0), tfar] is empty -- tfar below it,
// tfar = -inf included -- can hit nothing, for every backend. Embree must not
// be asked: it leaves such a ray's tfar untouched, and rtcOccluded1 reports an
// occluded ray by setting tfar to -inf, so a ray that came with tfar = -inf
// would read as occluded.
bool has_empty_interval(const Ray& r) { return r.tfar < std::max(r.tnear, 0.0f); }

struct EmbreeOptions {
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
  bool robust = false;
  bool disc = false;  // spheres as RTC_GEOMETRY_TYPE_DISC_POINT (see the file's top)
};

// Embree's geometry ids, one per primitive type (PrimitiveKind's order).
enum GeometryId : unsigned { kTriangleGeometry = 0, kSphereGeometry = 1, kBoxGeometry = 2, kObbGeometry = 3 };

// A user geometry's callbacks: our scene-level surface test of one analytic
// type (analytic_hit.h) behind Embree's traversal. The user pointer is the
// backend's copy of that type's primitives. Embree calls the callbacks with
// N = 1 for rtcIntersect1 / rtcOccluded1; they loop over N as the API allows.
template <typename Prim>
struct UserGeometry;

template <>
struct UserGeometry<BBox> {
  static BBox bounds(const BBox& b) { return b; }
  static bool hit(const Ray& ray, const BBox& b, float& t) {
    return intersect_box_surface<Slab>(Slab::precompute(ray), ray, ray.tfar, b, t);
  }
};

template <>
struct UserGeometry<OrientedBox> {
  static BBox bounds(const OrientedBox& b) { return oriented_box_bounds(b); }
  static bool hit(const Ray& ray, const OrientedBox& b, float& t) {
    return intersect_obb_surface<Obb>(ray, ray.tfar, b, t);
  }
};

// The box Embree's BVH gets: the primitive's, widened on every side by 1e-6
// of its largest coordinate magnitude or extent, and one float ulp.
// - Embree's node test replaces 1/0 by a large finite number (rcp_safe), so a
//   ray lying exactly in a box's far plane, with a zero component across it,
//   gets the far distance 0 * large = 0 on that axis and is culled before our
//   test, which keeps it (closed box; Slab reads 0 * inf = NaN as no
//   constraint). One ulp outward makes that distance positive.
// - Its distances are plane * (1/d) - org * (1/d) with an approximate 1/d
//   (rcp and one Newton step), off from our Slab's by some ulps of the
//   coordinates and of t, so a ray through an edge or a corner can pass ours
//   and fail Embree's. RTC_SCENE_FLAG_ROBUST does not help: Embree 3.13 has
//   no robust traversal for user geometry (bvh4_factory.cpp lists only
//   BVH4VirtualIntersector1). The 1e-6 covers rays from within about the
//   box's own magnitude; from much further, an edge hit can still be culled
//   (embree_analytic_test.cpp, KnownLimit_EdgesAndCornersFromFarAwayCanBeCulled).
// Culling only: the callback decides every hit on the primitive itself.
template <typename Prim>
void user_bounds(const RTCBoundsFunctionArguments* args) {
  const BBox b = UserGeometry<Prim>::bounds(static_cast<const Prim*>(args->geometryUserPtr)[args->primID]);
  float scale = 0.0f;
  for (int a = 0; a < 3; ++a)
    scale = std::max({scale, std::fabs(b.lower[a]), std::fabs(b.upper[a]), b.upper[a] - b.lower[a]});
  const float pad = scale * 1e-6f;
  const auto down = [&](float x) { return std::nextafter(x - pad, -std::numeric_limits<float>::infinity()); };
  const auto up = [&](float x) { return std::nextafter(x + pad, std::numeric_limits<float>::infinity()); };
  *args->bounds_o = {down(b.lower.x), down(b.lower.y), down(b.lower.z), 0.0f,
                     up(b.upper.x),   up(b.upper.y),   up(b.upper.z),   0.0f};
}

// The ray as Embree holds it (tnear >= 0 already: fill() raised it), its
// current tfar being the closest hit so far.
inline Ray ray_of(RTCRayN* r, unsigned n, unsigned i) {
  return {{RTCRayN_org_x(r, n, i), RTCRayN_org_y(r, n, i), RTCRayN_org_z(r, n, i)},
          RTCRayN_tnear(r, n, i),
          {RTCRayN_dir_x(r, n, i), RTCRayN_dir_y(r, n, i), RTCRayN_dir_z(r, n, i)},
          RTCRayN_tfar(r, n, i)};
}

template <typename Prim>
void user_intersect(const RTCIntersectFunctionNArguments* args) {
  const Prim& prim = static_cast<const Prim*>(args->geometryUserPtr)[args->primID];
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Ray ray = ray_of(rays, args->N, i);
    float t;
    if (!UserGeometry<Prim>::hit(ray, prim, t)) continue;  // t in (tnear, tfar]: the closest so far
    RTCRayN_tfar(rays, args->N, i) = t;
    // Ng: the backward direction, a placeholder (raybench hits carry no normal).
    RTCHitN_Ng_x(hits, args->N, i) = -ray.dir.x;
    RTCHitN_Ng_y(hits, args->N, i) = -ray.dir.y;
    RTCHitN_Ng_z(hits, args->N, i) = -ray.dir.z;
    RTCHitN_u(hits, args->N, i) = 0.0f;
    RTCHitN_v(hits, args->N, i) = 0.0f;
    RTCHitN_primID(hits, args->N, i) = args->primID;
    RTCHitN_geomID(hits, args->N, i) = args->geomID;
    RTCHitN_instID(hits, args->N, i, 0) = args->context->instID[0];
  }
}

template <typename Prim>
void user_occluded(const RTCOccludedFunctionNArguments* args) {
  const Prim& prim = static_cast<const Prim*>(args->geometryUserPtr)[args->primID];
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    float t;
    if (UserGeometry<Prim>::hit(ray_of(args->ray, args->N, i), prim, t))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();  // Embree's "occluded"
  }
}

class EmbreeBackend final : public Backend {
 public:
  EmbreeBackend(std::string name, EmbreeOptions options)
      : name_(std::move(name)), options_(options) {
    // No "threads=N": Embree would enforce it with a process-wide
    // tbb::global_control, replaced by each newer device, so while a
    // 1-thread Embree backend was the newest every other backend's 2-thread
    // build ran on one thread (ours measured 1.0x instead of 1.8x). Embree's
    // build runs in the caller's TBB arena instead, which the harness sizes
    // to BackendConfig::threads for every backend alike (TraceExecutor::run).
    const std::string device_config = "verbose=0";
    device_ = rtcNewDevice(device_config.c_str());
    if (!device_) throw std::runtime_error("embree: cannot create a device (" + device_config + ")");
    rtcSetDeviceErrorFunction(
        device_, [](void* self, RTCError, const char* message) { static_cast<EmbreeBackend*>(self)->last_error_ = message; },
        this);
    rtcSetDeviceMemoryMonitorFunction(
        device_,
        [](void* self, ssize_t bytes, bool) {
          static_cast<EmbreeBackend*>(self)->allocated_ += bytes;
          return true;
        },
        this);
  }
  ~EmbreeBackend() override {
    if (scene_) rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }

  const std::string& name() const override { return name_; }

  Capabilities capabilities() const override {
    Capabilities c;
    c.spheres = c.boxes = c.oriented_boxes = true;
    return c;
  }

  void build(const Scene& scene) override {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, options_.quality);
    rtcSetSceneFlags(scene_, options_.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    const PrimitiveSpans prims = scene.primitives();
    analytic_ = prims.has_analytic();
    first_id_[kTriangleGeometry] = 0;
    first_id_[kSphereGeometry] = static_cast<std::uint32_t>(prims.first_sphere());
    first_id_[kBoxGeometry] = static_cast<std::uint32_t>(prims.first_box());
    first_id_[kObbGeometry] = static_cast<std::uint32_t>(prims.first_obb());
    if (!scene.triangles.empty()) attach_triangles(scene.triangles);
    if (!scene.spheres.empty()) attach_spheres(scene.spheres);
    // The callbacks read the backend's own copies, which outlive the Scene.
    boxes_ = scene.boxes;
    obbs_ = scene.obbs;
    if (!boxes_.empty()) attach_user(boxes_, kBoxGeometry);
    if (!obbs_.empty()) attach_user(obbs_, kObbGeometry);
    // Only what the build itself allocates counts as the structure's memory,
    // not the vertex and index buffers every backend shares an equivalent of.
    const std::int64_t before = allocated_.load();
    rtcCommitScene(scene_);
    memory_ = static_cast<std::size_t>(std::max<std::int64_t>(0, allocated_.load() - before));
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("embree: build failed: " + last_error_);
  }

  std::size_t memory_bytes() const override { return memory_; }

  // A triangle-only scene takes the loop without the id mapping, so that its
  // per-ray work is what it was before analytic primitives existed.
  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if (analytic_) intersect_rays<true>(rays, hits);
    else intersect_rays<false>(rays, hits);
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      occluded[i] = 0;
      if (!is_traceable(rays[i]) || has_empty_interval(rays[i])) continue;
      RTCRay ray;
      fill(ray, rays[i]);
      rtcOccluded1(scene_, &context, &ray);
      // tfar >= 0 went in (the interval is not empty): -inf is Embree's "occluded".
      occluded[i] = ray.tfar == -std::numeric_limits<float>::infinity() ? 1 : 0;
    }
  }

 private:
  template <bool Analytic>
  void intersect_rays(std::span<const Ray> rays, std::span<Hit> hits) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      hits[i] = Hit{};
      if (!is_traceable(rays[i]) || has_empty_interval(rays[i])) continue;  // Debian's Embree asserts on NaN/Inf
      RTCRayHit rh;
      fill(rh.ray, rays[i]);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      if constexpr (Analytic) {
        const bool triangle = rh.hit.geomID == kTriangleGeometry;
        hits[i] = {rh.ray.tfar, static_cast<std::int32_t>(first_id_[rh.hit.geomID] + rh.hit.primID),
                   triangle ? rh.hit.u : 0.0f, triangle ? rh.hit.v : 0.0f};
      } else {
        hits[i] = {rh.ray.tfar, static_cast<std::int32_t>(rh.hit.primID), rh.hit.u, rh.hit.v};
      }
    }
  }

  // Commits `geometry` and attaches it to the scene under `id`.
  void attach(RTCGeometry geometry, GeometryId id) {
    rtcSetGeometryBuildQuality(geometry, options_.quality);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene_, geometry, id);
    rtcReleaseGeometry(geometry);
  }

  void attach_triangles(const std::vector<Triangle>& triangles) {
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    const std::size_t n = triangles.size();
    // Embree allocates these buffers itself, padded for its 16-byte loads.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
    auto* indices = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), n));
    if (!vertices || !indices) throw std::runtime_error("embree: buffer allocation failed: " + last_error_);
    std::memcpy(vertices, triangles.data(), n * sizeof(Triangle));
    for (std::size_t i = 0; i < 3 * n; ++i) indices[i] = static_cast<std::uint32_t>(i);
    attach(geometry, kTriangleGeometry);
  }

  void attach_spheres(const std::vector<Sphere>& spheres) {
    RTCGeometry geometry =
        rtcNewGeometry(device_, options_.disc ? RTC_GEOMETRY_TYPE_DISC_POINT : RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* points = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                               4 * sizeof(float), spheres.size()));
    if (!points) throw std::runtime_error("embree: buffer allocation failed: " + last_error_);
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      const Sphere& s = spheres[i];
      // |r|: Embree drops a sphere of negative radius as invalid (see the top).
      points[4 * i + 0] = s.center.x;
      points[4 * i + 1] = s.center.y;
      points[4 * i + 2] = s.center.z;
      points[4 * i + 3] = std::fabs(s.radius);
    }
    attach(geometry, kSphereGeometry);
  }

  template <typename Prim>
  void attach_user(const std::vector<Prim>& prims, GeometryId id) {
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(prims.size()));
    rtcSetGeometryUserData(geometry, const_cast<Prim*>(prims.data()));
    rtcSetGeometryBoundsFunction(geometry, user_bounds<Prim>, nullptr);
    rtcSetGeometryIntersectFunction(geometry, user_intersect<Prim>);
    rtcSetGeometryOccludedFunction(geometry, user_occluded<Prim>);
    attach(geometry, id);
  }

  static void fill(RTCRay& out, const Ray& in) {
    const Ray r = with_nonnegative_tnear(in);
    out.org_x = r.org.x;
    out.org_y = r.org.y;
    out.org_z = r.org.z;
    out.tnear = r.tnear;
    out.dir_x = r.dir.x;
    out.dir_y = r.dir.y;
    out.dir_z = r.dir.z;
    out.time = 0.0f;
    out.tfar = r.tfar;
    out.mask = 0xffffffffu;
    out.id = 0;
    out.flags = 0;
  }

  std::string name_;
  EmbreeOptions options_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::string last_error_;
  std::atomic<std::int64_t> allocated_{0};
  std::size_t memory_ = 0;
  bool analytic_ = false;             // the scene has spheres, boxes or OBBs
  std::uint32_t first_id_[4] = {};   // the global prim id of each geometry's primID 0
  std::vector<BBox> boxes_;          // the user geometries' primitives
  std::vector<OrientedBox> obbs_;
};

std::unique_ptr<Backend> make_embree_backend(const std::string& name, const std::vector<std::string>& options,
                                             const BackendConfig&) {
  EmbreeOptions parsed;
  for (const std::string& o : options) {
    if (o == "low") parsed.quality = RTC_BUILD_QUALITY_LOW;
    else if (o == "medium") parsed.quality = RTC_BUILD_QUALITY_MEDIUM;
    else if (o == "high") parsed.quality = RTC_BUILD_QUALITY_HIGH;
    else if (o == "robust") parsed.robust = true;
    else if (o == "disc") parsed.disc = true;
    else throw InputError("", fmt::format("backend '{}': unknown embree option '{}' (known: low, medium, high, robust, disc)", name, o));
  }
  return std::make_unique<EmbreeBackend>(name, parsed);
}

std::vector<BackendInfo> embree_backend_names() {
  return {{"embree", "Embree " RTC_VERSION_STRING ", medium build quality (default), rtcIntersect1/rtcOccluded1"},
          {"embree:high", "Embree, high build quality (spatial splits)"},
          {"embree:low", "Embree, low build quality (fast build)"},
          {"embree:robust", "Embree with RTC_SCENE_FLAG_ROBUST (options combine: embree:high:robust)", "robust"},
          {"embree:disc", "Embree with spheres as ray-facing discs (RTC_GEOMETRY_TYPE_DISC_POINT): hit at the centre's depth, not the surface; for comparison"}};
}

}  // namespace

RAYBENCH_BACKEND_FAMILY("embree", 100, make_embree_backend, embree_backend_names);

std::string embree_version() {
  return RTC_VERSION_STRING;
}

}  // namespace raybench
