#include "mann_whitney.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace raybench {

MannWhitney mann_whitney_u(std::span<const double> x, std::span<const double> y) {
  MannWhitney result;
  const std::size_t n1 = x.size(), n2 = y.size(), n = n1 + n2;
  if (n1 == 0 || n2 == 0) return result;
  if (n > 56) throw std::invalid_argument("mann_whitney_u: at most 56 values in all");
  for (double a : x)
    for (double b : y) result.u += a > b ? 1.0 : (a == b ? 0.5 : 0.0);

  // Doubled midranks (integers): tied values share the mean of their ranks.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  const auto value = [&](std::size_t i) { return i < n1 ? x[i] : y[i - n1]; };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return value(a) < value(b); });
  std::vector<int> rank2(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && value(order[j + 1]) == value(order[i])) ++j;
    const int doubled = static_cast<int>(i + 1 + j + 1);  // 2 * mean of ranks i+1 .. j+1
    for (std::size_t k = i; k <= j; ++k) rank2[order[k]] = doubled;
    i = j + 1;
  }
  int observed = 0, total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    total += rank2[i];
    if (i < n1) observed += rank2[i];
  }
  // ways[k][s]: subsets of k of the pooled values whose doubled ranks sum to s.
  std::vector<std::vector<double>> ways(n1 + 1, std::vector<double>(static_cast<std::size_t>(total) + 1, 0.0));
  ways[0][0] = 1.0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = std::min(i + 1, n1); k >= 1; --k)
      for (int s = total; s >= rank2[i]; --s) ways[k][s] += ways[k - 1][s - rank2[i]];
  const double mean = static_cast<double>(n1) * static_cast<double>(n + 1);  // doubled: 2 * n1 (n + 1) / 2
  const double distance = std::fabs(observed - mean);
  double extreme = 0.0, all = 0.0;
  for (int s = 0; s <= total; ++s) {
    all += ways[n1][s];
    if (std::fabs(s - mean) >= distance - 1e-9) extreme += ways[n1][s];
  }
  result.p_value = std::min(1.0, extreme / all);
  return result;
}

}  // namespace raybench
