// Tracing a whole ray set with a backend on N threads. Every backend is
// driven the same way: the rays are cut into fixed chunks, handed to TBB
// workers of one arena, and each chunk is one virtual call into the backend.
#pragma once

#include <functional>
#include <memory>
#include <span>

#include <tbb/task_arena.h>

#include "backends/backend.h"

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
  // Runs f inside the arena, so that builds also use exactly `threads` threads.
  void run(const std::function<void()>& f) const;

 private:
  int threads_;
  std::unique_ptr<tbb::task_arena> arena_;
};

}  // namespace raybench
