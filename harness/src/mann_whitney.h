// The Mann–Whitney U test (Wilcoxon rank-sum), two-sided, exact.
//
// The p-value is the probability, under "both samples come from one
// distribution", of a rank sum at least as far from its mean as observed.
// It is computed exactly by counting, over all C(n1+n2, n1) ways to split
// the pooled midranks, the splits with such a sum (dynamic programming over
// doubled midranks, so ties are exact too). Exact counting is what small
// benchmark samples (5 to 30 repetitions) need; the normal approximation is
// poor there. Counts are doubles: exact up to C(56, 28) ~ 7.6e15 < 2^53.
#pragma once

#include <span>

namespace raybench {

struct MannWhitney {
  double u = 0;        // U of the first sample: pairs (x, y) with x > y, ties counting 1/2
  double p_value = 1;  // two-sided; 1 when either sample is empty
};

// Throws std::invalid_argument when the samples total more than 56 values.
MannWhitney mann_whitney_u(std::span<const double> x, std::span<const double> y);

}  // namespace raybench
