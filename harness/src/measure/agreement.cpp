// Per-ray agreement of a backend with a reference (measure/agreement.h):
// hit/miss, primitive and t compared ray by ray; a different primitive at
// the same float t, or at the same t as the referee ties hits, is counted as
// a tie as well.
#include "measure/agreement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "referee/referee.h"

namespace raybench {

double nearest_rank_percentile(std::vector<double>& values, double p) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto rank = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(p * values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + rank, values.end());
  return values[rank];
}

Agreement compare_hits(std::span<const Hit> tested, std::span<const Hit> reference, std::span<const Ray> rays,
                       std::span<const Triangle> triangles) {
  return compare_hits(tested, reference, rays, PrimitiveSpans{triangles, {}, {}, {}});
}

Agreement compare_hits(std::span<const Hit> tested, std::span<const Hit> reference, std::span<const Ray> rays,
                       const PrimitiveSpans& prims) {
  const bool exact_ties = !rays.empty() && prims.size() > 0;
  // A prim outside the scene (a backend's bug) is never a tie, and never indexes past it.
  const auto in_scene = [&](std::int32_t prim) { return prim >= 0 && static_cast<std::size_t>(prim) < prims.size(); };
  Agreement a;
  a.has_prims = true;
  a.rays = tested.size();
  std::vector<double> relerr;
  for (std::size_t i = 0; i < tested.size(); ++i) {
    const Hit& t = tested[i];
    const Hit& r = reference[i];
    a.hits += t.hit();
    if (t.hit() != r.hit()) continue;
    ++a.same_hit;
    if (!t.hit()) continue;
    ++a.both_hit;
    if (t.prim == r.prim) ++a.same_prim;
    else if (t.t == r.t || (exact_ties && in_scene(t.prim) && in_scene(r.prim) &&
                            same_t(rays[i], prims, static_cast<std::size_t>(t.prim), static_cast<std::size_t>(r.prim))))
      ++a.prim_ties;
    const double diff = std::fabs(static_cast<double>(t.t) - r.t);
    relerr.push_back(r.t != 0.0f ? diff / std::fabs(static_cast<double>(r.t)) : diff);
  }
  if (!relerr.empty()) {
    a.t_relerr_p999 = nearest_rank_percentile(relerr, 0.999);
    a.t_relerr_max = *std::max_element(relerr.begin(), relerr.end());
  }
  return a;
}

Agreement compare_occlusion(std::span<const std::uint8_t> tested, std::span<const std::uint8_t> reference) {
  Agreement a;
  a.rays = tested.size();
  for (std::size_t i = 0; i < tested.size(); ++i) {
    a.hits += tested[i] != 0;
    a.same_hit += (tested[i] != 0) == (reference[i] != 0);
  }
  return a;
}

}  // namespace raybench
