// Judging a backend's answers against the referee's, ray by ray, into the
// error rates of one accuracy row (accuracy/accuracy_csv.h).
#pragma once

#include <cstdint>
#include <span>

#include "accuracy/accuracy_csv.h"
#include "raybench/math/ray.h"
#include "referee/referee.h"

namespace raybench {

// Closest-hit answers. `sources` (empty, or one per ray) names the triangle a
// secondary ray starts from: hitting it again, where the referee does not
// accept that hit, is a self-intersection. Fills the counting columns of
// `row` (rays, invalid, truth_hits, ambiguous, false_*, wrong_prim, self_hits, ulp_*, t_relerr_*).
void judge_hits(const Referee& referee, std::span<const Ray> rays, std::span<const RefereeVerdict> truth,
                std::span<const Hit> hits, std::span<const std::int32_t> sources, AccuracyRow& row);

// Occlusion answers: only hit/miss can be wrong (no triangle, no t).
void judge_occlusion(std::span<const Ray> rays, std::span<const RefereeVerdict> truth,
                     std::span<const std::uint8_t> occluded, AccuracyRow& row);

// |t - exact| in units of the float ulp at the exact t (the spacing of floats
// of that magnitude); 0 when both are equal.
double ulp_error(float t, double exact);

}  // namespace raybench
