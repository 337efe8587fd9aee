// Specification of the one-sided Wilcoxon signed-rank test (results/signed_rank.h)
// that the within-run gate asks of paired log ratios: exact p-values as the
// published tables of the signed-rank statistic's lower-tail probabilities
// give them (the one-sided 5 % critical values of n = 10, 15, 20: 10, 30,
// 60), ties counted exactly, zeros dropped, and the normal approximation
// beyond 50 pairs (its value computed by hand from the formula).
#include "results/signed_rank.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace raybench {
namespace {

// n differences with ranks 1..n (no ties), negative except those of `positive_ranks`.
std::vector<double> with_positive_ranks(int n, const std::vector<int>& positive_ranks) {
  std::vector<double> d;
  for (int k = 1; k <= n; ++k) d.push_back(-k);
  for (int k : positive_ranks) d[k - 1] = k;
  return d;
}

TEST(SignedRank, ExactTailProbabilitiesAreThoseOfThePublishedTables) {
  // P(W+ <= T): n = 10, T = 10 is 43/1024 = 0.0420 (the one-sided 5 % critical value);
  // T = 11 is 54/1024 = 0.0527, just above it.
  SignedRank r = signed_rank_exact_less(with_positive_ranks(10, {10}));
  EXPECT_EQ(r.w_plus, 10);
  EXPECT_EQ(r.n, 10u);
  EXPECT_DOUBLE_EQ(r.p_value, 43.0 / 1024);
  EXPECT_DOUBLE_EQ(signed_rank_exact_less(with_positive_ranks(10, {5, 6})).p_value, 54.0 / 1024);
  // n = 15, T = 30: 1550/32768 = 0.0473; n = 20, T = 60: 51017/1048576 = 0.0487.
  EXPECT_DOUBLE_EQ(signed_rank_exact_less(with_positive_ranks(15, {1, 2, 12, 15})).p_value, 1550.0 / 32768);
  EXPECT_DOUBLE_EQ(signed_rank_exact_less(with_positive_ranks(20, {20, 19, 18, 3})).p_value, 51017.0 / 1048576);
  // n = 6, T = 2: 3/64; n = 8, T = 5: 10/256.
  EXPECT_DOUBLE_EQ(signed_rank_exact_less(with_positive_ranks(6, {2})).p_value, 3.0 / 64);
  EXPECT_DOUBLE_EQ(signed_rank_exact_less(with_positive_ranks(8, {5})).p_value, 10.0 / 256);
}

TEST(SignedRank, EveryDifferenceNegativeGivesTheSmallestPossibleP) {
  for (int n : {1, 5, 7, 12}) EXPECT_DOUBLE_EQ(signed_rank_exact_less(with_positive_ranks(n, {})).p_value, std::ldexp(1.0, -n));
  // All positive: the other tail, p = 1.
  EXPECT_DOUBLE_EQ(signed_rank_exact_less(std::vector<double>{1, 2, 3}).p_value, 1.0);
  // alpha 0.01 needs 7 pairs (2^-7 = 0.0078), 0.05 needs 5 (0.031), 0.03125 needs 6.
  EXPECT_EQ(signed_rank_min_pairs(0.01), 7u);
  EXPECT_EQ(signed_rank_min_pairs(0.05), 5u);
  EXPECT_EQ(signed_rank_min_pairs(0.03125), 6u);
}

TEST(SignedRank, TiesShareMidranksAndAreCountedExactly) {
  // |d| ranks 1, 2.5, 2.5, 4, 5, 6; W+ = 4 (the 3). Sign assignments with
  // W+ <= 4, by hand: {}, {1}, {2.5}, {2.5'}, {1, 2.5}, {1, 2.5'}, {4}: 7 of 64.
  const SignedRank r = signed_rank_exact_less(std::vector<double>{-1, -2, -2, 3, -4, -5});
  EXPECT_EQ(r.w_plus, 4);
  EXPECT_DOUBLE_EQ(r.p_value, 7.0 / 64);
}

TEST(SignedRank, ZerosAreDropped) {
  // 0.5 ranks 1; the three -1 share 3; 2 ranks 5, -3 ranks 6: W+ = 6, 14 of 64.
  const SignedRank r = signed_rank_exact_less(std::vector<double>{0.5, -1, -1, -1, 2, -3, 0});
  EXPECT_EQ(r.n, 6u);
  EXPECT_EQ(r.w_plus, 6);
  EXPECT_DOUBLE_EQ(r.p_value, 14.0 / 64);
  EXPECT_DOUBLE_EQ(signed_rank_less(std::vector<double>{0, 0, 0}).p_value, 1.0);
  EXPECT_DOUBLE_EQ(signed_rank_less(std::vector<double>{}).p_value, 1.0);
}

TEST(SignedRank, BeyondFiftyPairsTheNormalApproximationDecides) {
  // 60 differences (-1)^k (k + 1) - 5 (one of them 0): W+ = 730 of n = 59,
  // p = Phi((730 - 885 + 0.5) / sqrt(17552.5 - tie correction)), computed by hand: 0.12177.
  std::vector<double> d;
  for (int k = 0; k < 60; ++k) d.push_back((k % 2 ? -1.0 : 1.0) * (k + 1) - 5);
  const SignedRank r = signed_rank_less(d);
  EXPECT_FALSE(r.exact);
  EXPECT_EQ(r.n, 59u);
  EXPECT_EQ(r.w_plus, 730);
  EXPECT_NEAR(r.p_value, 0.1217727397937809, 1e-12);
  EXPECT_THROW(signed_rank_exact_less(d), std::invalid_argument);
  // At 50 pairs both regimes apply, and agree closely.
  std::vector<double> fifty;
  for (int k = 1; k <= 50; ++k) fifty.push_back(k % 3 == 0 ? k : -k);
  const SignedRank exact = signed_rank_less(fifty), normal = signed_rank_normal_less(fifty);
  EXPECT_TRUE(exact.exact);
  EXPECT_NEAR(exact.p_value, normal.p_value, 0.002);
}

}  // namespace
}  // namespace raybench
