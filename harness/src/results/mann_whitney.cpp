#include "results/mann_whitney.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace raybench {
namespace {

// The pooled sample (x first, then y) ranked: doubled midranks (integers:
// tied values share the mean of their ranks) and the sizes of the groups of
// tied values.
struct Ranks {
  std::vector<std::int64_t> rank2;
  std::vector<std::size_t> tie_groups;
  std::int64_t x_sum2 = 0;  // doubled rank sum of x
};

Ranks rank(std::span<const double> x, std::span<const double> y) {
  const std::size_t n1 = x.size(), n = x.size() + y.size();
  const auto value = [&](std::size_t i) { return i < n1 ? x[i] : y[i - n1]; };
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return value(a) < value(b); });
  Ranks r;
  r.rank2.resize(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && value(order[j + 1]) == value(order[i])) ++j;
    const auto doubled = static_cast<std::int64_t>(i + 1 + j + 1);  // 2 * mean of ranks i+1 .. j+1
    for (std::size_t k = i; k <= j; ++k) r.rank2[order[k]] = doubled;
    r.tie_groups.push_back(j - i + 1);
    i = j + 1;
  }
  for (std::size_t i = 0; i < n1; ++i) r.x_sum2 += r.rank2[i];
  return r;
}

// U of x from its rank sum: R1 - n1 (n1 + 1) / 2 (midranks count a tie 1/2).
double u_of(const Ranks& r, std::size_t n1) {
  return static_cast<double>(r.x_sum2) / 2.0 - static_cast<double>(n1) * static_cast<double>(n1 + 1) / 2.0;
}

// C(n, m) in floating point (only compared with 2^53).
double binomial(std::size_t n, std::size_t m) {
  double c = 1.0;
  for (std::size_t i = 1; i <= m; ++i) c = c * static_cast<double>(n - m + i) / static_cast<double>(i);
  return c;
}

}  // namespace

bool mann_whitney_exact_affordable(std::size_t n1, std::size_t n2) {
  const std::size_t m = std::min(n1, n2), n = n1 + n2;
  if (m == 0) return true;
  // 2^53: the largest count a double holds exactly along with every smaller one.
  if (binomial(n, m) > 9007199254740992.0) return false;
  // The counting's steps: n values x m subset sizes x n (n + 1) doubled rank sums.
  return static_cast<double>(m) * static_cast<double>(n) * static_cast<double>(n) * static_cast<double>(n + 1) <= 2e7;
}

MannWhitney mann_whitney_exact(std::span<const double> x, std::span<const double> y) {
  MannWhitney result;
  const std::size_t n1 = x.size(), n2 = y.size(), n = n1 + n2;
  if (n1 == 0 || n2 == 0) return result;
  if (!mann_whitney_exact_affordable(n1, n2))
    throw std::invalid_argument("mann_whitney_exact: samples too large to count exactly");
  const Ranks r = rank(x, y);
  result.u = u_of(r, n1);
  // Count subsets of the smaller sample's size m; the test is two-sided and
  // symmetric, so either sample's rank sum gives the same p-value.
  const bool count_x = n1 <= n2;
  const std::size_t m = count_x ? n1 : n2;
  std::int64_t total = 0;
  for (std::int64_t v : r.rank2) total += v;
  const std::int64_t observed = count_x ? r.x_sum2 : total - r.x_sum2;
  // ways[k][s]: subsets of k of the pooled values whose doubled ranks sum to s.
  const auto sums = static_cast<std::size_t>(total) + 1;
  std::vector<std::vector<double>> ways(m + 1, std::vector<double>(sums, 0.0));
  ways[0][0] = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto step = static_cast<std::size_t>(r.rank2[i]);
    for (std::size_t k = std::min(i + 1, m); k >= 1; --k)
      for (std::size_t s = sums - 1; s >= step; --s) ways[k][s] += ways[k - 1][s - step];
  }
  const double mean = static_cast<double>(m) * static_cast<double>(n + 1);  // doubled: 2 * m (n + 1) / 2
  const double distance = std::fabs(static_cast<double>(observed) - mean);
  double extreme = 0.0, all = 0.0;
  for (std::size_t s = 0; s < sums; ++s) {
    all += ways[m][s];
    if (std::fabs(static_cast<double>(s) - mean) >= distance - 1e-9) extreme += ways[m][s];
  }
  result.p_value = std::min(1.0, extreme / all);
  return result;
}

MannWhitney mann_whitney_normal(std::span<const double> x, std::span<const double> y) {
  MannWhitney result;
  result.exact = false;
  const std::size_t n1 = x.size(), n2 = y.size();
  if (n1 == 0 || n2 == 0) return result;
  const Ranks r = rank(x, y);
  result.u = u_of(r, n1);
  const double n = static_cast<double>(n1 + n2), product = static_cast<double>(n1) * static_cast<double>(n2);
  double ties = 0.0;
  for (std::size_t t : r.tie_groups) ties += std::pow(static_cast<double>(t), 3.0) - static_cast<double>(t);
  const double variance = product / 12.0 * ((n + 1.0) - (n > 1.0 ? ties / (n * (n - 1.0)) : 0.0));
  if (!(variance > 0.0)) return result;  // every value tied: p = 1
  const double z = std::max(0.0, std::fabs(result.u - product / 2.0) - 0.5) / std::sqrt(variance);
  result.p_value = std::min(1.0, std::erfc(z / std::sqrt(2.0)));
  return result;
}

MannWhitney mann_whitney_u(std::span<const double> x, std::span<const double> y) {
  return mann_whitney_exact_affordable(x.size(), y.size()) ? mann_whitney_exact(x, y) : mann_whitney_normal(x, y);
}

}  // namespace raybench
