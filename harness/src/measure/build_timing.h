// Build times measured the way traces are: interleaved. Every backend is first
// built once untimed (the warm-up: first-touch page faults, allocator pools,
// TBB workers waking), then each of `repetitions` rounds builds every backend
// once, in turn. A noisy neighbour then slows all backends of a round alike,
// so the ratio of two backends' medians stays fair; timed back to back, one
// backend's builds could all fall into a quiet second and another's into a
// busy one (the scorecard saw the same default build read 25.8 and 33.1 ms).
// A build shorter than the minimum time is repeated within its round, as
// often as its warm-up build says fits (at most kMaxBuildsPerSample times),
// and the round's sample is their mean, as a trace repetition lasts at least
// --min-time: a single sub-millisecond build reads the timer's and the
// scheduler's noise (the small meshes' build ratios moved by 10-20 % between
// rounds, and flipped the scorecard's build targets from run to run).
#pragma once

#include <span>
#include <vector>

#include "backends/backend.h"
#include "scene/scene.h"
#include "measure/trace.h"

namespace raybench {

inline constexpr int kMaxBuildsPerSample = 1000;

// Wall-clock milliseconds per build, per backend (outer, as given) and round
// (inner; max(1, repetitions) of them): each the mean of the builds the round
// timed for that backend, enough to last about min_seconds. Each backend
// keeps the tree of its last build.
std::vector<std::vector<double>> time_builds_interleaved(std::span<Backend* const> backends, const Scene& scene,
                                                         const TraceExecutor& executor, int repetitions,
                                                         double min_seconds = 0.0);

}  // namespace raybench
