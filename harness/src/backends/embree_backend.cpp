// The only file that includes Embree. Embree 3 (Debian libembree-dev),
// single-ray API: rtcIntersect1 for closest hit, rtcOccluded1 for any hit.
#include <algorithm>
#include <atomic>
#include <limits>
#include <sys/types.h>
#include <cstring>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "backends/backend_families.h"
#include "io/error.h"

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
};

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

  void build(const Scene& scene) override {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, options_.quality);
    rtcSetSceneFlags(scene_, options_.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geometry, options_.quality);
    const std::size_t n = scene.triangles.size();
    // Embree allocates these buffers itself, padded for its 16-byte loads.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
    auto* indices = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), n));
    if (!vertices || !indices) throw std::runtime_error("embree: buffer allocation failed: " + last_error_);
    std::memcpy(vertices, scene.triangles.data(), n * sizeof(Triangle));
    for (std::size_t i = 0; i < 3 * n; ++i) indices[i] = static_cast<std::uint32_t>(i);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene_, geometry, 0);
    rtcReleaseGeometry(geometry);
    // Only what the build itself allocates counts as the structure's memory,
    // not the vertex and index buffers every backend shares an equivalent of.
    const std::int64_t before = allocated_.load();
    rtcCommitScene(scene_);
    memory_ = static_cast<std::size_t>(std::max<std::int64_t>(0, allocated_.load() - before));
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("embree: build failed: " + last_error_);
  }

  std::size_t memory_bytes() const override { return memory_; }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
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
      if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
        hits[i] = {rh.ray.tfar, static_cast<std::int32_t>(rh.hit.primID), rh.hit.u, rh.hit.v};
    }
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
};

}  // namespace

std::unique_ptr<Backend> make_embree_backend(const std::string& name, const std::vector<std::string>& options,
                                             const BackendConfig&) {
  EmbreeOptions parsed;
  for (const std::string& o : options) {
    if (o == "low") parsed.quality = RTC_BUILD_QUALITY_LOW;
    else if (o == "medium") parsed.quality = RTC_BUILD_QUALITY_MEDIUM;
    else if (o == "high") parsed.quality = RTC_BUILD_QUALITY_HIGH;
    else if (o == "robust") parsed.robust = true;
    else throw InputError("", fmt::format("backend '{}': unknown embree option '{}' (known: low, medium, high, robust)", name, o));
  }
  return std::make_unique<EmbreeBackend>(name, parsed);
}

std::vector<BackendInfo> embree_backend_names() {
  return {{"embree", "Embree " RTC_VERSION_STRING ", medium build quality (default), rtcIntersect1/rtcOccluded1"},
          {"embree:high", "Embree, high build quality (spatial splits)"},
          {"embree:low", "Embree, low build quality (fast build)"},
          {"embree:robust", "Embree with RTC_SCENE_FLAG_ROBUST (options combine: embree:high:robust)", "robust"}};
}

std::string embree_version() {
  return RTC_VERSION_STRING;
}

}  // namespace raybench
