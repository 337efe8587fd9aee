// Specification of Embree's coherent ray modes (issue 32): `embree:packet4|8|16`
// (rtcIntersect4/8/16, rtcOccluded4/8/16 over consecutive rays) and
// `embree:stream` (rtcIntersect1M/rtcOccluded1M), with the coherent or the
// incoherent context flag. Every mode answers as `embree` (rtcIntersect1) on
// the same screened rays: the same hit or miss, the same primitive unless two
// are hit at exactly the same t, the same occlusion; for every tail length,
// with empty-interval lanes anywhere in a packet, and with NaN/Inf rays
// screened as the harness screens them (rays/screening.h). Also: the options,
// their conflicts, and what the provenance says about native widths.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "backends/embree_options.h"
#include "measure/trace.h"
#include "rays/rayset.h"
#include "rays/screening.h"
#include "scene/scene.h"
#include "test_util.h"

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Every coherent mode, with the options it must combine with. Each is
// compared with its single-ray twin (single_ray_twin): `embree` itself for
// the plain modes.
const std::vector<std::string> kModes = {"embree:packet4",         "embree:packet8",
                                         "embree:packet16",        "embree:stream",
                                         "embree:stream:incoherent", "embree:packet8:incoherent",
                                         "embree:packet16:avx2",   "embree:packet4:high:robust"};

// The mode's single-ray twin: the same name without its ray mode options
// (embree:packet16:avx2 -> embree:avx2), the same device, build and kernels.
std::string single_ray_twin(const std::string& mode) {
  std::string twin = "embree";
  std::size_t start = mode.find(':');
  while (start != std::string::npos) {
    const std::size_t end = mode.find(':', start + 1);
    const std::string option = mode.substr(start + 1, end == std::string::npos ? std::string::npos : end - start - 1);
    if (option.rfind("packet", 0) != 0 && option != "stream" && option != "incoherent") twin += ":" + option;
    start = end;
  }
  return twin;
}

std::string value(const std::vector<std::pair<std::string, std::string>>& pairs, const std::string& key) {
  for (const auto& [k, v] : pairs)
    if (k == key) return v;
  return "(absent)";
}

// ---------------------------------------------------------------------------
// Options

TEST(EmbreeRayModeOptions, EachModeIsOneOptionAndCombinesWithTheOthers) {
  EXPECT_EQ(parse_embree_options("embree", {}).ray_mode, EmbreeRayMode::kSingle);
  EXPECT_EQ(parse_embree_options("embree:packet4", {"packet4"}).ray_mode, EmbreeRayMode::kPacket4);
  EXPECT_EQ(parse_embree_options("embree:packet8", {"packet8"}).ray_mode, EmbreeRayMode::kPacket8);
  EXPECT_EQ(parse_embree_options("embree:packet16", {"packet16"}).ray_mode, EmbreeRayMode::kPacket16);
  const EmbreeOptions stream = parse_embree_options("embree:stream", {"stream"});
  EXPECT_EQ(stream.ray_mode, EmbreeRayMode::kStream);
  EXPECT_FALSE(stream.incoherent);
  const EmbreeOptions all = parse_embree_options("embree:high:robust:avx2:no_hugepages:incoherent:packet16",
                                                 {"high", "robust", "avx2", "no_hugepages", "incoherent", "packet16"});
  EXPECT_EQ(all.ray_mode, EmbreeRayMode::kPacket16);
  EXPECT_TRUE(all.incoherent);
  EXPECT_TRUE(all.robust);
  EXPECT_EQ(all.isa, "avx2");
  EXPECT_EQ(all.quality, EmbreeQuality::kHigh);
  EXPECT_EQ(embree_packet_width(EmbreeRayMode::kPacket4), 4);
  EXPECT_EQ(embree_packet_width(EmbreeRayMode::kPacket16), 16);
  EXPECT_EQ(embree_packet_width(EmbreeRayMode::kStream), 0);
  EXPECT_EQ(embree_packet_width(EmbreeRayMode::kSingle), 0);
}

TEST(EmbreeRayModeOptions, TwoModesOrIncoherentSingleRaysAreOneLineErrors) {
  const auto error = [](const std::string& name, const std::vector<std::string>& options) {
    return testing::input_error_of([&] { parse_embree_options(name, options); });
  };
  EXPECT_HAS(error("embree:packet8:stream", {"packet8", "stream"}),
             "backend 'embree:packet8:stream': embree options 'packet8' and 'stream' conflict: one ray mode per backend");
  EXPECT_HAS(error("embree:packet4:packet16", {"packet4", "packet16"}), "one ray mode per backend");
  EXPECT_HAS(error("embree:stream:stream", {"stream", "stream"}), "embree option 'stream' given twice");
  EXPECT_HAS(error("embree:stream:incoherent:incoherent", {"stream", "incoherent", "incoherent"}),
             "embree option 'incoherent' given twice");
  EXPECT_HAS(error("embree:incoherent", {"incoherent"}),
             "backend 'embree:incoherent': embree option 'incoherent' needs a packet or stream mode");
  EXPECT_HAS(error("embree:packet32", {"packet32"}), "unknown embree option 'packet32'");
  for (const std::string& e : {error("embree:incoherent", {"incoherent"}), error("embree:packet8:stream", {"packet8", "stream"})})
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_HAS(testing::input_error_of([] { make_backend("embree:packet8:packet8"); }), "given twice");
}

TEST(EmbreeRayModeOptions, TheSingleRayTwinDropsOnlyTheRayMode) {
  EXPECT_EQ(single_ray_twin("embree:packet8"), "embree");
  EXPECT_EQ(single_ray_twin("embree:stream:incoherent"), "embree");
  EXPECT_EQ(single_ray_twin("embree:packet4:high:robust"), "embree:high:robust");
  EXPECT_EQ(single_ray_twin("embree:packet16:avx2"), "embree:avx2");
}

// ---------------------------------------------------------------------------
// Native widths, as the metadata records them

TEST(EmbreeRayModeRecord, SaysWhetherEmbreeRunsTheWidthNativelyAndWhatItDoesOtherwise) {
  const EmbreeNativeRays avx2{true, true, false, true};
  const EmbreeOptions p16 = parse_embree_options("embree:packet16", {"packet16"});
  const EmbreeOptions p8 = parse_embree_options("embree:packet8", {"packet8"});
  EXPECT_EQ(embree_ray_mode(p8, avx2), "packet8 (rtcIntersect8/rtcOccluded8, coherent flag): native");
  EXPECT_EQ(embree_ray_mode(p16, avx2),
            "packet16 (rtcIntersect16/rtcOccluded16, coherent flag): emulated by Embree (no native 16-wide packets "
            "on this device; native widths: 4, 8), its stream filter splits each packet");
  EXPECT_HAS(embree_ray_mode(p16, EmbreeNativeRays{}), "built without ray packets: rtcIntersect1 per lane");
  const EmbreeOptions incoherent = parse_embree_options("embree:stream:incoherent", {"stream", "incoherent"});
  EXPECT_EQ(embree_ray_mode(incoherent, avx2),
            "stream (rtcIntersect1M/rtcOccluded1M over each chunk, incoherent flag): native");
  EXPECT_EQ(embree_ray_mode(parse_embree_options("embree", {}), avx2), "single rays (rtcIntersect1/rtcOccluded1)");
  EXPECT_EQ(embree_ray_mode_summary(p16, avx2), "packet16 emulated, coherent");
  EXPECT_EQ(embree_ray_mode_summary(p8, avx2), "packet8 native, coherent");
  EXPECT_EQ(embree_ray_mode_summary(parse_embree_options("embree", {}), avx2), "");
}

// On this machine: every mode records its ray mode, and the progress line says it.
TEST(EmbreeRayModeRecord, EveryModesProvenanceNamesItsModeAndNativeness) {
  for (const std::string& name : kModes) {
    SCOPED_TRACE(name);
    const auto p = make_backend(name)->provenance();
    const std::string mode = value(p, "ray_mode");
    const std::string option = name.find("stream") != std::string::npos ? "stream"
                               : name.find("packet16") != std::string::npos ? "packet16"
                               : name.find("packet8") != std::string::npos  ? "packet8"
                                                                             : "packet4";
    EXPECT_EQ(mode.rfind(option + " (", 0), 0u) << mode;
    EXPECT_TRUE(mode.ends_with(": native") || mode.find(": emulated by Embree (") != std::string::npos) << mode;
    EXPECT_HAS(value(p, "summary"), option + (mode.ends_with(": native") ? " native" : " emulated"));
    EXPECT_HAS(mode, name.find("incoherent") != std::string::npos ? "incoherent flag" : "coherent flag");
  }
  EXPECT_EQ(value(make_backend("embree")->provenance(), "ray_mode"), "single rays (rtcIntersect1/rtcOccluded1)");
  // Forced to AVX2, a device has no 16-wide packets (device.cpp: hasISA(AVX512)).
  EXPECT_HAS(value(make_backend("embree:packet16:avx2")->provenance(), "ray_mode"),
             "emulated by Embree (no native 16-wide packets on this device");
}

// ---------------------------------------------------------------------------
// Answers: every mode as `embree`

// How far a mode's t may be from rtcIntersect1's on the same primitive: the
// packet kernels compute t their own way and differ by up to ~2 ulp
// (measured on proc:terrain_spheres_small and proc:analytic_mix); 1e-6 is ~8 ulp.
constexpr float kTRelative = 1e-6f;

// `embree`'s answers and the mode's on the same screened rays, ray by ray.
void expect_same_answers(const std::string& mode, const Backend& single, const Backend& coherent,
                         const std::vector<Ray>& screened_rays, std::vector<Hit> expected_hits = {},
                         std::vector<std::uint8_t> expected_occ = {}) {
  const std::size_t n = screened_rays.size();
  if (expected_hits.empty()) {
    expected_hits.assign(n, Hit{});
    expected_occ.assign(n, 0);
    single.intersect(screened_rays, expected_hits);
    single.occluded(screened_rays, expected_occ);
  }
  // Garbage in the outputs: every answer must be written.
  std::vector<Hit> hits(n, Hit{7.0f, 7, 7.0f, 7.0f});
  std::vector<std::uint8_t> occ(n, 7);
  coherent.intersect(screened_rays, hits);
  coherent.occluded(screened_rays, occ);
  int mismatches = 0;
  for (std::size_t i = 0; i < n && mismatches < 5; ++i) {
    const Hit& e = expected_hits[i];
    const Hit& h = hits[i];
    const bool same = e.hit() == h.hit() && (e.prim == h.prim || e.t == h.t) && occ[i] == expected_occ[i] &&
                      (!e.hit() || std::fabs(e.t - h.t) <= kTRelative * std::max(1.0f, std::fabs(e.t)));
    if (!same) {
      ++mismatches;
      ADD_FAILURE() << mode << ", ray " << i << " of " << n << ": embree prim " << e.prim << " t " << e.t
                    << " occluded " << int(expected_occ[i]) << "; mode prim " << h.prim << " t " << h.t
                    << " occluded " << int(occ[i]);
    }
  }
}

RaySetSpec spec(RaySetKind kind, std::size_t count, std::uint64_t seed) {
  RaySetSpec s;
  s.kind = kind, s.count = count, s.seed = seed;
  return s;
}

struct RaySource {
  const char* scene;
  RaySetKind kind;
};

// A triangle scene and one with every primitive type (user geometry in packets),
// coherent rays (primary, shadow) and incoherent ones (diffuse, uniform), and
// G15's NaN, Inf and out-of-range rays, screened.
const std::vector<RaySource> kSources = {
    {"proc:terrain_spheres_small", RaySetKind::kPrimary}, {"proc:terrain_spheres_small", RaySetKind::kShadow},
    {"proc:terrain_spheres_small", RaySetKind::kDiffuse}, {"proc:terrain_spheres_small", RaySetKind::kUniform},
    {"proc:terrain_spheres_small", RaySetKind::kInvalid}, {"proc:analytic_mix", RaySetKind::kPrimary},
    {"proc:analytic_mix", RaySetKind::kUniform},          {"proc:analytic_mix", RaySetKind::kInvalid},
};

TEST(EmbreeRayModes, AnswerAsSingleRaysOnCoherentIncoherentAndScreenedRays) {
  for (const RaySource& source : kSources) {
    const Scene scene = load_scene(source.scene);
    const ScreenedRays screened = screen_rays(RayGenerator(scene).generate(spec(source.kind, 3000, 7)));
    if (source.kind == RaySetKind::kInvalid) {
      ASSERT_FALSE(screened.screened.empty());
    }
    for (const std::string& mode : kModes) {
      SCOPED_TRACE(std::string(source.scene) + " " + to_string(source.kind) + " " + mode);
      const auto single = make_backend(single_ray_twin(mode));
      single->build(scene);
      const auto coherent = make_backend(mode);
      coherent->build(scene);
      expect_same_answers(mode, *single, *coherent, screened.rays);
      // A screened-out ray is a miss before force_misses, not only after.
      std::vector<Hit> hits(screened.rays.size());
      std::vector<std::uint8_t> occ(screened.rays.size());
      coherent->intersect(screened.rays, hits);
      coherent->occluded(screened.rays, occ);
      for (std::size_t i : screened.screened) {
        EXPECT_FALSE(hits[i].hit()) << "screened ray " << i;
        EXPECT_EQ(occ[i], 0) << "screened ray " << i;
      }
    }
  }
}

// Every tail: spans of 1 to 33 rays (packets of 16 leave tails 1..15) starting
// anywhere, and the trace executor's chunks on two threads.
TEST(EmbreeRayModes, EveryTailLengthAndEveryChunking) {
  const Scene scene = load_scene("proc:terrain_spheres_small");
  const ScreenedRays screened = screen_rays(RayGenerator(scene).generate(spec(RaySetKind::kPrimary, 2500, 3)));
  for (const std::string& mode : kModes) {
    SCOPED_TRACE(mode);
    const auto single = make_backend(single_ray_twin(mode));
    single->build(scene);
    const auto coherent = make_backend(mode);
    coherent->build(scene);
    for (std::size_t count = 1; count <= 33; ++count) {
      SCOPED_TRACE("count " + std::to_string(count));
      const std::vector<Ray> some(screened.rays.begin() + 17 * count, screened.rays.begin() + 18 * count);
      expect_same_answers(mode, *single, *coherent, some);
    }
    std::vector<Hit> one(screened.rays.size()), two(screened.rays.size());
    std::vector<std::uint8_t> occ_one(screened.rays.size()), occ_two(screened.rays.size());
    TraceExecutor(1).intersect(*single, screened.rays, one);
    TraceExecutor(1).occluded(*single, screened.rays, occ_one);
    TraceExecutor(2).intersect(*coherent, screened.rays, two);
    TraceExecutor(2).occluded(*coherent, screened.rays, occ_two);
    int hits = 0;
    for (std::size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(one[i].prim, two[i].prim) << "ray " << i;
      EXPECT_EQ(occ_one[i], occ_two[i]) << "ray " << i;
      hits += one[i].hit();
    }
    EXPECT_GT(hits, 400);  // the camera sees the terrain: the comparison is not of misses
  }
}

// Lanes whose interval is empty (kEmptyRay, tfar < tnear, tfar = -inf) at every
// position of a packet: they answer a miss and not occluded, and the lanes
// beside them answer as they would alone.
TEST(EmbreeRayModes, EmptyLanesAnywhereInAPacketAreMissesAndLeaveTheOthersAlone) {
  Scene square;
  square.triangles = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  const std::vector<Ray> empties = {kEmptyRay, {{0.5f, 0.25f, 1}, 0.0f, {0, 0, -1}, -kInf},
                                    {{0.5f, 0.25f, 1}, 1.5f, {0, 0, -1}, 1.0f}};
  for (const std::string& mode : kModes) {
    SCOPED_TRACE(mode);
    const auto backend = make_backend(mode);
    backend->build(square);
    for (std::size_t empty_every = 2; empty_every <= 5; ++empty_every) {
      std::vector<Ray> rays;
      std::vector<Hit> expected_hits;
      std::vector<std::uint8_t> expected_occ;
      for (std::size_t i = 0; i < 37; ++i) {
        if (i % empty_every == 0) {
          rays.push_back(empties[i % empties.size()]);
          expected_hits.push_back(Hit{});
          expected_occ.push_back(0);
        } else {
          // Crosses the square at t = 1 (prim 0 below the diagonal) or misses it beside.
          const bool inside = i % 3 != 0;
          rays.push_back({{inside ? 0.75f : 2.0f, 0.25f, 1}, 0.0f, {0, 0, -1}, kInf});
          expected_hits.push_back(inside ? Hit{1.0f, 0, 0.0f, 0.0f} : Hit{});
          expected_occ.push_back(inside ? 1 : 0);
        }
      }
      const ScreenedRays screened = screen_rays(rays);
      ASSERT_TRUE(screened.screened.empty());
      expect_same_answers(mode, *backend, *backend, screened.rays, expected_hits, expected_occ);
    }
  }
}

}  // namespace
}  // namespace raybench
