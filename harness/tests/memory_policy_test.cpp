// Specification of the run's memory policy (BackendConfig::huge_pages): the
// residency reader (measure/page_residency.h), the setting and its metadata
// (suite/settings_rules.h, suite/suite_run.h), Embree's device-config share
// (backends/embree_memory.h), and, live, that the policy decides where
// Embree's and our bvh8's structures land: in huge pages when on, not when off.
#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "backends/embree_memory.h"
#include "io/error.h"
#include "measure/build_timing.h"
#include "measure/page_residency.h"
#include "measure/trace.h"
#include "raybench/bvh/huge_pages.h"
#include "scene/scene.h"
#include "suite/settings_rules.h"
#include "suite/suite_run.h"

namespace raybench {
namespace {

constexpr std::size_t kMiB = std::size_t{1} << 20;

TEST(PageResidency, AnonHugePagesOfASmapsRollupAreReadInBytes) {
  const std::string rollup =
      "55d0c0a00000-7ffd5a3f1000 ---p 00000000 00:00 0                          [rollup]\n"
      "Rss:               48560 kB\n"
      "Anonymous:         30212 kB\n"
      "AnonHugePages:     20480 kB\n"
      "ShmemPmdMapped:        0 kB\n";
  EXPECT_EQ(parse_anon_huge_page_bytes(rollup), std::optional<std::size_t>(20480 * 1024));
}

TEST(PageResidency, EveryMappingOfAnSmapsTextIsAddedUp) {
  const std::string smaps =
      "7f0000000000-7f0000400000 rw-p 00000000 00:00 0\nAnonHugePages:      4096 kB\n"
      "7f0000400000-7f0000401000 rw-p 00000000 00:00 0\nAnonHugePages:         0 kB\n"
      "7f0000600000-7f0000a00000 rw-p 00000000 00:00 0\nAnonHugePages:      2048 kB\n";
  EXPECT_EQ(parse_anon_huge_page_bytes(smaps), std::optional<std::size_t>(6 * kMiB));
}

TEST(PageResidency, ATextWithoutTheFieldOrWithAMalformedOneIsUnavailableNotZero) {
  EXPECT_EQ(parse_anon_huge_page_bytes(""), std::nullopt);
  EXPECT_EQ(parse_anon_huge_page_bytes("Rss: 10 kB\n"), std::nullopt);
  EXPECT_EQ(parse_anon_huge_page_bytes("AnonHugePages: many kB\n"), std::nullopt);
  EXPECT_EQ(parse_anon_huge_page_bytes("AnonHugePages: 2048 MB\n"), std::nullopt);
  EXPECT_EQ(parse_anon_huge_page_bytes("AnonHugePages: 0 kB\n"), std::optional<std::size_t>(0));
}

TEST(PageResidency, TheThpModeIsTheBracketedWord) {
  EXPECT_EQ(parse_thp_mode("always [madvise] never\n"), "madvise");
  EXPECT_EQ(parse_thp_mode("[always] madvise never\n"), "always");
  EXPECT_EQ(parse_thp_mode("always madvise [never]\n"), "never");
  EXPECT_EQ(parse_thp_mode("always madvise never\n"), "");
  EXPECT_EQ(parse_thp_mode("[]"), "");
  EXPECT_EQ(parse_thp_mode(""), "");
}

TEST(PageResidency, ThisMachineAnswersOrSaysUnavailable) {
  const std::string mode = transparent_huge_pages_mode();
  EXPECT_TRUE(mode == "always" || mode == "madvise" || mode == "never" || mode == "unavailable") << mode;
#if defined(__linux__)
  EXPECT_TRUE(anon_huge_page_bytes().has_value()) << "/proc/self/smaps_rollup should be readable on Linux";
#endif
}

TEST(MemoryPolicy, TheSettingIsOnOrOffAndAnythingElseIsOneLineNamingWhereItWasGiven) {
  EXPECT_TRUE(huge_pages_setting(GivenValue::from_flag("--huge-pages", "on")));
  EXPECT_FALSE(huge_pages_setting(GivenValue::from_flag("--huge-pages", "off")));
  for (const char* bad : {"", "On", "yes", "1", "true"}) {
    try {
      huge_pages_setting(GivenValue::from_flag("--huge-pages", bad));
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("--huge-pages"), std::string::npos) << message;
      EXPECT_NE(message.find("must be on or off"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(MemoryPolicy, UnderMadviseTheMetadataSaysWhichPolicyHeldForEveryBackend) {
  EXPECT_EQ(memory_policy_description(true, "madvise"), "huge pages for every backend (transparent, madvise)");
  EXPECT_EQ(memory_policy_description(false, "madvise"), "ordinary pages for every backend");
}

// Under "always" nothing is advised off huge pages (Embree's memory cannot
// be), so "off" is a request the kernel may overrule, and "on" owes nothing
// to advice.
TEST(MemoryPolicy, UnderAlwaysOffIsOnlyARequestAndOnIsNotMadvise) {
  EXPECT_EQ(memory_policy_description(false, "always"),
            "ordinary pages requested for every backend, but the kernel's THP mode 'always' may give any of them "
            "huge pages");
  const std::string on = memory_policy_description(true, "always");
  EXPECT_EQ(on, "huge pages for every backend (transparent, the kernel's THP mode 'always')");
  EXPECT_EQ(on.find("madvise"), std::string::npos) << on;
}

TEST(MemoryPolicy, UnderNeverNoBackendGetsHugePages) {
  const std::string on = memory_policy_description(true, "never");
  EXPECT_EQ(on, "huge pages requested for every backend, but the kernel's THP mode 'never' gives none of them huge pages");
  EXPECT_EQ(on.find("madvise"), std::string::npos) << on;
  EXPECT_EQ(memory_policy_description(false, "never"), "ordinary pages for every backend");
}

TEST(MemoryPolicy, AnUnknownModeIsSaidToBeUnknown) {
  for (const char* mode : {"unavailable", ""}) {
    EXPECT_EQ(memory_policy_description(true, mode),
              "huge pages requested for every backend (transparent, madvise); the kernel's THP mode is unknown");
    EXPECT_EQ(memory_policy_description(false, mode),
              "ordinary pages requested for every backend; the kernel's THP mode is unknown");
  }
}

// Embree 3.13's blocks reach its advised os_malloc only at exactly
// maxAllocationSize (2 MiB - 64): "on" asks for thread blocks of that size;
// "off" keeps its main blocks below it (embree_memory.cpp says why).
TEST(MemoryPolicy, EmbreesShareIsADeviceConfigFragment) {
  EXPECT_EQ(embree_memory_config(true), "hugepages=1,alloc_thread_block_size=2097088");
  EXPECT_EQ(embree_memory_config(false), "hugepages=0,alloc_main_block_size=1048576");
}

TEST(MemoryPolicy, OurSwitchIsOnByDefaultAndSettable) {
  EXPECT_TRUE(huge_pages_enabled());
  set_huge_pages(false);
  EXPECT_FALSE(huge_pages_enabled());
  set_huge_pages(true);
  EXPECT_TRUE(huge_pages_enabled());
}

// A terrain of 2 x 256 x 256 = 131,072 triangles: trees of several MiB, below
// the ~40 MiB from which Embree's default blocks alone reach huge pages.
Scene terrain() {
  Scene scene;
  scene.name = "memory_policy_terrain";
  constexpr int kCells = 256;
  const auto height = [](int x, int z) { return 0.25f * static_cast<float>((x * 7 + z * 13) % 5); };
  for (int z = 0; z < kCells; ++z) {
    for (int x = 0; x < kCells; ++x) {
      const Vec3f a{float(x), height(x, z), float(z)}, b{float(x + 1), height(x + 1, z), float(z)};
      const Vec3f c{float(x), height(x, z + 1), float(z + 1)}, d{float(x + 1), height(x + 1, z + 1), float(z + 1)};
      scene.triangles.push_back({a, b, c});
      scene.triangles.push_back({b, d, c});
    }
  }
  return scene;
}

struct Landed {
  std::size_t structure_bytes = 0;  // what the backend reports
  std::size_t huge_bytes = 0;       // growth of AnonHugePages across its first build
};

// Embree built through its API with the policy's device config, as the
// embree backend composes it (the backend adds its other settings).
Landed build_embree(const Scene& scene, bool huge_pages) {
  static std::atomic<long long> allocated{0};
  const std::string config = "verbose=0," + embree_memory_config(huge_pages);
  RTCDevice device = rtcNewDevice(config.c_str());
  EXPECT_NE(device, nullptr) << config;
  rtcSetDeviceMemoryMonitorFunction(device, [](void*, ssize_t bytes, bool) { allocated += bytes; return true; }, nullptr);
  RTCScene rtc_scene = rtcNewScene(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const std::size_t n = scene.triangles.size();
  auto* vertices = static_cast<float*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
  std::memcpy(vertices, scene.triangles.data(), n * sizeof(Triangle));
  for (unsigned i = 0; i < 3 * n; ++i) indices[i] = i;
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(rtc_scene, geometry);
  rtcReleaseGeometry(geometry);
  Landed landed;
  const long long allocated_before = allocated.load();
  const std::size_t huge_before = anon_huge_page_bytes().value();
  TraceExecutor(1).run([&] { rtcCommitScene(rtc_scene); });
  const std::size_t huge_after = anon_huge_page_bytes().value();
  landed.huge_bytes = huge_after > huge_before ? huge_after - huge_before : 0;
  landed.structure_bytes = static_cast<std::size_t>(allocated.load() - allocated_before);
  rtcReleaseScene(rtc_scene);
  rtcReleaseDevice(device);
  return landed;
}

// bvh8 made and built as a run does (BackendConfig, time_builds_interleaved).
Landed build_bvh8(const Scene& scene, bool huge_pages) {
  const std::unique_ptr<Backend> backend = make_backend("bvh8", {1, huge_pages});
  Backend* const backends[] = {backend.get()};
  std::vector<std::optional<std::size_t>> huge;
  time_builds_interleaved(backends, scene, TraceExecutor(1), 1, 0.0, &huge);
  EXPECT_TRUE(huge.at(0).has_value());
  return {backend->memory_bytes(), huge.at(0).value_or(0)};
}

// Each live test runs in a process of its own under ctest (gtest_discover_tests),
// so memory one of them advised is never reused by the other.
TEST(MemoryPolicyLive, OnPutsEmbreesAndOurStructuresInHugePages) {
  const std::string mode = transparent_huge_pages_mode();
  if (mode == "never" || mode == "unavailable" || !anon_huge_page_bytes())
    GTEST_SKIP() << "the kernel gives no transparent huge pages here (THP mode: " << mode
                 << "), so no policy can put a structure in them";
  const Scene scene = terrain();
  const Landed embree = build_embree(scene, true);
  const Landed bvh8 = build_bvh8(scene, true);
  EXPECT_GT(embree.structure_bytes, 4 * kMiB);
  EXPECT_GT(bvh8.structure_bytes, 4 * kMiB);
  EXPECT_GE(embree.huge_bytes, embree.structure_bytes / 2)
      << "embree: " << embree.huge_bytes << " of " << embree.structure_bytes << " bytes in huge pages";
  EXPECT_GE(bvh8.huge_bytes, bvh8.structure_bytes / 2)
      << "bvh8: " << bvh8.huge_bytes << " of " << bvh8.structure_bytes << " bytes in huge pages";
}

TEST(MemoryPolicyLive, OffKeepsBothOffHugePagesWhereTheKernelOnlyFollowsAdvice) {
  const std::string mode = transparent_huge_pages_mode();
  if (mode != "madvise" || !anon_huge_page_bytes())
    GTEST_SKIP() << "THP mode is '" << mode << "': only in 'madvise' mode does withholding the advice keep memory "
                 << "off huge pages";
  const Scene scene = terrain();
  const Landed embree = build_embree(scene, false);
  const Landed bvh8 = build_bvh8(scene, false);
  EXPECT_GT(embree.structure_bytes, 4 * kMiB);
  EXPECT_GT(bvh8.structure_bytes, 4 * kMiB);
  EXPECT_EQ(embree.huge_bytes, 0u) << embree.structure_bytes;
  EXPECT_EQ(bvh8.huge_bytes, 0u) << bvh8.structure_bytes;
  set_huge_pages(true);
}

}  // namespace
}  // namespace raybench
