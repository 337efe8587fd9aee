// Answers checked for shape, for any backend (measure/answer_check.h).
#include "measure/answer_check.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace raybench {

std::string AnswerProblems::describe() const {
  std::vector<std::string> parts;
  const auto add = [&](std::size_t n, const std::string& what) {
    if (n == 0) return;
    parts.push_back(parts.empty() ? fmt::format("{} of {} rays with {}", n, rays, what) : fmt::format("{} with {}", n, what));
  };
  add(prim_outside, fmt::format("prim outside [0, {})", triangles));
  add(nan_t, "NaN t");
  add(infinite_hit, "a hit at infinite t");
  add(bad_occlusion, "an occlusion flag other than 0 or 1");
  if (parts.empty()) return "";
  std::string out = parts[0];
  for (std::size_t i = 1; i < parts.size(); ++i) out += (i + 1 == parts.size() ? " and " : ", ") + parts[i];
  return out;
}

AnswerProblems check_hits(std::span<const Hit> hits, std::size_t triangles) {
  AnswerProblems p;
  p.rays = hits.size();
  p.triangles = triangles;
  for (const Hit& h : hits) {
    const bool in_scene = h.prim >= 0 && static_cast<std::size_t>(h.prim) < triangles;
    p.prim_outside += !in_scene && h.prim != kNoHit;
    p.nan_t += std::isnan(h.t);
    p.infinite_hit += in_scene && std::isinf(h.t);
  }
  return p;
}

AnswerProblems check_occlusion(std::span<const std::uint8_t> occluded) {
  AnswerProblems p;
  p.rays = occluded.size();
  for (std::uint8_t o : occluded) p.bad_occlusion += o > 1;
  return p;
}

namespace {
void require(const AnswerProblems& p, const Backend& backend, const std::string& where) {
  if (!p.any()) return;
  const std::string plugin = backend.plugin_name();
  throw std::runtime_error(fmt::format("backend '{}'{} returned {} on {}", backend.name(),
                                       plugin.empty() ? "" : " (" + plugin + ")", p.describe(), where));
}
}  // namespace

void require_valid_hits(const Backend& backend, std::span<const Hit> hits, std::size_t triangles,
                        const std::string& where) {
  require(check_hits(hits, triangles), backend, where);
}

void require_valid_occlusion(const Backend& backend, std::span<const std::uint8_t> occluded, const std::string& where) {
  require(check_occlusion(occluded), backend, where);
}

}  // namespace raybench
