// Specification of Embree's configuration and its record (issue 33):
// the `embree:` options and the device config they make
// (backends/embree_options.h), the reading of Embree's verbose output
// (backends/embree_selection.h) on text captured from Embree 3.13.5, the live
// probe behind an Embree backend's provenance, the ISA error, and the tight
// loops' handling of screened rays with an empty interval.
#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "backends/embree_memory.h"
#include "backends/embree_options.h"
#include "backends/embree_selection.h"
#include "io/error.h"
#include "rays/screening.h"
#include "test_util.h"

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

std::string value(const std::vector<std::pair<std::string, std::string>>& pairs, const std::string& key) {
  for (const auto& [k, v] : pairs)
    if (k == key) return v;
  return "(absent)";
}

// ---------------------------------------------------------------------------
// Options and the device config

TEST(EmbreeOptions, TheDefaultIsSimd256MediumAndEmbreesChoiceOfIsa) {
  const EmbreeOptions o = parse_embree_options("embree", {});
  EXPECT_EQ(o.frequency_level, "simd256");
  EXPECT_EQ(o.quality, EmbreeQuality::kMedium);
  EXPECT_EQ(o.isa, "");
  EXPECT_FALSE(o.robust);
  EXPECT_FALSE(o.huge_pages.has_value());
}

TEST(EmbreeOptions, FrequencyIsaAndPagesCombineWithQualityInAnyOrder) {
  const EmbreeOptions o = parse_embree_options("embree:avx2:simd128:high:no_hugepages:robust",
                                               {"avx2", "simd128", "high", "no_hugepages", "robust"});
  EXPECT_EQ(o.isa, "avx2");
  EXPECT_EQ(o.frequency_level, "simd128");
  EXPECT_EQ(o.quality, EmbreeQuality::kHigh);
  EXPECT_EQ(o.huge_pages, false);
  EXPECT_TRUE(o.robust);
  for (const std::string isa : {"sse2", "sse4.2", "avx", "avx2", "avx512"})
    EXPECT_EQ(parse_embree_options("embree:" + isa, {isa}).isa, isa);
  EXPECT_EQ(parse_embree_options("embree:simd512", {"simd512"}).frequency_level, "simd512");
  EXPECT_EQ(parse_embree_options("embree:hugepages", {"hugepages"}).huge_pages, true);
}

TEST(EmbreeOptions, UnknownRepeatedAndConflictingOptionsAreOneLineErrors) {
  const auto error = [](const std::string& name, const std::vector<std::string>& options) {
    return testing::input_error_of([&] { parse_embree_options(name, options); });
  };
  EXPECT_HAS(error("embree:avx3", {"avx3"}), "backend 'embree:avx3': unknown embree option 'avx3' (known: ");
  EXPECT_HAS(error("embree:avx3", {"avx3"}), "sse4.2");
  EXPECT_HAS(error("embree:sse42", {"sse42"}), "unknown embree option 'sse42'");
  EXPECT_HAS(error("embree:high:low", {"high", "low"}),
             "embree options 'high' and 'low' conflict: one build quality per backend");
  EXPECT_HAS(error("embree:simd128:simd256", {"simd128", "simd256"}), "one frequency level per backend");
  EXPECT_HAS(error("embree:avx2:avx512", {"avx2", "avx512"}), "'avx2' and 'avx512' conflict: one ISA per backend");
  EXPECT_HAS(error("embree:hugepages:no_hugepages", {"hugepages", "no_hugepages"}), "one memory policy per backend");
  EXPECT_HAS(error("embree:avx2:avx2", {"avx2", "avx2"}), "embree option 'avx2' given twice");
  EXPECT_HAS(error("embree:robust:robust", {"robust", "robust"}), "embree option 'robust' given twice");
  for (const std::string& e : {error("embree:avx3", {"avx3"}), error("embree:high:low", {"high", "low"})})
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  // Through the registry, as a user names it.
  EXPECT_HAS(testing::input_error_of([] { make_backend("embree:simd1024"); }), "unknown embree option 'simd1024'");
}

TEST(EmbreeOptions, TheDeviceConfigComposesVerboseMemoryFrequencyAndIsa) {
  const std::string on = embree_memory_config(true), off = embree_memory_config(false);
  const auto with_memory = [](const std::string& memory, const std::string& rest) {
    return "verbose=0" + (memory.empty() ? "" : "," + memory) + "," + rest;
  };
  EXPECT_EQ(embree_device_config(parse_embree_options("embree", {}), true), with_memory(on, "frequency_level=simd256"));
  EXPECT_EQ(embree_device_config(parse_embree_options("embree", {}), false), with_memory(off, "frequency_level=simd256"));
  EXPECT_EQ(embree_device_config(parse_embree_options("embree:simd128:avx2", {"simd128", "avx2"}), true),
            with_memory(on, "frequency_level=simd128,isa=avx2"));
  // The backend's own page option overrides the run's policy, either way.
  EXPECT_EQ(embree_device_config(parse_embree_options("embree:no_hugepages", {"no_hugepages"}), true),
            with_memory(off, "frequency_level=simd256"));
  EXPECT_EQ(embree_device_config(parse_embree_options("embree:hugepages", {"hugepages"}), false),
            with_memory(on, "frequency_level=simd256"));
  EXPECT_TRUE(embree_huge_pages(parse_embree_options("embree", {}), true));
  EXPECT_FALSE(embree_huge_pages(parse_embree_options("embree:no_hugepages", {"no_hugepages"}), true));
  EXPECT_TRUE(embree_huge_pages(parse_embree_options("embree:hugepages", {"hugepages"}), false));
}

TEST(EmbreeOptions, AnIsaTheCpuLacksIsNamedInTheError) {
  const EmbreeOptions o = parse_embree_options("embree:avx512", {"avx512"});
  const std::string e = embree_device_error("embree:avx512", o, "verbose=0,isa=avx512", true);
  EXPECT_HAS(e, "backend 'embree:avx512': this CPU lacks the ISA avx512 (Embree refused isa=avx512: "
                "RTC_ERROR_UNSUPPORTED_CPU); name one it has (sse2, sse4.2, avx, avx2, avx512) or none");
  EXPECT_HAS(embree_device_error("embree", parse_embree_options("embree", {}), "verbose=0", false),
             "backend 'embree': Embree cannot create a device (config 'verbose=0')");
}

// Live: every ISA this CPU has makes a backend; one it lacks is an InputError
// naming it (on this Intel AVX-512 machine every ISA is present; on a CPU
// without AVX-512 the second branch runs for embree:avx512).
TEST(EmbreeOptions, EveryIsaMakesABackendOrSaysTheCpuLacksIt) {
  const std::vector<std::pair<std::string, bool>> isas = {
      {"sse2", __builtin_cpu_supports("sse2")},
      {"sse4.2", __builtin_cpu_supports("sse4.2")},
      {"avx", __builtin_cpu_supports("avx")},
      {"avx2", __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2")},
      {"avx512", __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                     __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq")}};
  for (const auto& [isa, has] : isas) {
    SCOPED_TRACE(isa);
    const std::string name = "embree:" + isa;
    if (has) {
      const auto backend = make_backend(name);
      Scene s;
      s.triangles = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
      backend->build(s);
      const Ray r{{0.2f, 0.2f, -1}, 0.0f, {0, 0, 1}, kInf};
      std::vector<Hit> hit(1);
      backend->intersect({&r, 1}, hit);
      EXPECT_EQ(hit[0].prim, 0);
    } else {
      EXPECT_HAS(testing::input_error_of([&] { make_backend(name); }), "this CPU lacks the ISA " + isa);
    }
  }
}

// ---------------------------------------------------------------------------
// Reading Embree's verbose output. The texts are Embree 3.13.5's (Debian
// libembree3-3 3.13.5+dfsg-2) on the issue-33 machine (Intel Xeon, family 6
// model 167, which Embree calls "Unknown CPU"), verbose=2, one triangle
// committed; trimmed to the banner, the state lines read and the commit.

constexpr const char* kAvx512Bvh8 = R"(
Embree Ray Tracing Kernels 3.13.5 ()
  Compiler  : GCC 12.2.0
  Build     : Release 
  Platform  : Linux (64bit)
  CPU       : Unknown CPU (GenuineIntel)
   Threads  : 2
   ISA      : XMM YMM ZMM SSE SSE2 SSE3 SSSE3 SSE4.1 SSE4.2 POPCNT AVX F16C RDRAND AVX2 FMA3 LZCNT BMI1 BMI2 AVX512F AVX512DQ AVX512CD AVX512BW AVX512VL AVX512IFMA AVX512VBMI 
   Targets  : SSE SSE2 SSE3 SSSE3 SSE4.1 SSE4.2 AVX AVXI AVX2 AVX512 
   MXCSR    : FTZ=0, DAZ=0
  Config
    Threads : default
    ISA     : XMM YMM ZMM SSE SSE2 SSE3 SSSE3 SSE4.1 SSE4.2 POPCNT AVX F16C RDRAND AVX2 FMA3 LZCNT BMI1 BMI2 AVX512F AVX512DQ AVX512CD AVX512BW AVX512VL AVX512IFMA AVX512VBMI 
    Targets : SSE SSE2 SSE3 SSSE3 SSE4.1 SSE4.2 AVX AVXI AVX2 AVX512  (supported)
              SSE2 SSE4.2 AVX AVX2 AVX512  (compile time enabled)
    Features: raymasks intersection_filter 
    Tasking : TBB2021.5 TBB_header_interface_12050 TBB_lib_interface_12080 

general:
  build threads      = 0
  build user threads = 0
  start_threads      = 0
  affinity           = 0
  frequency_level    = simd256
  hugepages          = enabled
  verbosity          = 2
triangles:
  accel              = default
  builder            = default
  traverser          = default
              triangles:          1
building BVH8<triangle4> using avx::BVH8BuilderSAH ...
finished BVH8<triangle4> : 0.0669956ms, 0.0149263 Mprim/s, 0.00262704 GB/s
created scene intersector
  accels[0]
    intersector1  = avx512::BVH8Triangle4Intersector1Moeller
    intersector4  = avx512::BVH8Triangle4Intersector4HybridMoellerNoFilter
selected scene intersector
  intersector1  = avx512::BVH8Triangle4Intersector1Moeller
  intersector4  = avx512::BVH8Triangle4Intersector4HybridMoellerNoFilter
  intersector8  = avx512::BVH8Triangle4Intersector8HybridMoellerNoFilter
  intersector16 = avx512::BVH8Triangle4Intersector16HybridMoellerNoFilter
  intersectorN = avx512::BVH8Triangle4IntersectorStreamMoellerNoFilter)";

TEST(EmbreeVerbose, ReadsIsaBvhLeafBuilderAndIntersector) {
  const EmbreeSelection s = parse_embree_verbose(kAvx512Bvh8);
  EXPECT_EQ(s.isa, "avx512");
  EXPECT_EQ(s.accel, "BVH8");
  EXPECT_EQ(s.leaf, "Triangle4");
  EXPECT_EQ(s.builder, "avx::BVH8BuilderSAH");
  EXPECT_EQ(s.intersector1, "BVH8Triangle4Intersector1Moeller");
  EXPECT_EQ(s.frequency_level, "simd256");
  EXPECT_EQ(s.hugepages, "enabled");
  EXPECT_EQ(s.cpu, "Unknown CPU (GenuineIntel)");
  EXPECT_EQ(s.banner_build, "Release");
  EXPECT_TRUE(s.complete());
  EXPECT_EQ(embree_summary(s, true), "ISA avx512, BVH8 Triangle4, intersector BVH8Triangle4Intersector1Moeller, "
                                     "frequency_level simd256, huge pages on");
}

// frequency_level=simd128 (Embree's own default on Skylake-class CPUs) with
// RTC_SCENE_FLAG_ROBUST, and hugepages=0: a BVH4 of Triangle4v leaves.
constexpr const char* kAvx512Bvh4Robust = R"(
  CPU       : Unknown CPU (GenuineIntel)
general:
  frequency_level    = simd128
  hugepages          = disabled
building BVH4<triangle4v> using avx::BVH4BuilderSAH ...
selected scene intersector
  intersector1  = avx512::BVH4Triangle4vIntersector1Pluecker
  intersector4  = avx512::BVH4Triangle4vIntersector4HybridPluecker
)";

TEST(EmbreeVerbose, ReadsABvh4OfRobustLeaves) {
  const EmbreeSelection s = parse_embree_verbose(kAvx512Bvh4Robust);
  EXPECT_EQ(s.isa, "avx512");
  EXPECT_EQ(s.accel, "BVH4");
  EXPECT_EQ(s.leaf, "Triangle4v");
  EXPECT_EQ(s.intersector1, "BVH4Triangle4vIntersector1Pluecker");
  EXPECT_EQ(s.frequency_level, "simd128");
  EXPECT_EQ(s.hugepages, "disabled");
  EXPECT_EQ(s.banner_build, kEmbreeUnknown);
}

// isa=sse4.2: Embree 3.13.5 has no SSE4.2 single-ray triangle kernel and
// runs its SSE2 one, so the ISA recorded is the kernel's, not the option's.
TEST(EmbreeVerbose, TheIsaIsTheKernelsNamespace) {
  const EmbreeSelection s = parse_embree_verbose(
      "building BVH4<triangle4> using sse2::BVH4BuilderSAH ...\n"
      "selected scene intersector\n"
      "  intersector1  = sse2::BVH4Triangle4Intersector1Moeller\n");
  EXPECT_EQ(s.isa, "sse2");
  EXPECT_EQ(s.accel, "BVH4");
}

TEST(EmbreeVerbose, WhatItCannotReadIsUnknownNeverAnError) {
  for (const char* text : {"", "garbage\nwithout: the lines\n", "building BVH8 without a leaf\n",
                           "  intersector1  = avx2::BVH8Triangle4Intersector1Moeller\n"}) {
    SCOPED_TRACE(text);
    const EmbreeSelection s = parse_embree_verbose(text);
    EXPECT_FALSE(s.complete());
    EXPECT_EQ(s.isa, kEmbreeUnknown);  // an intersector line outside "selected scene intersector" is not read
    const auto p = embree_provenance(s, "verbose=0", false, "lib", "unknown");
    EXPECT_HAS(value(p, "probe"), "could not be read");
    EXPECT_EQ(value(p, "accel"), kEmbreeUnknown);
    EXPECT_HAS(embree_summary(s, false), "ISA unknown, unknown unknown, intersector unknown");
    EXPECT_HAS(embree_summary(s, false), "could not be read");
  }
}

TEST(EmbreeLibrary, AssertionsAreReadFromTheLibrarysImports) {
  EXPECT_EQ(assertions_from_library_bytes(std::string_view("\x7f" "ELF..abort\0__assert_fail\0memcpy\0", 32)),
            "enabled");
  EXPECT_EQ(assertions_from_library_bytes(std::string_view("\x7f" "ELF..abort\0memcpy\0", 18)), "disabled");
  EXPECT_EQ(assertions_from_library_bytes("__assert_failure"), "disabled");  // another name
  EXPECT_EQ(assertions_from_library_bytes(""), "unknown");
}

// ---------------------------------------------------------------------------
// The live probe: an Embree backend's provenance on this machine.

TEST(EmbreeProbe, RecordsWhatEmbreeSelectedOnThisMachine) {
  const auto backend = make_backend("embree");
  const auto p = backend->provenance();
  const std::vector<std::string> isas = {"sse2", "sse42", "avx", "avx2", "avx512"};
  EXPECT_NE(std::find(isas.begin(), isas.end(), value(p, "isa")), isas.end()) << value(p, "isa");
  EXPECT_TRUE(value(p, "accel") == "BVH8" || value(p, "accel") == "BVH4") << value(p, "accel");
  EXPECT_HAS(value(p, "intersector1"), "Intersector1");
  EXPECT_EQ(value(p, "frequency_level"), "simd256");  // set explicitly, whatever the CPU model
  EXPECT_EQ(value(p, "huge_pages"), "on");            // BackendConfig's default policy
  EXPECT_EQ(value(p, "device_config"), embree_device_config(parse_embree_options("embree", {}), true));
  EXPECT_HAS(value(p, "library"), "libembree3");
  EXPECT_HAS(value(p, "summary"), "ISA " + value(p, "isa") + ", " + value(p, "accel") + " ");
  EXPECT_EQ(value(p, "probe"), "(absent)");
  // simd256 allows the 8-wide BVH wherever the CPU has AVX.
  if (__builtin_cpu_supports("avx")) {
    EXPECT_EQ(value(p, "accel"), "BVH8");
  }
  // Debian's libembree3 is built with assertions (issue 33).
  if (value(p, "library").find("Debian package") != std::string::npos) {
    EXPECT_HAS(value(p, "assertions"), "enabled");
  }
}

TEST(EmbreeProbe, Simd128BuildsABvh4AndOptionsReachTheProbe) {
  const auto p = make_backend("embree:simd128:robust:no_hugepages")->provenance();
  EXPECT_EQ(value(p, "accel"), "BVH4");
  EXPECT_EQ(value(p, "leaf"), "Triangle4v");  // RTC_SCENE_FLAG_ROBUST's leaves
  EXPECT_HAS(value(p, "intersector1"), "Pluecker");
  EXPECT_EQ(value(p, "frequency_level"), "simd128");
  EXPECT_EQ(value(p, "huge_pages"), "off");
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_EQ(value(make_backend("embree:avx2")->provenance(), "isa"), "avx2");
  }
}

TEST(EmbreeProbe, LeavesStdoutAsItWas) {
  ::testing::internal::CaptureStdout();
  make_backend("embree")->provenance();
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
}

// ---------------------------------------------------------------------------
// The tight loops on screened rays (backend.h's contract).

Scene square() {
  Scene s;
  s.triangles = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  return s;
}

TEST(EmbreeLoops, EmptyIntervalsAreMissesAndNotOccluded) {
  for (const std::string name : {"embree", "embree:robust", "embree:simd128"}) {
    SCOPED_TRACE(name);
    const auto backend = make_backend(name);
    backend->build(square());
    // Each line crosses the square at t = 1. Screened, as every caller hands them over.
    std::vector<Ray> raw = {kEmptyRay, {{0.5f, 0.25f, 1}, 0.0f, {0, 0, -1}, -kInf},
                            {{0.5f, 0.25f, 1}, 0.0f, {0, 0, -1}, -1.0f}, {{0.5f, 0.25f, 1}, 1.5f, {0, 0, -1}, 1.0f},
                            {{0.5f, 0.25f, 1}, -kInf, {0, 0, -1}, -kInf}, {{0.5f, 0.25f, 1}, 2.0f, {0, 0, -1}, kInf},
                            {{0.5f, 0.25f, 1}, 0.0f, {0, 0, -1}, kInf}};  // the last one open: it hits
    const ScreenedRays screened = screen_rays(raw);
    ASSERT_TRUE(screened.screened.empty());
    std::vector<Hit> hits(raw.size(), Hit{7.0f, 7, 7.0f, 7.0f});
    std::vector<std::uint8_t> occ(raw.size(), 7);
    backend->intersect(screened.rays, hits);
    backend->occluded(screened.rays, occ);
    for (std::size_t i = 0; i + 1 < raw.size(); ++i) {
      EXPECT_EQ(hits[i].prim, kNoHit) << "ray " << i;
      EXPECT_EQ(hits[i].t, kInf) << "ray " << i;  // the default Hit, written over whatever was there
      EXPECT_EQ(occ[i], 0) << "ray " << i;
    }
    EXPECT_EQ(hits.back().prim, 0);
    EXPECT_FLOAT_EQ(hits.back().t, 1.0f);
    EXPECT_EQ(occ.back(), 1);
  }
}

// A batch reuses one RTCRayHit: a hit's answer must not leak into the next
// ray's, nor a miss's default into a hit.
TEST(EmbreeLoops, AnswersDoNotLeakBetweenRaysOfABatch) {
  const auto backend = make_backend("embree");
  backend->build(square());
  std::vector<Ray> rays;
  for (int i = 0; i < 64; ++i) {
    const float x = (i % 3 == 0) ? 2.0f : 0.25f + 0.005f * static_cast<float>(i);
    rays.push_back({{x, 0.1f, 1}, 0.0f, {0, 0, -1}, (i % 5 == 0) ? 0.5f : kInf});
  }
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint8_t> occ(rays.size());
  backend->intersect(rays, hits);
  backend->occluded(rays, occ);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool expected = rays[i].org.x < 1.0f && rays[i].tfar > 1.0f;
    EXPECT_EQ(hits[i].hit(), expected) << "ray " << i;
    EXPECT_EQ(occ[i], expected ? 1 : 0) << "ray " << i;
    if (expected) {
      EXPECT_EQ(hits[i].prim, 0) << "ray " << i;
      EXPECT_FLOAT_EQ(hits[i].t, 1.0f) << "ray " << i;
    } else {
      EXPECT_EQ(hits[i].t, kInf) << "ray " << i;
    }
  }
}

}  // namespace
}  // namespace raybench
