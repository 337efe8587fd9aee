// The `embree:` options and device config (backends/embree_options.h).
#include "backends/embree_options.h"

#include <algorithm>
#include <iterator>

#include <fmt/format.h>

#include "backends/embree_memory.h"
#include "io/error.h"

namespace raybench {
namespace {

const std::vector<std::string> kFrequencyLevels = {"simd128", "simd256", "simd512"};

struct RayModeName {
  const char* option;
  EmbreeRayMode mode;
};
constexpr RayModeName kRayModes[] = {{"packet4", EmbreeRayMode::kPacket4},
                                     {"packet8", EmbreeRayMode::kPacket8},
                                     {"packet16", EmbreeRayMode::kPacket16},
                                     {"stream", EmbreeRayMode::kStream}};

const char* ray_mode_option(EmbreeRayMode mode) {
  for (const RayModeName& m : kRayModes)
    if (m.mode == mode) return m.option;
  return "single";
}

bool native(EmbreeRayMode mode, const EmbreeNativeRays& n) {
  switch (mode) {
    case EmbreeRayMode::kPacket4: return n.packet4;
    case EmbreeRayMode::kPacket8: return n.packet8;
    case EmbreeRayMode::kPacket16: return n.packet16;
    case EmbreeRayMode::kStream: return n.stream;
    case EmbreeRayMode::kSingle: return true;
  }
  return true;
}

}  // namespace

const std::vector<std::string>& embree_isa_names() {
  static const std::vector<std::string> names = {"sse2", "sse4.2", "avx", "avx2", "avx512"};
  return names;
}

EmbreeOptions parse_embree_options(const std::string& name, const std::vector<std::string>& options) {
  EmbreeOptions parsed;
  const auto error = [&](const std::string& problem) {
    return InputError("", fmt::format("backend '{}': {}", name, problem));
  };
  // The option that set each kind so far, to name both in a conflict.
  std::string quality_set, frequency_set, isa_set, pages_set;
  const auto claim = [&](std::string& slot, const std::string& option, const char* kind) {
    if (slot == option) throw error(fmt::format("embree option '{}' given twice", option));
    if (!slot.empty())
      throw error(fmt::format("embree options '{}' and '{}' conflict: one {} per backend", slot, option, kind));
    slot = option;
  };
  std::string ray_mode_set;
  bool robust = false, disc = false, incoherent = false;
  const auto once = [&](bool& flag, const std::string& option) {
    if (flag) throw error(fmt::format("embree option '{}' given twice", option));
    flag = true;
  };
  const std::vector<std::string>& isas = embree_isa_names();
  for (const std::string& o : options) {
    if (o == "low" || o == "medium" || o == "high") {
      claim(quality_set, o, "build quality");
      parsed.quality = o == "low" ? EmbreeQuality::kLow : o == "high" ? EmbreeQuality::kHigh : EmbreeQuality::kMedium;
    } else if (std::find(kFrequencyLevels.begin(), kFrequencyLevels.end(), o) != kFrequencyLevels.end()) {
      claim(frequency_set, o, "frequency level");
      parsed.frequency_level = o;
    } else if (std::find(isas.begin(), isas.end(), o) != isas.end()) {
      claim(isa_set, o, "ISA");
      parsed.isa = o;
    } else if (o == "hugepages" || o == "no_hugepages") {
      claim(pages_set, o, "memory policy");
      parsed.huge_pages = o == "hugepages";
    } else if (o == "robust") {
      once(robust, o);
      parsed.robust = true;
    } else if (o == "disc") {
      once(disc, o);
      parsed.disc = true;
    } else if (o == "incoherent") {
      once(incoherent, o);
      parsed.incoherent = true;
    } else if (const auto m = std::find_if(std::begin(kRayModes), std::end(kRayModes),
                                           [&](const RayModeName& r) { return o == r.option; });
               m != std::end(kRayModes)) {
      claim(ray_mode_set, o, "ray mode");
      parsed.ray_mode = m->mode;
    } else {
      throw error(fmt::format("unknown embree option '{}' (known: low, medium, high, robust, disc, {}, {}, "
                              "hugepages, no_hugepages, packet4, packet8, packet16, stream, incoherent)",
                              o, fmt::join(kFrequencyLevels, ", "), fmt::join(isas, ", ")));
    }
  }
  if (parsed.incoherent && parsed.ray_mode == EmbreeRayMode::kSingle)
    throw error("embree option 'incoherent' needs a packet or stream mode (packet4, packet8, packet16, stream): "
                "rtcIntersect1 does not read the context flag");
  return parsed;
}

int embree_packet_width(EmbreeRayMode mode) {
  return mode == EmbreeRayMode::kPacket4 ? 4 : mode == EmbreeRayMode::kPacket8 ? 8 : mode == EmbreeRayMode::kPacket16 ? 16 : 0;
}

std::string embree_ray_mode(const EmbreeOptions& options, const EmbreeNativeRays& native_rays) {
  const EmbreeRayMode mode = options.ray_mode;
  if (mode == EmbreeRayMode::kSingle) return "single rays (rtcIntersect1/rtcOccluded1)";
  const int width = embree_packet_width(mode);
  const std::string calls = width ? fmt::format("rtcIntersect{}/rtcOccluded{}", width, width)
                                  : std::string("rtcIntersect1M/rtcOccluded1M over each chunk");
  const std::string head = fmt::format("{} ({}, {} flag)", ray_mode_option(mode), calls,
                                       options.incoherent ? "incoherent" : "coherent");
  if (native(mode, native_rays)) return head + ": native";
  if (!width) return head + ": not supported by this Embree (built without ray packets)";
  // rtcore.cpp: an Embree built without EMBREE_RAY_PACKETS (then it has no
  // streams either) answers rtcIntersectN one lane at a time.
  if (!native_rays.stream) return head + ": emulated by Embree (built without ray packets: rtcIntersect1 per lane)";
  std::vector<int> widths;
  if (native_rays.packet4) widths.push_back(4);
  if (native_rays.packet8) widths.push_back(8);
  if (native_rays.packet16) widths.push_back(16);
  // rtcore.cpp: without an intersector of the width, rtcIntersectN hands the
  // packet to the device's ray stream filter (intersectSOA).
  return fmt::format("{}: emulated by Embree (no native {}-wide packets on this device; native widths: {}), "
                     "its stream filter splits each packet",
                     head, width, widths.empty() ? std::string("none") : fmt::format("{}", fmt::join(widths, ", ")));
}

std::string embree_ray_mode_summary(const EmbreeOptions& options, const EmbreeNativeRays& native_rays) {
  if (options.ray_mode == EmbreeRayMode::kSingle) return "";
  return fmt::format("{} {}, {}", ray_mode_option(options.ray_mode),
                     native(options.ray_mode, native_rays) ? "native" : "emulated",
                     options.incoherent ? "incoherent" : "coherent");
}

bool embree_huge_pages(const EmbreeOptions& options, bool run_huge_pages) {
  return options.huge_pages.value_or(run_huge_pages);
}

std::string embree_device_config(const EmbreeOptions& options, bool run_huge_pages) {
  std::vector<std::string> parts = {"verbose=0"};
  if (std::string memory = embree_memory_config(embree_huge_pages(options, run_huge_pages)); !memory.empty())
    parts.push_back(std::move(memory));
  parts.push_back("frequency_level=" + options.frequency_level);
  if (!options.isa.empty()) parts.push_back("isa=" + options.isa);
  return fmt::format("{}", fmt::join(parts, ","));
}

std::string embree_device_error(const std::string& name, const EmbreeOptions& options, const std::string& config,
                                bool unsupported_cpu) {
  if (unsupported_cpu && !options.isa.empty())
    return fmt::format("backend '{}': this CPU lacks the ISA {} (Embree refused isa={}: RTC_ERROR_UNSUPPORTED_CPU); "
                       "name one it has ({}) or none, to let Embree choose",
                       name, options.isa, options.isa, fmt::join(embree_isa_names(), ", "));
  if (unsupported_cpu)
    return fmt::format("backend '{}': Embree does not support this CPU (RTC_ERROR_UNSUPPORTED_CPU, config '{}')", name,
                       config);
  return fmt::format("backend '{}': Embree cannot create a device (config '{}')", name, config);
}

}  // namespace raybench
