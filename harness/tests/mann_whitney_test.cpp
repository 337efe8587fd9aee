// Specification of the Mann–Whitney U test (harness/src/results/mann_whitney.h):
// exact p-values counted by hand from the C(n1+n2, n1) equally likely splits,
// and the normal approximation beyond, against values worked out apart from
// raybench (the formulas below, and an enumeration in Python's exact
// fractions for 28 vs 28).
#include "results/mann_whitney.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace raybench {
namespace {

TEST(MannWhitney, CompletelySeparatedSamples) {
  // 3 vs 3: of C(6,3) = 20 splits, only the two extremes are as far out.
  const std::vector<double> low{1, 2, 3}, high{4, 5, 6};
  const MannWhitney r = mann_whitney_u(low, high);
  EXPECT_DOUBLE_EQ(r.u, 0.0);
  EXPECT_DOUBLE_EQ(r.p_value, 2.0 / 20.0);
  EXPECT_DOUBLE_EQ(mann_whitney_u(high, low).u, 9.0);
  // 5 vs 5: 2 of C(10,5) = 252; the smallest p five repetitions can give.
  EXPECT_DOUBLE_EQ(mann_whitney_u(std::vector<double>{1, 2, 3, 4, 5}, std::vector<double>{6, 7, 8, 9, 10}).p_value, 2.0 / 252.0);
}

TEST(MannWhitney, InterleavedSamplesAreNotSignificant) {
  const std::vector<double> x{1, 3, 5, 7}, y{2, 4, 6, 8};
  const MannWhitney r = mann_whitney_u(x, y);
  EXPECT_DOUBLE_EQ(r.u, 6.0);  // pairs with x > y: 0 + 1 + 2 + 3
  EXPECT_GT(r.p_value, 0.5);
}

TEST(MannWhitney, TiesAreCountedExactly) {
  // All values equal: every split has the same rank sum, p = 1.
  EXPECT_DOUBLE_EQ(mann_whitney_u(std::vector<double>{2, 2, 2}, std::vector<double>{2, 2}).p_value, 1.0);
  // x = {1, 2}, y = {2, 3}: midranks 1, 2.5, 2.5, 4; x's sum 3.5, mean 5.
  // Splits (6 in all) with |sum - 5| >= 1.5: {1, 2.5} twice and {2.5, 4} twice.
  const MannWhitney r = mann_whitney_u(std::vector<double>{1, 2}, std::vector<double>{2, 3});
  EXPECT_DOUBLE_EQ(r.u, 0.5);
  EXPECT_DOUBLE_EQ(r.p_value, 4.0 / 6.0);
}

TEST(MannWhitney, EmptySamplesAreNotSignificant) {
  EXPECT_DOUBLE_EQ(mann_whitney_u(std::vector<double>{}, std::vector<double>{1}).p_value, 1.0);
  EXPECT_DOUBLE_EQ(mann_whitney_u(std::vector<double>{1}, std::vector<double>{}).p_value, 1.0);
}

TEST(MannWhitney, UpTo28Vs28TheSplitsAreCountedExactly) {
  EXPECT_TRUE(mann_whitney_exact_affordable(28, 28));  // C(56, 28) ~ 7.6e15 <= 2^53
  EXPECT_TRUE(mann_whitney_exact_affordable(5, 150));  // the smaller sample sets the count
  const std::vector<double> x(28, 1.0), y(28, 2.0);
  const MannWhitney separated = mann_whitney_u(x, y);
  EXPECT_TRUE(separated.exact);
  EXPECT_DOUBLE_EQ(separated.p_value, 2.0 / 7648690600760440.0);  // 2 / C(56, 28)
  // y = x + 6.5, x = 0 .. 27: 0.007813133754126305 by enumerating every split
  // in exact fractions (Python).
  std::vector<double> a, b;
  for (int i = 0; i < 28; ++i) a.push_back(i), b.push_back(i + 6.5);
  const MannWhitney shifted = mann_whitney_u(a, b);
  EXPECT_TRUE(shifted.exact);
  EXPECT_NEAR(shifted.p_value, 0.007813133754126305, 1e-15);
  EXPECT_DOUBLE_EQ(shifted.u, 231.0);
}

TEST(MannWhitney, BeyondThatTheNormalApproximationIsUsed) {
  // 30 vs 30 repetitions (`--reps 30`): C(60, 30) ~ 1.2e17 > 2^53.
  EXPECT_FALSE(mann_whitney_exact_affordable(30, 30));
  EXPECT_FALSE(mann_whitney_exact_affordable(5, 1000));  // ~5e9 counting steps
  std::vector<double> low, high;
  for (int i = 1; i <= 30; ++i) low.push_back(i), high.push_back(i + 30);
  EXPECT_THROW(mann_whitney_exact(low, high), std::invalid_argument);
  // Separated, no ties: U = 0, mu = 450, sigma^2 = 30 * 30 * 61 / 12 = 4575,
  // z = (450 - 0.5) / sqrt(4575) = 6.64559922588161, p = erfc(z / sqrt 2).
  const MannWhitney r = mann_whitney_u(low, high);
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 0.0);
  EXPECT_NEAR(r.p_value, 3.019859359162151e-11, 1e-20);
  EXPECT_NEAR(mann_whitney_u(high, low).p_value, 3.019859359162151e-11, 1e-20);  // two-sided
}

TEST(MannWhitney, TheNormalApproximationCorrectsForTies) {
  // x = 1 x10, 2 x10, 3 x10; y = 2 x10, 3 x10, 4 x10. U = 100 (x = 3 > y = 2)
  // + 200 ties / 2 = 200; tie groups 10, 20, 20, 10: sum(t^3 - t) = 17940;
  // sigma^2 = 900 / 12 * (61 - 17940 / (60 * 59)) = 4194.915254237288;
  // z = (250 - 0.5) / sigma = 3.8522011286216014, p = 0.00011706080954085454.
  std::vector<double> x, y;
  for (int v = 1; v <= 3; ++v)
    for (int k = 0; k < 10; ++k) x.push_back(v), y.push_back(v + 1);
  const MannWhitney r = mann_whitney_u(x, y);
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 200.0);
  EXPECT_NEAR(r.p_value, 0.00011706080954085454, 1e-15);
  // Every value tied: no evidence of a difference at all.
  const std::vector<double> same(40, 1.0);
  EXPECT_DOUBLE_EQ(mann_whitney_u(same, same).p_value, 1.0);
}

TEST(MannWhitney, TheTwoRegimesAgreeWhereBothApply) {
  // At 28 vs 28 the approximation is what the exact count gives, to 10 % at
  // p ~ 0.01 and 1 % at p ~ 0.1: the switch to it does not move a verdict
  // much. Exact values from the enumeration in Python, as above.
  std::vector<double> a, near, far;
  for (int i = 0; i < 28; ++i) a.push_back(i), far.push_back(i + 6.5), near.push_back(i + 3.5);
  EXPECT_NEAR(mann_whitney_normal(a, far).p_value, 0.008536288888245017, 1e-15);
  EXPECT_NEAR(mann_whitney_normal(a, far).p_value / mann_whitney_exact(a, far).p_value, 1.0, 0.10);
  EXPECT_NEAR(mann_whitney_exact(a, near).p_value, 0.134580461474354, 1e-14);
  EXPECT_NEAR(mann_whitney_normal(a, near).p_value, 0.13377101125482163, 1e-15);
  EXPECT_NEAR(mann_whitney_normal(a, near).p_value / mann_whitney_exact(a, near).p_value, 1.0, 0.01);
}

}  // namespace
}  // namespace raybench
