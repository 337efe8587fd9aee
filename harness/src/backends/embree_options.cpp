// The `embree:` options and device config (backends/embree_options.h).
#include "backends/embree_options.h"

#include <algorithm>

#include <fmt/format.h>

#include "backends/embree_memory.h"
#include "io/error.h"

namespace raybench {
namespace {

const std::vector<std::string> kFrequencyLevels = {"simd128", "simd256", "simd512"};

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
  bool robust = false, disc = false;
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
    } else {
      throw error(fmt::format("unknown embree option '{}' (known: low, medium, high, robust, disc, {}, {}, "
                              "hugepages, no_hugepages)",
                              o, fmt::join(kFrequencyLevels, ", "), fmt::join(isas, ", ")));
    }
  }
  return parsed;
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
