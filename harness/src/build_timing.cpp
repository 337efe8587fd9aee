#include "build_timing.h"

#include <algorithm>
#include <chrono>

namespace raybench {

std::vector<std::vector<double>> time_builds_interleaved(std::span<Backend* const> backends, const Scene& scene,
                                                         const TraceExecutor& executor, int repetitions) {
  for (Backend* backend : backends) executor.run([&] { backend->build(scene); });
  std::vector<std::vector<double>> ms(backends.size());
  for (int round = 0; round < std::max(1, repetitions); ++round) {
    for (std::size_t b = 0; b < backends.size(); ++b) {
      const auto start = std::chrono::steady_clock::now();
      executor.run([&] { backends[b]->build(scene); });
      ms[b].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
  }
  return ms;
}

}  // namespace raybench
