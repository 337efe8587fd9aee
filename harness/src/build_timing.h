// Build times measured the way traces are: interleaved. Every backend is first
// built once untimed (the warm-up: first-touch page faults, allocator pools,
// TBB workers waking), then each of `repetitions` rounds builds every backend
// once, in turn. A noisy neighbour then slows all backends of a round alike,
// so the ratio of two backends' medians stays fair; timed back to back, one
// backend's builds could all fall into a quiet second and another's into a
// busy one (the scorecard saw the same default build read 25.8 and 33.1 ms).
#pragma once

#include <span>
#include <vector>

#include "backend.h"
#include "scene.h"
#include "trace.h"

namespace raybench {

// Wall-clock milliseconds per backend (outer, as given) and round (inner;
// max(1, repetitions) of them). Each backend keeps the tree of its last build.
std::vector<std::vector<double>> time_builds_interleaved(std::span<Backend* const> backends, const Scene& scene,
                                                         const TraceExecutor& executor, int repetitions);

}  // namespace raybench
