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
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace raybench {

enum class EmbreeQuality { kLow, kMedium, kHigh };

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
};

// The ISA names Embree 3.13's device config accepts (state.cpp,
// string_to_cpufeatures, less its aliases), in ascending order.
const std::vector<std::string>& embree_isa_names();

// Parses the options after "embree" of `name` (e.g. {"high", "avx2"} of
// "embree:high:avx2"). Throws InputError, one line naming `name`, for an
// unknown option, one given twice, or two of one kind (two build qualities,
// two frequency levels, two ISAs, hugepages with no_hugepages).
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
