// TraceExecutor (measure/trace.h): chunks of at most kChunk rays, one
// virtual call each, on the workers of one TBB arena; every ray is traced
// once and its answer written to its own slot.
#include "measure/trace.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace raybench {

TraceExecutor::TraceExecutor(int threads)
    : threads_(threads < 1 ? 1 : threads), arena_(std::make_unique<tbb::task_arena>(threads_)) {}

void TraceExecutor::run(const std::function<void()>& f) const { arena_->execute(f); }

namespace {

template <typename Out, typename Call>
void chunked(tbb::task_arena& arena, int threads, std::span<const Ray> rays, std::span<Out> out, Call&& call) {
  if (threads == 1) {
    // One thread: the same chunks, in order, without scheduling overhead.
    for (std::size_t begin = 0; begin < rays.size(); begin += TraceExecutor::kChunk) {
      const std::size_t n = std::min(TraceExecutor::kChunk, rays.size() - begin);
      call(rays.subspan(begin, n), out.subspan(begin, n));
    }
    return;
  }
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, rays.size(), TraceExecutor::kChunk),
        [&](const tbb::blocked_range<std::size_t>& r) {
          call(rays.subspan(r.begin(), r.size()), out.subspan(r.begin(), r.size()));
        },
        tbb::simple_partitioner());
  });
}

}  // namespace

void TraceExecutor::intersect(const Backend& backend, std::span<const Ray> rays, std::span<Hit> hits) const {
  chunked(*arena_, threads_, rays, hits, [&](auto r, auto h) { backend.intersect(r, h); });
}

void TraceExecutor::occluded(const Backend& backend, std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
  chunked(*arena_, threads_, rays, occluded, [&](auto r, auto o) { backend.occluded(r, o); });
}

std::vector<Hit> TraceExecutor::answers(const Backend& backend, const ScreenedRays& rays) const {
  std::vector<Hit> hits(rays.rays.size());
  intersect(backend, rays.rays, hits);
  force_misses(rays, hits);
  return hits;
}

std::vector<std::uint8_t> TraceExecutor::occlusion_answers(const Backend& backend, const ScreenedRays& rays) const {
  std::vector<std::uint8_t> occ(rays.rays.size());
  occluded(backend, rays.rays, occ);
  force_misses(rays, occ);
  return occ;
}

}  // namespace raybench
