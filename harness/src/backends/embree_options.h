// The `embree:` options and the Embree device configuration they make, apart
// from Embree itself (embree_backend.cpp is the only file that includes it),
// so that names, conflicts and config strings are testable alone.
//
// The default is the configuration Embree's documentation recommends for
// ray-tracing throughput, set explicitly so that it does not vary with the
// CPU model Embree recognises: frequency_level=simd256 (rtcNewDevice.md: "If
// you application heavily uses AVX code, you should best set the frequency
// level to simd256"; Embree 3.12.1 chose simd128 on Skylake-class CPUs, which
// builds a BVH4 instead of a BVH8), medium build quality, RTC_SCENE_FLAG_NONE,
// a static scene, and Embree's own choice of ISA (the best the CPU has).
// docs/backends.md, "Embree's configuration", cites the passages.
// The ray mode (issue 32) is how the rays of a chunk reach Embree: one at a
// time (rtcIntersect1, the default), in packets of 4, 8 or 16 consecutive rays
// (rtcIntersect4/8/16), or as one stream (rtcIntersect1M); packets and streams
// carry RTC_INTERSECT_CONTEXT_FLAG_COHERENT unless `incoherent` is given.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace raybench {

enum class EmbreeQuality { kLow, kMedium, kHigh };

// How a chunk's rays reach Embree: `embree`, `embree:packet4|8|16`, `embree:stream`.
enum class EmbreeRayMode { kSingle, kPacket4, kPacket8, kPacket16, kStream };

struct EmbreeOptions {
  EmbreeQuality quality = EmbreeQuality::kMedium;
  bool robust = false;  // RTC_SCENE_FLAG_ROBUST
  bool disc = false;    // spheres as RTC_GEOMETRY_TYPE_DISC_POINT
  // Embree's frequency_level: simd128, simd256 or simd512 (in Embree 3.13
  // only simd128 differs: it forbids the 8-wide BVH).
  std::string frequency_level = "simd256";
  // Embree's isa= (sse2, sse4.2, avx, avx2, avx512); empty: Embree's choice.
  std::string isa;
  // `embree:hugepages` / `embree:no_hugepages`: this backend's memory policy
  // instead of the run's (BackendConfig::huge_pages).
  std::optional<bool> huge_pages;
  EmbreeRayMode ray_mode = EmbreeRayMode::kSingle;
  // `embree:...:incoherent`: RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT instead
  // of COHERENT for packets and streams (an error for single rays, whose
  // traversal does not read the flag).
  bool incoherent = false;
};

// The rays per packet of a packet mode (4, 8, 16); 0 for single rays and streams.
int embree_packet_width(EmbreeRayMode mode);

// What Embree says it runs natively on a device (rtcGetDeviceProperty:
// RTC_DEVICE_PROPERTY_NATIVE_RAY4/8/16_SUPPORTED, RAY_STREAM_SUPPORTED).
struct EmbreeNativeRays {
  bool packet4 = false, packet8 = false, packet16 = false, stream = false;
};

// The ray mode as the run's metadata records it (provenance.<backend>.ray_mode):
// the mode, the calls, the context flag and whether Embree runs it natively,
// e.g. "packet16 (rtcIntersect16/rtcOccluded16, coherent flag): native" or
// "packet16 (...): emulated by Embree (no native 16-wide packets on this
// device; native widths: 4, 8), its stream filter splits each packet".
std::string embree_ray_mode(const EmbreeOptions& options, const EmbreeNativeRays& native);

// The short form for the progress line: "packet16 native", "stream coherent",
// "packet16 emulated"; "" for single rays.
std::string embree_ray_mode_summary(const EmbreeOptions& options, const EmbreeNativeRays& native);

// The ISA names Embree 3.13's device config accepts (state.cpp,
// string_to_cpufeatures, less its aliases), in ascending order.
const std::vector<std::string>& embree_isa_names();

// Parses the options after "embree" of `name` (e.g. {"high", "avx2"} of
// "embree:high:avx2"). Throws InputError, one line naming `name`, for an
// unknown option, one given twice, or two of one kind (two build qualities,
// two frequency levels, two ISAs, hugepages with no_hugepages, two ray modes),
// or `incoherent` without a packet or stream mode.
EmbreeOptions parse_embree_options(const std::string& name, const std::vector<std::string>& options);

// Whether the backend's structures get huge pages: its own option, else the run's policy.
bool embree_huge_pages(const EmbreeOptions& options, bool run_huge_pages);

// The device config string: "verbose=0", the memory policy's fragment
// (embree_memory_config), the frequency level, and the ISA when one is named;
// comma separated, e.g. "verbose=0,frequency_level=simd256,isa=avx2".
std::string embree_device_config(const EmbreeOptions& options, bool run_huge_pages);

// The one-line error for a device Embree refused to create with `config`:
// when `unsupported_cpu` (RTC_ERROR_UNSUPPORTED_CPU) and an ISA was named, it
// says this CPU lacks that ISA and which ones to try.
std::string embree_device_error(const std::string& name, const EmbreeOptions& options, const std::string& config,
                                bool unsupported_cpu);

}  // namespace raybench
