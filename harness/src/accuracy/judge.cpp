#include "accuracy/judge.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "measure/agreement.h"

namespace raybench {
namespace {

double fraction(std::size_t count, std::size_t total) { return total ? static_cast<double>(count) / total : 0.0; }

// The columns every query shares.
void count_truth(std::span<const Ray> rays, std::span<const RefereeVerdict> truth, AccuracyRow& row) {
  std::size_t invalid = 0, truth_hits = 0, ambiguous = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    invalid += !is_traceable(rays[i]);
    truth_hits += truth[i].hit();
    ambiguous += truth[i].ambiguous;
  }
  row.rays = rays.size();
  row.invalid = fraction(invalid, rays.size());
  row.truth_hits = fraction(truth_hits, rays.size());
  row.ambiguous = fraction(ambiguous, rays.size());
}

}  // namespace

double ulp_error(float t, double exact) {
  if (static_cast<double>(t) == exact) return 0.0;
  const float nearest = static_cast<float>(exact);
  // The float spacing at |exact|: 2^(exponent - 23) for normal floats, the
  // denormal spacing below FLT_MIN.
  const int exponent = std::ilogb(std::max(std::fabs(nearest), std::numeric_limits<float>::min()));
  const double ulp = std::ldexp(1.0, exponent - std::numeric_limits<float>::digits + 1);
  return std::fabs(static_cast<double>(t) - exact) / ulp;
}

void judge_hits(const Referee& referee, std::span<const Ray> rays, std::span<const RefereeVerdict> truth,
                std::span<const Hit> hits, std::span<const std::int32_t> sources, AccuracyRow& row) {
  count_truth(rays, truth, row);
  std::size_t false_miss = 0, false_hit = 0, wrong_prim = 0, self_hits = 0;
  std::vector<double> ulps, relerrs;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const RefereeVerdict& v = truth[i];
    const Hit& h = hits[i];
    if (v.hit() && !h.hit()) ++false_miss;
    if (!v.hit() && h.hit()) ++false_hit;
    bool accepted = false;
    if (v.hit() && h.hit()) {
      accepted = referee.accepts(rays[i], v, h.prim);
      if (!accepted && !v.ambiguous) ++wrong_prim;
      if (accepted || v.ambiguous) {
        ulps.push_back(ulp_error(h.t, v.t));
        relerrs.push_back(v.t > 0.0 ? std::fabs(static_cast<double>(h.t) - v.t) / v.t : 0.0);
      }
    }
    if (!sources.empty() && h.hit() && h.prim == sources[i] && !accepted) ++self_hits;
  }
  row.false_miss = fraction(false_miss, rays.size());
  row.false_hit = fraction(false_hit, rays.size());
  row.wrong_prim = fraction(wrong_prim, rays.size());
  row.self_hits = sources.empty() ? std::numeric_limits<double>::quiet_NaN() : fraction(self_hits, rays.size());
  row.ulp_p50 = nearest_rank_percentile(ulps, 0.5);
  row.ulp_p99 = nearest_rank_percentile(ulps, 0.99);
  row.ulp_max = ulps.empty() ? std::numeric_limits<double>::quiet_NaN() : *std::max_element(ulps.begin(), ulps.end());
  row.t_relerr_p99 = nearest_rank_percentile(relerrs, 0.99);
  row.t_relerr_max =
      relerrs.empty() ? std::numeric_limits<double>::quiet_NaN() : *std::max_element(relerrs.begin(), relerrs.end());
}

void judge_occlusion(std::span<const Ray> rays, std::span<const RefereeVerdict> truth,
                     std::span<const std::uint8_t> occluded, AccuracyRow& row) {
  count_truth(rays, truth, row);
  std::size_t false_miss = 0, false_hit = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    false_miss += truth[i].hit() && !occluded[i];
    false_hit += !truth[i].hit() && occluded[i];
  }
  row.false_miss = fraction(false_miss, rays.size());
  row.false_hit = fraction(false_hit, rays.size());
  row.wrong_prim = 0.0;
}

}  // namespace raybench
