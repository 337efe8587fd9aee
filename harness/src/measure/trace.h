// Tracing a whole ray set with a backend on N threads. Every backend is
// driven the same way: the rays are cut into fixed chunks, handed to TBB
// workers of one arena, and each chunk is one virtual call into the backend.
// Guarantee: every ray is traced exactly once and its answer written to the
// same index of the output; no more than `threads` threads trace.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include <tbb/task_arena.h>

#include "backends/backend.h"
#include "rays/screening.h"

namespace raybench {

class TraceExecutor {
 public:
  // Rays per chunk: large enough that the virtual call and task overhead
  // vanish, small enough to balance two threads on incoherent rays.
  static constexpr std::size_t kChunk = 1024;

  explicit TraceExecutor(int threads);
  int threads() const { return threads_; }

  void intersect(const Backend& backend, std::span<const Ray> rays, std::span<Hit> hits) const;
  void occluded(const Backend& backend, std::span<const Ray> rays, std::span<std::uint8_t> occluded) const;
  // The answers that count (untimed: agreement, the referee, `raybench
  // trace`): every ray of a screened set traced, and the answers of the rays
  // screened out forced to misses (rays/screening.h).
  std::vector<Hit> answers(const Backend& backend, const ScreenedRays& rays) const;
  std::vector<std::uint8_t> occlusion_answers(const Backend& backend, const ScreenedRays& rays) const;
  // Runs f inside the arena, so that builds also use exactly `threads` threads.
  void run(const std::function<void()>& f) const;

 private:
  int threads_;
  std::unique_ptr<tbb::task_arena> arena_;
};

}  // namespace raybench
