// The Wilcoxon signed-rank test, one-sided: do paired differences tend to
// lie below zero? The within-run gate (compare.h) asks it of the log ratios
// candidate / reference of each interleaved round: a candidate slower than
// its reference gives negative log ratios in most rounds.
//
// W+ is the sum of the ranks of |d| over the positive differences d, with
// midranks for tied |d|; differences that are exactly 0 are dropped first
// (Wilcoxon's method; scipy.stats.wilcoxon's zero_method="wilcox"), so n is
// the number of non-zero differences. Under "the differences are symmetric
// about 0" each of the 2^n sign assignments is equally likely, and
//   p = P(W+ <= observed W+)   (alternative: below zero).
//
// Exact up to n = 50 nonzero differences: the 2^n sign assignments are
// counted by dynamic programming over doubled midranks (so ties are exact
// too); counts stay below 2^53 and the counting takes n^2 (n + 1) steps.
// Beyond that, the normal approximation with the tie correction of the
// variance and a continuity correction of 1/2 (as scipy.stats.wilcoxon with
// method="approx", correction=True, alternative="less"):
//   mu = n (n + 1) / 4,  sigma^2 = n (n + 1) (2n + 1) / 24 - sum(t^3 - t) / 48
//   z = (W+ - mu - sign(W+ - mu) / 2) / sigma,  p = Phi(z)
// where t runs over the sizes of the groups of tied |d|.
//
// The smallest p that n differences can give is 2^-n (every one negative),
// so fewer than signed_rank_min_pairs(alpha) rounds never reach p < alpha.
#pragma once

#include <cstddef>
#include <span>

namespace raybench {

struct SignedRank {
  double w_plus = 0;    // rank sum of the positive differences
  std::size_t n = 0;    // non-zero differences (zeros dropped)
  double p_value = 1;   // one-sided, alternative "below zero"; 1 when n = 0
  bool exact = true;    // false: the normal approximation
};

// Largest n counted exactly.
inline constexpr std::size_t kSignedRankExactMax = 50;

// Exact where n <= kSignedRankExactMax, else the normal approximation.
// The differences must not be NaN.
SignedRank signed_rank_less(std::span<const double> differences);

// The two regimes on their own (tests compare them where both apply).
// signed_rank_exact_less throws std::invalid_argument beyond kSignedRankExactMax.
SignedRank signed_rank_exact_less(std::span<const double> differences);
SignedRank signed_rank_normal_less(std::span<const double> differences);

// The fewest non-zero pairs whose smallest possible p (2^-n) is below alpha.
std::size_t signed_rank_min_pairs(double alpha);

}  // namespace raybench
