// What Embree selected for a device config: the ISA of its single-ray kernel,
// the acceleration structure it built for triangles (BVH8 or BVH4, and its
// leaf, e.g. Triangle4), the intersector names, as its verbose output says
// them. Embree 3 has no property for any of this: with verbose=2 its device
// prints its state (kernels/common/device.cpp, Device::print; state.cpp,
// State::print) and rtcCommitScene prints "building BVH8<triangle4> using
// avx::BVH8BuilderSAH" and "selected scene intersector" with the names
// (kernels/common/scene.cpp). embree_backend.cpp captures that text once per
// backend, outside every timing (the probe); this file only reads it.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace raybench {

inline constexpr const char* kEmbreeUnknown = "unknown";

struct EmbreeSelection {
  std::string isa = kEmbreeUnknown;           // the single-ray kernel's ISA namespace: "avx512"
  std::string accel = kEmbreeUnknown;         // "BVH8" or "BVH4"
  std::string leaf = kEmbreeUnknown;          // "Triangle4"
  std::string builder = kEmbreeUnknown;       // "avx::BVH8BuilderSAH"
  std::string intersector1 = kEmbreeUnknown;  // "BVH8Triangle4Intersector1Moeller" (intersect and occluded)
  std::string frequency_level = kEmbreeUnknown;  // as Embree reports it: simd128, simd256, simd512
  std::string hugepages = kEmbreeUnknown;     // as Embree reports it: enabled, disabled, failed
  std::string cpu = kEmbreeUnknown;           // Embree's name for the CPU: "Unknown CPU (GenuineIntel)"
  // The banner's "Build": "Release" unless Embree was compiled with DEBUG;
  // it says nothing about assertions (NDEBUG): see embree_assertions.
  std::string banner_build = kEmbreeUnknown;

  // True when the ISA and the acceleration structure were both found.
  bool complete() const { return isa != kEmbreeUnknown && accel != kEmbreeUnknown; }
};

// Reads Embree 3.13's verbose=2 output of creating a device and committing a
// triangle scene. Fields it cannot find stay "unknown"; it never throws.
EmbreeSelection parse_embree_verbose(std::string_view text);

// Whether a shared library was built with assertions, from its bytes: a
// library compiled without NDEBUG calls glibc's __assert_fail, whose name is
// then in its dynamic symbol table. "enabled", "disabled", or "unknown" when
// `library_bytes` is empty (the file could not be read).
std::string assertions_from_library_bytes(std::string_view library_bytes);

// The key/value pairs of a run's metadata for one Embree backend
// (provenance.<backend>.<key>) and its one progress line, e.g. "ISA avx512,
// BVH8 Triangle4, intersector BVH8Triangle4Intersector1Moeller,
// frequency_level simd256, huge pages on".
std::vector<std::pair<std::string, std::string>> embree_provenance(const EmbreeSelection& selection,
                                                                   const std::string& device_config, bool huge_pages,
                                                                   const std::string& library,
                                                                   const std::string& assertions);
std::string embree_summary(const EmbreeSelection& selection, bool huge_pages);

}  // namespace raybench
