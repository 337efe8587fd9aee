// Specification of the exact Mann–Whitney U test (harness/src/mann_whitney.h),
// with p-values counted by hand from the C(n1+n2, n1) equally likely splits.
#include "mann_whitney.h"

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

TEST(MannWhitney, EmptyOrTooLargeSamples) {
  EXPECT_DOUBLE_EQ(mann_whitney_u(std::vector<double>{}, std::vector<double>{1}).p_value, 1.0);
  const std::vector<double> many(30, 1.0);
  EXPECT_THROW(mann_whitney_u(many, many), std::invalid_argument);
  const std::vector<double> x(28, 1.0), y(28, 2.0);
  EXPECT_LT(mann_whitney_u(x, y).p_value, 1e-10);  // 28 vs 28 still counted exactly
}

}  // namespace
}  // namespace raybench
