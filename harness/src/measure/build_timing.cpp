#include "measure/build_timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "measure/page_residency.h"

namespace raybench {

namespace {

// Milliseconds that `builds` builds of one backend take, in one run of the executor.
double time_builds(Backend& backend, const Scene& scene, const TraceExecutor& executor, int builds) {
  const auto start = std::chrono::steady_clock::now();
  executor.run([&] {
    for (int i = 0; i < builds; ++i) backend.build(scene);
  });
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::vector<std::vector<double>> time_builds_interleaved(std::span<Backend* const> backends, const Scene& scene,
                                                         const TraceExecutor& executor, int repetitions,
                                                         double min_seconds,
                                                         std::vector<std::optional<std::size_t>>* huge_page_bytes) {
  // The warm-up build, untimed in the results, says how many builds fill min_seconds.
  std::vector<int> builds_per_sample(backends.size());
  if (huge_page_bytes) huge_page_bytes->assign(backends.size(), std::nullopt);
  for (std::size_t b = 0; b < backends.size(); ++b) {
    const std::optional<std::size_t> huge_before = huge_page_bytes ? anon_huge_page_bytes() : std::nullopt;
    const double warm_up_ms = time_builds(*backends[b], scene, executor, 1);
    if (huge_before) {
      const std::optional<std::size_t> huge_after = anon_huge_page_bytes();
      if (huge_after) (*huge_page_bytes)[b] = *huge_after > *huge_before ? *huge_after - *huge_before : 0;
    }
    const double fit = warm_up_ms > 0.0 ? std::ceil(min_seconds * 1e3 / warm_up_ms) : kMaxBuildsPerSample;
    builds_per_sample[b] = static_cast<int>(std::clamp(fit, 1.0, static_cast<double>(kMaxBuildsPerSample)));
  }
  std::vector<std::vector<double>> ms(backends.size());
  for (int round = 0; round < std::max(1, repetitions); ++round) {
    for (std::size_t b = 0; b < backends.size(); ++b) {
      const int builds = builds_per_sample[b];
      ms[b].push_back(time_builds(*backends[b], scene, executor, builds) / builds);
    }
  }
  return ms;
}

}  // namespace raybench
