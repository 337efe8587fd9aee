// Checks that a backend's answers are answers at all, for any backend, outside
// the timing: a hit's prim inside the scene, t never NaN, a hit at a finite t,
// an occlusion flag 0 or 1. What it does not judge: whether an answer is
// right (agreement and the referee do that).
// Guarantee: require_valid_* throw one line naming the backend, the scene,
// the ray set and how many rays broke each rule, e.g.
//   backend 'plugin:x.so' (my_bvh) returned 12 of 262144 rays with prim outside
//   [0, 1000) and 3 with NaN t on bunny/primary
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "backends/backend.h"
#include "raybench/math/ray.h"

namespace raybench {

struct AnswerProblems {
  std::size_t rays = 0;
  std::size_t prim_outside = 0;     // a prim neither kNoHit nor in [0, triangles)
  std::size_t nan_t = 0;            // t is NaN (hit or miss)
  std::size_t infinite_hit = 0;     // a hit (prim in range) at t = +-inf
  std::size_t bad_occlusion = 0;    // an occlusion flag other than 0 and 1
  std::size_t triangles = 0;

  bool any() const { return prim_outside + nan_t + infinite_hit + bad_occlusion > 0; }
  // "12 of 262144 rays with prim outside [0, 1000) and 3 with NaN t"; "" when none.
  std::string describe() const;
};

AnswerProblems check_hits(std::span<const Hit> hits, std::size_t triangles);
AnswerProblems check_occlusion(std::span<const std::uint8_t> occluded);

// Throw std::runtime_error "backend '<name>' (<plugin name>) returned ...
// on <where>" when check_* finds a problem; `where` is "scene/rayset".
void require_valid_hits(const Backend& backend, std::span<const Hit> hits, std::size_t triangles,
                        const std::string& where);
void require_valid_occlusion(const Backend& backend, std::span<const std::uint8_t> occluded, const std::string& where);

}  // namespace raybench
