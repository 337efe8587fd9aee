// Screening: the one place that decides what every backend is given to trace.
// A ray set is screened once, outside any timing, and the screened copy is
// what Embree, our BVHs and plugins all trace:
// - an untraceable ray (is_traceable false: NaN or Inf, coordinates beyond
//   Embree's range, a NaN interval bound) becomes kEmptyRay, whose interval
//   is empty, so no backend, plugin or built-in, ever sees NaN or Inf;
// - a negative tnear is raised to 0 (with_nonnegative_tnear), so every
//   backend traces the interval (max(tnear, 0), tfar] the same way.
// Whatever a backend answers for a ray screened out, its answer is a miss:
// force_misses applies that after the untimed traces whose answers count
// (agreement, the referee's judging, `raybench trace`), never in the timed
// loop. The exact referee judges the original rays, not this copy.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "raybench/math/ray.h"

namespace raybench {

// The ray an untraceable ray becomes: origin 0, direction (1, 0, 0), the
// empty interval (1, 0]. Every backend can trace it and none may hit.
inline constexpr Ray kEmptyRay{{0.0f, 0.0f, 0.0f}, 1.0f, {1.0f, 0.0f, 0.0f}, 0.0f};

struct ScreenedRays {
  std::vector<Ray> rays;                // what every backend traces, index for index
  std::vector<std::size_t> screened;    // indices of rays replaced by kEmptyRay, ascending
  std::size_t raised_tnear = 0;         // traceable rays whose negative tnear became 0
};

ScreenedRays screen_rays(std::span<const Ray> rays);

// Sets the answer of every screened-out ray to a miss (Hit{}, or 0).
// `answers` is indexed like the rays given to screen_rays.
void force_misses(const ScreenedRays& screened, std::span<Hit> answers);
void force_misses(const ScreenedRays& screened, std::span<std::uint8_t> answers);

}  // namespace raybench
