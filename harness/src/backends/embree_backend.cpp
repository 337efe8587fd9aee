// The only file that includes Embree. Embree 3 (Debian libembree-dev):
// rtcIntersect1 for closest hit, rtcOccluded1 for any hit; with a ray mode
// (embree_options.h, issue 32) the packet calls rtcIntersect4/8/16 over
// consecutive rays of a chunk, or rtcIntersect1M over the chunk as a stream.
// A packet lane Embree must not trace (a tail lane, a screened ray with an
// empty interval) gets valid = 0 and also holds an empty interval, because
// an emulated width ignores the mask (rtcore.cpp hands it to the stream
// filter, which skips rays with tnear > tfar).
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
// Options, the default device config and the record of what Embree selected:
// embree_options.h, embree_selection.h; docs/backends.md, "Embree's configuration".
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sys/types.h>
#include <cstddef>
#include <cstdio>
#include <cerrno>
#include <cstring>
#include <exception>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include <dlfcn.h>
#include <unistd.h>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "backends/backend.h"
#include "backends/embree_backend.h"
#include "backends/embree_options.h"
#include "io/command_output.h"
#include "backends/embree_selection.h"
#include "io/error.h"
#include "raybench/math/prefetch.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/analytic_hit.h"
#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/primitives.h"
#include "raybench/simd/lanes.h"
#include "rays/screening.h"

namespace raybench {
namespace {

RTCBuildQuality rtc_quality(EmbreeQuality q) {
  return q == EmbreeQuality::kLow ? RTC_BUILD_QUALITY_LOW : q == EmbreeQuality::kHigh ? RTC_BUILD_QUALITY_HIGH
                                                                                       : RTC_BUILD_QUALITY_MEDIUM;
}

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

// The ray as Embree holds it (tnear >= 0 already: screening raised it), its
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

// ---------------------------------------------------------------------------
// The probe: what Embree selects for a backend's device config, read from its
// verbose output (embree_selection.h), once per backend and outside every timing.

struct CloseFile {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

// dup2(from, to), retried while it is interrupted (EINTR) or races another
// thread's open (EBUSY), its only failures for two open descriptors.
bool redirect_descriptor(int from, int to) {
  for (int attempt = 0; attempt < 1000; ++attempt) {
    if (::dup2(from, to) >= 0) return true;
    if (errno != EINTR && errno != EBUSY) return false;
  }
  return false;
}

// Runs `work` with stdout (fd 1) going to a temporary file and returns what
// was written there. C and C++ streams are flushed before and after, and fd 1
// is restored whether `work` returns or throws (its exception is rethrown).
// Returns "" without running `work` when stdout cannot be redirected (the
// probe's fields are then "unknown"), so nothing verbose reaches the user's
// stdout; throws std::runtime_error if fd 1 cannot be restored, rather than
// run on with the user's stdout going to a deleted file.
std::string capture_stdout(const std::function<void()>& work) {
  std::cout.flush();
  std::fflush(stdout);
  const std::unique_ptr<std::FILE, CloseFile> file(std::tmpfile());
  if (!file) return {};
  const int saved = ::dup(STDOUT_FILENO);
  if (saved < 0) return {};
  if (!redirect_descriptor(::fileno(file.get()), STDOUT_FILENO)) {
    ::close(saved);
    return {};
  }
  std::exception_ptr failure;
  try {
    work();
  } catch (...) {
    failure = std::current_exception();
  }
  std::cout.flush();
  std::fflush(stdout);
  const bool restored = redirect_descriptor(saved, STDOUT_FILENO);
  const int restore_error = errno;
  ::close(saved);
  if (!restored)
    throw std::runtime_error(fmt::format("cannot restore stdout after probing Embree's selection: {}",
                                         std::strerror(restore_error)));
  if (failure) std::rethrow_exception(failure);
  std::string text;
  if (::lseek(::fileno(file.get()), 0, SEEK_SET) == 0) {
    char buffer[4096];
    for (ssize_t n; (n = ::read(::fileno(file.get()), buffer, sizeof buffer)) > 0;)
      text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

// Embree's verbose output of a device made with `device_config` (verbose=2
// appended: the last value of a key wins) committing one triangle with the
// backend's build quality and scene flags.
EmbreeSelection probe_selection(const std::string& device_config, const EmbreeOptions& options) {
  const std::string text = capture_stdout([&] {
    RTCDevice device = rtcNewDevice((device_config + ",verbose=2").c_str());
    if (!device) return;
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, rtc_quality(options.quality));
    rtcSetSceneFlags(scene, options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3));
    auto* indices = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), 1));
    if (vertices && indices) {
      const float triangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
      std::memcpy(vertices, triangle, sizeof triangle);
      indices[0] = 0, indices[1] = 1, indices[2] = 2;
      rtcSetGeometryBuildQuality(geometry, rtc_quality(options.quality));
      rtcCommitGeometry(geometry);
      rtcAttachGeometry(scene, geometry);
      rtcCommitScene(scene);
    }
    rtcReleaseGeometry(geometry);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  });
  return parse_embree_verbose(text);
}

// The Embree library this process runs (its file, and the Debian package and
// version that installed it when dpkg knows it) and whether it was built with
// assertions (embree_selection.h). The same for every backend: computed once.
struct EmbreeLibrary {
  std::string description = kEmbreeUnknown;
  std::string assertions = kEmbreeUnknown;
};

const EmbreeLibrary& embree_library() {
  static const EmbreeLibrary library = [] {
    EmbreeLibrary out;
    Dl_info info{};
    if (!::dladdr(reinterpret_cast<void*>(&rtcNewDevice), &info) || !info.dli_fname) return out;
    char resolved[4096];
    const std::string path = ::realpath(info.dli_fname, resolved) ? resolved : info.dli_fname;
    out.description = path;
    if (path.find('\'') == std::string::npos) {
      // "libembree3-3:amd64: /usr/lib/x86_64-linux-gnu/libembree3.so.3.13.5"
      const std::string owner = command_first_line("dpkg-query --search '" + path + "' 2>/dev/null");
      const std::size_t colon = owner.find(": ");
      if (colon != std::string::npos) {
        const std::string package = owner.substr(0, colon);
        const std::string version = command_first_line("dpkg-query -W -f='${Version}' '" + package + "' 2>/dev/null");
        out.description += fmt::format(" (Debian package {} {})", package, version.empty() ? kEmbreeUnknown : version);
      }
    }
    std::ifstream file(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    out.assertions = assertions_from_library_bytes(bytes);
    return out;
  }();
  return library;
}

// Rays go to Embree as they are: a Ray's first seven floats (org, tnear, dir)
// are RTCRay's, and its eighth (tfar) sits where RTCRay has time, so load()
// stores dir+time as one 16-byte vector with time = 0, per ray; mask, id and
// flags are set once per batch (batch_ray).
static_assert(offsetof(Ray, tnear) == offsetof(RTCRay, tnear) && offsetof(Ray, dir) == offsetof(RTCRay, dir_x));
static_assert(offsetof(Ray, tfar) == 7 * sizeof(float));
static_assert(offsetof(RTCRay, org_x) == 0 && offsetof(RTCRay, time) == 7 * sizeof(float) &&
              sizeof(Vec3f) == 3 * sizeof(float));

// An RTCRay with the fields Embree never writes set: every mask bit, id and
// flags 0. Its org, tnear, dir, time (0) and tfar are written per ray by load().
RTCRay batch_ray() {
  RTCRay r;
  r.time = 0.0f;
  r.mask = 0xffffffffu;
  r.id = 0;
  r.flags = 0;
  return r;
}

// A screened ray (backend.h) into Embree's, in three stores: Embree reads
// org+tnear and dir+time as 16-byte vectors, which a store of the same 16
// bytes forwards to at once, while narrower stores make the load wait for
// them to reach the cache (a store-forwarding stall per vector).
// Measured: docs/notes/embree-wrapper.md.
inline void load(RTCRay& out, const Ray& in) {
  using Float4 = float __attribute__((vector_size(16)));  // GCC's generic vector: no intrinsics needed
  Float4 org_tnear, dir_time;
  std::memcpy(&org_tnear, &in.org, sizeof(Float4));
  std::memcpy(&dir_time, &in.dir, sizeof(Float4));  // dir, tfar
  dir_time[3] = 0.0f;                                // time
  std::memcpy(&out.org_x, &org_tnear, sizeof(Float4));
  std::memcpy(&out.dir_x, &dir_time, sizeof(Float4));
  out.tfar = in.tfar;
}

// Embree's packet types and calls of one width.
template <int K>
struct Packet;

template <>
struct Packet<4> {
  using RayHitK = RTCRayHit4;
  using RayK = RTCRay4;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHitK* r) { rtcIntersect4(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, RayK* r) { rtcOccluded4(valid, s, c, r); }
};

template <>
struct Packet<8> {
  using RayHitK = RTCRayHit8;
  using RayK = RTCRay8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHitK* r) { rtcIntersect8(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, RayK* r) { rtcOccluded8(valid, s, c, r); }
};

template <>
struct Packet<16> {
  using RayHitK = RTCRayHit16;
  using RayK = RTCRay16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHitK* r) {
    rtcIntersect16(valid, s, c, r);
  }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, RayK* r) { rtcOccluded16(valid, s, c, r); }
};

// The fields of a packet Embree never writes, for every lane: every mask
// bit, id, flags, time 0 (load_packet writes the rays, every lane, before
// each call).
template <int K, typename RayK>
void init_packet(RayK& packet) {
  for (int i = 0; i < K; ++i) {
    packet.time[i] = 0.0f;
    packet.mask[i] = 0xffffffffu;
    packet.id[i] = 0;
    packet.flags[i] = 0;
  }
}

// `rays` (at most K, screened) into the packet's lanes and the valid mask:
// -1 where the interval is not empty (tnear <= tfar, what rtcIntersect1M
// traces too), else 0; lanes past the rays get kEmptyRay and 0.
// A full packet of 8 or 16 rays goes in 8 at a time, transposed in
// registers and stored a field at a time (as our packets load theirs,
// wide_bvh_packet.h): written lane by lane, each field was read by Embree's
// first 32- or 64-byte load of it while its 8 or 16 stores were still on
// their way to the cache (a failed store-to-load forward; measured:
// docs/notes/embree-packets.md).
template <int K, typename RayK>
inline void load_packet(RayK& packet, int* valid, std::span<const Ray> rays) {
#if defined(__AVX2__)
  if constexpr (K % 8 == 0) {
    if (rays.size() == static_cast<std::size_t>(K)) {
      static_assert(sizeof(Ray) == 8 * sizeof(float));
      float* const to[8] = {packet.org_x, packet.org_y, packet.org_z, packet.tnear,
                            packet.dir_x, packet.dir_y, packet.dir_z, packet.tfar};  // a Ray's fields in order
      for (int first = 0; first < K; first += 8) {
        simd::FloatLanes<8> fields[8];  // ox oy oz tnear dx dy dz tfar, lane i: ray first + i
        simd::FloatLanes<8>::load_transposed8(reinterpret_cast<const float*>(&rays[first]), fields);
        for (int k = 0; k < 8; ++k) fields[k].storeu(to[k] + first);
        // -1 where tnear <= tfar (false for NaN, as the scalar test below).
        _mm256_storeu_ps(reinterpret_cast<float*>(valid + first), _mm256_cmp_ps(fields[3].v, fields[7].v, _CMP_LE_OQ));
      }
      return;
    }
  }
#endif
  for (std::size_t i = 0; i < static_cast<std::size_t>(K); ++i) {
    const Ray& r = i < rays.size() ? rays[i] : kEmptyRay;
    packet.org_x[i] = r.org.x, packet.org_y[i] = r.org.y, packet.org_z[i] = r.org.z;
    packet.dir_x[i] = r.dir.x, packet.dir_y[i] = r.dir.y, packet.dir_z[i] = r.dir.z;
    packet.tnear[i] = r.tnear, packet.tfar[i] = r.tfar;
    valid[i] = r.tnear <= r.tfar ? -1 : 0;
  }
}

// Rays per rtcIntersect1M call: a whole chunk of the trace executor (1024)
// in one stream; a larger span, as a test may pass, in pieces of this size.
constexpr std::size_t kStreamPiece = 4096;

class EmbreeBackend final : public Backend {
 public:
  EmbreeBackend(std::string name, EmbreeOptions options, const BackendConfig& config)
      : name_(std::move(name)),
        options_(std::move(options)),
        device_config_(embree_device_config(options_, config.huge_pages)),
        huge_pages_(embree_huge_pages(options_, config.huge_pages)) {
    // No "threads=N": Embree would enforce it with a process-wide
    // tbb::global_control, replaced by each newer device, so while a
    // 1-thread Embree backend was the newest every other backend's 2-thread
    // build ran on one thread (ours measured 1.0x instead of 1.8x). Embree's
    // build runs in the caller's TBB arena instead, which the harness sizes
    // to BackendConfig::threads for every backend alike (TraceExecutor::run).
    device_ = rtcNewDevice(device_config_.c_str());
    // An ISA the CPU lacks: Embree refuses the device (RTC_ERROR_UNSUPPORTED_CPU).
    if (!device_)
      throw InputError("", embree_device_error(name_, options_, device_config_,
                                               rtcGetDeviceError(nullptr) == RTC_ERROR_UNSUPPORTED_CPU));
    native_.packet4 = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED) != 0;
    native_.packet8 = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
    native_.packet16 = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
    native_.stream = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED) != 0;
    if (options_.ray_mode == EmbreeRayMode::kStream && !native_.stream) {
      rtcReleaseDevice(device_);
      throw InputError("", fmt::format("backend '{}': this Embree has no ray streams (built without ray packets: "
                                       "RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED is 0)",
                                       name_));
    }
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

  // What Embree selected for this backend's config (the probe: a second
  // device, one triangle, committed once) and the library it runs; computed
  // on the first call, never in a timed loop. Fields the probe cannot read
  // are "unknown"; it throws only if stdout cannot be restored (capture_stdout).
  std::vector<std::pair<std::string, std::string>> provenance() const override {
    if (!selection_) selection_ = probe_selection(device_config_, options_);
    const EmbreeLibrary& library = embree_library();
    auto p = embree_provenance(*selection_, device_config_, huge_pages_, library.description, library.assertions);
    p.emplace_back("ray_mode", embree_ray_mode(options_, native_));
    const std::string mode = embree_ray_mode_summary(options_, native_);
    p.emplace_back("summary", embree_summary(*selection_, huge_pages_) + (mode.empty() ? "" : ", " + mode));
    return p;
  }

  Capabilities capabilities() const override {
    Capabilities c;
    c.spheres = c.boxes = c.oriented_boxes = true;
    return c;
  }

  void build(const Scene& scene) override {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, rtc_quality(options_.quality));
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
    if (analytic_) intersect_in_mode<true>(rays, hits);
    else intersect_in_mode<false>(rays, hits);
  }

  // Rays are screened (backend.h): finite, tnear >= 0, tfar not NaN, the
  // interval possibly empty (tfar < tnear, -inf included; kEmptyRay). Embree
  // accepts them as they are (its asserted checks: every |coordinate| <=
  // FLT_LARGE, |tnear|, |tfar| <= inf, tnear >= 0) and finds nothing in an
  // empty interval, leaving tfar as it came.
  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    switch (coherent_guarded_mode(rays)) {
      case EmbreeRayMode::kPacket4: return occluded_packets<4>(rays, occluded);
      case EmbreeRayMode::kPacket8: return occluded_packets<8>(rays, occluded);
      case EmbreeRayMode::kPacket16: return occluded_packets<16>(rays, occluded);
      case EmbreeRayMode::kStream: return occluded_stream(rays, occluded);
      case EmbreeRayMode::kSingle: break;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = batch_ray();
    for (std::size_t i = 0; i < rays.size(); ++i) {
      load(ray, rays[i]);
      rtcOccluded1(scene_, &context, &ray);
      // Embree's "occluded" lowers tfar to -inf; a ray that came with -inf
      // (an empty interval) cannot be lowered, so it reads as not occluded.
      occluded[i] = ray.tfar < rays[i].tfar;
    }
  }

 private:
  // The ray mode for this chunk. Debian's Embree, built with assertions,
  // aborts in its coherent packet traversal (bvh_intersector_hybrid.cpp,
  // occludedCoherent: `child != BVH::emptyNode`) when one packet holds
  // directions of very different lengths (1e-20 beside 1e-7: the
  // direction-scaling set, G16). A chunk with a direction length outside
  // [2^-10, 2^10] is traced ray by ray, as `embree` (the same answers);
  // the check is a few operations per ray, with no branch per ray. Renderers'
  // rays (unit directions) never take that path.
  EmbreeRayMode coherent_guarded_mode(std::span<const Ray> rays) const {
    if (options_.ray_mode == EmbreeRayMode::kSingle || options_.incoherent) return options_.ray_mode;
    float shortest = std::numeric_limits<float>::infinity(), longest = 0.0f;
    for (const Ray& r : rays) {
      const float length2 = r.dir.x * r.dir.x + r.dir.y * r.dir.y + r.dir.z * r.dir.z;
      shortest = std::min(shortest, length2);
      longest = std::max(longest, length2);
    }
    return shortest >= 0x1p-20f && longest <= 0x1p20f ? options_.ray_mode : EmbreeRayMode::kSingle;
  }

  template <bool Analytic>
  void intersect_in_mode(std::span<const Ray> rays, std::span<Hit> hits) const {
    switch (coherent_guarded_mode(rays)) {
      case EmbreeRayMode::kPacket4: return intersect_packets<4, Analytic>(rays, hits);
      case EmbreeRayMode::kPacket8: return intersect_packets<8, Analytic>(rays, hits);
      case EmbreeRayMode::kPacket16: return intersect_packets<16, Analytic>(rays, hits);
      case EmbreeRayMode::kStream: return intersect_stream<Analytic>(rays, hits);
      case EmbreeRayMode::kSingle: return intersect_rays<Analytic>(rays, hits);
    }
  }

  // The context of packets and streams: coherent unless `incoherent`.
  RTCIntersectContext coherence_context() const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = options_.incoherent ? RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT : RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return context;
  }

  // An answer of Embree's into ours, for every ray mode: a miss, or the
  // global prim id (first_id_ of its geometry plus primID, with u = v = 0
  // for an analytic hit: prim/analytic_hit.h).
  template <bool Analytic>
  Hit hit_of(unsigned geom_id, unsigned prim_id, float t, float u, float v) const {
    if (geom_id == RTC_INVALID_GEOMETRY_ID) return Hit{};
    if constexpr (Analytic) {
      const bool triangle = geom_id == kTriangleGeometry;
      return {t, static_cast<std::int32_t>(first_id_[geom_id] + prim_id), triangle ? u : 0.0f, triangle ? v : 0.0f};
    } else {
      return {t, static_cast<std::int32_t>(prim_id), u, v};
    }
  }

  template <int K, bool Analytic>
  void intersect_packets(std::span<const Ray> rays, std::span<Hit> hits) const {
    RTCIntersectContext context = coherence_context();
    typename Packet<K>::RayHitK packet;  // aligned by its type (RTC_ALIGN)
    alignas(4 * K) int valid[K];
    init_packet<K>(packet.ray);
    for (int i = 0; i < K; ++i) packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;  // as intersect_rays
    for (std::size_t first = 0; first < rays.size(); first += K) {
      const std::size_t lanes = std::min<std::size_t>(K, rays.size() - first);
      load_packet<K>(packet.ray, valid, rays.subspan(first, lanes));
      prefetch_rays(rays, first + K, K);  // the next packet's, as our packets do (wide_bvh_packet.h)
      for (int i = 0; i < K; ++i) packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      Packet<K>::intersect(valid, scene_, &context, &packet);
      for (std::size_t i = 0; i < lanes; ++i)
        hits[first + i] = hit_of<Analytic>(packet.hit.geomID[i], packet.hit.primID[i], packet.ray.tfar[i],
                                           packet.hit.u[i], packet.hit.v[i]);
    }
  }

  template <int K>
  void occluded_packets(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
    RTCIntersectContext context = coherence_context();
    typename Packet<K>::RayK packet;
    alignas(4 * K) int valid[K];
    init_packet<K>(packet);
    for (std::size_t first = 0; first < rays.size(); first += K) {
      const std::size_t lanes = std::min<std::size_t>(K, rays.size() - first);
      load_packet<K>(packet, valid, rays.subspan(first, lanes));
      prefetch_rays(rays, first + K, K);
      Packet<K>::occluded(valid, scene_, &context, &packet);
      // As occluded(): "occluded" lowers tfar to -inf; a lane Embree did not trace keeps its tfar.
      for (std::size_t i = 0; i < lanes; ++i) occluded[first + i] = packet.tfar[i] < rays[first + i].tfar;
    }
  }

  // The stream's structures, one buffer per thread, grown (rarely: to the
  // chunk size) outside the per-ray work; the fields Embree never writes
  // (batch_ray's, instID) are set when an element is made.
  template <typename T>
  static std::vector<T>& stream_buffer(std::size_t n, const T& fresh) {
    thread_local std::vector<T> buffer;
    if (buffer.size() < n) buffer.resize(n, fresh);
    return buffer;
  }

  // rtcIntersect1M traces a ray with tnear > tfar as rtcIntersect1 does (a
  // screened ray: finite, found nothing), so the stream gets every ray as is.
  template <bool Analytic>
  void intersect_stream(std::span<const Ray> rays, std::span<Hit> hits) const {
    RTCIntersectContext context = coherence_context();
    RTCRayHit fresh;
    fresh.ray = batch_ray();
    fresh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    for (std::size_t first = 0; first < rays.size(); first += kStreamPiece) {
      const std::size_t n = std::min(kStreamPiece, rays.size() - first);
      std::vector<RTCRayHit>& stream = stream_buffer(n, fresh);
      for (std::size_t i = 0; i < n; ++i) {
        load(stream[i].ray, rays[first + i]);
        stream[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect1M(scene_, &context, stream.data(), static_cast<unsigned>(n), sizeof(RTCRayHit));
      for (std::size_t i = 0; i < n; ++i) {
        const RTCRayHit& rh = stream[i];
        hits[first + i] = hit_of<Analytic>(rh.hit.geomID, rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v);
      }
    }
  }

  void occluded_stream(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
    RTCIntersectContext context = coherence_context();
    for (std::size_t first = 0; first < rays.size(); first += kStreamPiece) {
      const std::size_t n = std::min(kStreamPiece, rays.size() - first);
      std::vector<RTCRay>& stream = stream_buffer(n, batch_ray());
      for (std::size_t i = 0; i < n; ++i) load(stream[i], rays[first + i]);
      rtcOccluded1M(scene_, &context, stream.data(), static_cast<unsigned>(n), sizeof(RTCRay));
      for (std::size_t i = 0; i < n; ++i) occluded[first + i] = stream[i].tfar < rays[first + i].tfar;
    }
  }

  template <bool Analytic>
  void intersect_rays(std::span<const Ray> rays, std::span<Hit> hits) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray = batch_ray();
    // Set once: a hit writes the context's instID[0], which is invalid
    // without instances (the user callbacks copy it too).
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      load(rh.ray, rays[i]);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      hits[i] = hit_of<Analytic>(rh.hit.geomID, rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v);  // written once
    }
  }

  // Commits `geometry` and attaches it to the scene under `id`.
  void attach(RTCGeometry geometry, GeometryId id) {
    rtcSetGeometryBuildQuality(geometry, rtc_quality(options_.quality));
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

  std::string name_;
  EmbreeOptions options_;
  std::string device_config_;  // embree_device_config
  bool huge_pages_;            // the memory policy it was given (its option, else the run's)
  EmbreeNativeRays native_;    // what the device runs natively (rtcGetDeviceProperty)
  mutable std::optional<EmbreeSelection> selection_;  // the probe's, once provenance() asks
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
                                             const BackendConfig& config) {
  return std::make_unique<EmbreeBackend>(name, parse_embree_options(name, options), config);
}

std::vector<BackendInfo> embree_backend_names() {
  return {{"embree", "Embree " RTC_VERSION_STRING ", medium build quality, frequency_level=simd256, Embree's best ISA "
                     "(the default: docs/backends.md), rtcIntersect1/rtcOccluded1"},
          {"embree:high", "Embree, high build quality (spatial splits)"},
          {"embree:low", "Embree, low build quality (fast build)"},
          {"embree:robust", "Embree with RTC_SCENE_FLAG_ROBUST (options combine: embree:high:robust)", "robust"},
          {"embree:disc", "Embree with spheres as ray-facing discs (RTC_GEOMETRY_TYPE_DISC_POINT): hit at the centre's depth, not the surface; for comparison"},
          {"embree:simd128", "Embree at frequency_level=simd128, its own default on Skylake-class CPUs: a BVH4 "
                             "instead of a BVH8 (simd256 is the default; simd512 builds as simd256 in Embree 3.13)"},
          {"embree:hugepages", "Embree with its structures in huge pages whatever the run's memory policy"},
          {"embree:no_hugepages", "Embree with its structures in ordinary pages whatever the run's memory policy"},
          {"embree:packet4", "Embree's 4-ray packets: rtcIntersect4/rtcOccluded4 over consecutive rays, coherent flag "
                             "(combines: embree:packet4:incoherent)"},
          {"embree:packet8", "Embree's 8-ray packets: rtcIntersect8/rtcOccluded8 over consecutive rays, coherent flag"},
          {"embree:packet16", "Embree's 16-ray packets: rtcIntersect16/rtcOccluded16 over consecutive rays, coherent "
                              "flag (emulated by Embree where the device has no 16-wide packets)"},
          {"embree:stream", "Embree's ray stream: rtcIntersect1M/rtcOccluded1M over each chunk of 1024 rays with "
                            "RTC_INTERSECT_CONTEXT_FLAG_COHERENT"},
          {"embree:stream:incoherent", "Embree's ray stream with RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT"},
          {"embree:ISA", "Embree forced to one ISA: embree:sse2, embree:sse4.2, embree:avx, embree:avx2, "
                         "embree:avx512 (an ISA this CPU lacks is an error)", "fast", false, true}};
}

}  // namespace

RAYBENCH_BACKEND_FAMILY("embree", 100, make_embree_backend, embree_backend_names);

std::string embree_version() {
  return RTC_VERSION_STRING;
}

}  // namespace raybench
