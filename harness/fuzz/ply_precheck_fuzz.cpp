// Fuzz target: the PLY header pre-check (ply_header_problem,
// harness/src/scene/ply_precheck.h), pure, on any bytes as a file's head (at
// most the kPlyPrecheckBytes it is given). Any answer is fine; a crash, a
// sanitizer report, an exception or a hang is a finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene/ply_precheck.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  raybench::ply_header_problem(
      std::string_view(reinterpret_cast<const char*>(data), std::min(size, raybench::kPlyPrecheckBytes)));
  return 0;
}
