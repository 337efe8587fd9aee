// The Mann–Whitney U test (Wilcoxon rank-sum), two-sided.
//
// The p-value is the probability, under "both samples come from one
// distribution", of a rank sum at least as far from its mean as observed.
//
// Exact where exact and affordable: the splits of the pooled midranks are
// counted, all C(n1+n2, m) of them (m the smaller sample's size), by dynamic
// programming over doubled midranks, so ties are exact too. Exact counting is
// what small benchmark samples need; the normal approximation is poor there.
// Counts are doubles, exact while C(n1+n2, m) <= 2^53; the counting takes
// about m (n1+n2)^3 steps, kept under 2e7 (milliseconds). Both hold up to
// 28 vs 28 values and, for instance, 5 vs 150.
//
// Beyond that (e.g. 30 vs 30 repetitions: C(60, 30) ~ 1.2e17 > 2^53) the
// normal approximation, with the tie correction of the variance and a
// continuity correction of 1/2 (as scipy.stats.mannwhitneyu with
// method="asymptotic", use_continuity=True):
//   mu = n1 n2 / 2,  sigma^2 = n1 n2 / 12 * ((n + 1) - sum(t^3 - t) / (n (n - 1)))
//   z = max(0, |U - mu| - 1/2) / sigma,  p = erfc(z / sqrt 2)
// where t runs over the sizes of the groups of tied values.
#pragma once

#include <cstddef>
#include <span>

namespace raybench {

struct MannWhitney {
  double u = 0;        // U of the first sample: pairs (x, y) with x > y, ties counting 1/2
  double p_value = 1;  // two-sided; 1 when either sample is empty or every value is tied
  bool exact = true;   // false: the normal approximation
};

// The exact test where mann_whitney_exact_affordable, else the normal approximation.
// The values must not be NaN (they are ranked; compare.h refuses such samples).
MannWhitney mann_whitney_u(std::span<const double> x, std::span<const double> y);

// Whether samples of these sizes are counted exactly (see above).
bool mann_whitney_exact_affordable(std::size_t n1, std::size_t n2);

// The two regimes on their own (tests compare them where both apply).
// mann_whitney_exact throws std::invalid_argument when the sizes are not affordable.
MannWhitney mann_whitney_exact(std::span<const double> x, std::span<const double> y);
MannWhitney mann_whitney_normal(std::span<const double> x, std::span<const double> y);

}  // namespace raybench
