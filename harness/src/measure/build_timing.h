// Build times measured the way traces are: interleaved. Every backend is first
// built once untimed (the warm-up: first-touch page faults, allocator pools,
// TBB workers waking), then each of `repetitions` rounds builds every backend
// once, in turn. A noisy neighbour then slows all backends of a round alike,
// so the ratio of two backends' medians stays fair; timed back to back, one
// backend's builds could all fall into a quiet second and another's into a
// busy one.
// A build shorter than the minimum time is repeated within its round, as
// often as its warm-up build says fits (at most kMaxBuildsPerSample times),
// and the round's sample is their mean, as a trace repetition lasts at least
// --min-time: a single sub-millisecond build reads the timer's and the
// scheduler's noise.
// Guarantee: every backend is timed in every round, in the same order; a
// sample is the mean of at least one and at most kMaxBuildsPerSample builds.
// observed: docs/notes/harness-measurement.md
#pragma once

#include <cstddef>
#include <optional>
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
// With `huge_page_bytes`, it gets per backend how much the process's
// anonymous memory in huge pages grew across its warm-up build
// (page_residency.h; nullopt where unreadable): for a backend not built
// before, the part of the structure it keeps that landed in huge pages.
std::vector<std::vector<double>> time_builds_interleaved(std::span<Backend* const> backends, const Scene& scene,
                                                         const TraceExecutor& executor, int repetitions,
                                                         double min_seconds = 0.0,
                                                         std::vector<std::optional<std::size_t>>* huge_page_bytes = nullptr);

}  // namespace raybench
