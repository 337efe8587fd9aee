#include "results/signed_rank.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace raybench {
namespace {

// The non-zero differences ranked by |d|: doubled midranks (integers),
// which of them are positive, and the sizes of the groups of tied |d|.
struct Ranks {
  std::vector<std::int64_t> rank2;
  std::vector<bool> positive;
  std::vector<std::size_t> tie_groups;
  std::int64_t plus_sum2 = 0;  // doubled W+
};

Ranks rank(std::span<const double> differences) {
  std::vector<double> d;
  for (double v : differences)
    if (v != 0.0) d.push_back(v);
  const std::size_t n = d.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return std::fabs(d[a]) < std::fabs(d[b]); });
  Ranks r;
  r.rank2.resize(n);
  r.positive.resize(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && std::fabs(d[order[j + 1]]) == std::fabs(d[order[i]])) ++j;
    const auto doubled = static_cast<std::int64_t>(i + 1 + j + 1);  // 2 * mean of ranks i+1 .. j+1
    for (std::size_t k = i; k <= j; ++k) r.rank2[order[k]] = doubled;
    r.tie_groups.push_back(j - i + 1);
    i = j + 1;
  }
  for (std::size_t i = 0; i < n; ++i) {
    r.positive[i] = d[i] > 0;
    if (r.positive[i]) r.plus_sum2 += r.rank2[i];
  }
  return r;
}

}  // namespace

SignedRank signed_rank_exact_less(std::span<const double> differences) {
  const Ranks r = rank(differences);
  SignedRank result;
  result.n = r.rank2.size();
  result.w_plus = static_cast<double>(r.plus_sum2) / 2.0;
  if (result.n > kSignedRankExactMax) throw std::invalid_argument("signed_rank_exact_less: too many pairs to count exactly");
  if (result.n == 0) return result;
  // ways[s]: sign assignments whose positive doubled ranks sum to s.
  const std::int64_t total = std::accumulate(r.rank2.begin(), r.rank2.end(), std::int64_t{0});
  std::vector<double> ways(static_cast<std::size_t>(total) + 1, 0.0);
  ways[0] = 1.0;
  for (std::int64_t step : r.rank2)
    for (std::int64_t s = total; s >= step; --s) ways[static_cast<std::size_t>(s)] += ways[static_cast<std::size_t>(s - step)];
  double at_most = 0.0, all = 0.0;
  for (std::int64_t s = 0; s <= total; ++s) {
    all += ways[static_cast<std::size_t>(s)];
    if (s <= r.plus_sum2) at_most += ways[static_cast<std::size_t>(s)];
  }
  result.p_value = std::min(1.0, at_most / all);
  return result;
}

SignedRank signed_rank_normal_less(std::span<const double> differences) {
  const Ranks r = rank(differences);
  SignedRank result;
  result.exact = false;
  result.n = r.rank2.size();
  result.w_plus = static_cast<double>(r.plus_sum2) / 2.0;
  if (result.n == 0) return result;
  const double n = static_cast<double>(result.n);
  double ties = 0.0;
  for (std::size_t t : r.tie_groups) ties += std::pow(static_cast<double>(t), 3.0) - static_cast<double>(t);
  const double mean = n * (n + 1.0) / 4.0;
  const double variance = n * (n + 1.0) * (2.0 * n + 1.0) / 24.0 - ties / 48.0;
  if (!(variance > 0.0)) return result;
  const double offset = result.w_plus - mean;
  const double corrected = offset - (offset > 0 ? 0.5 : offset < 0 ? -0.5 : 0.0);
  result.p_value = std::min(1.0, 0.5 * std::erfc(-corrected / std::sqrt(variance) / std::sqrt(2.0)));
  return result;
}

SignedRank signed_rank_less(std::span<const double> differences) {
  const auto nonzero = static_cast<std::size_t>(
      std::count_if(differences.begin(), differences.end(), [](double v) { return v != 0.0; }));
  return nonzero <= kSignedRankExactMax ? signed_rank_exact_less(differences) : signed_rank_normal_less(differences);
}

std::size_t signed_rank_min_pairs(double alpha) {
  std::size_t n = 1;
  while (n < 1000 && !(std::ldexp(1.0, -static_cast<int>(n)) < alpha)) ++n;
  return n;
}

}  // namespace raybench
