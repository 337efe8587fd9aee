// Specification of interleaved build timing (harness/src/measure/build_timing.h).
#include "measure/build_timing.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "scene/procedural.h"

namespace raybench {
namespace {

// Writes its name into a shared log each time it builds, and checks that it
// builds inside the executor's arena (on the given thread count).
class RecordingBackend final : public Backend {
 public:
  RecordingBackend(std::string name, std::vector<std::string>& log) : name_(std::move(name)), log_(log) {}
  const std::string& name() const override { return name_; }
  void build(const Scene& scene) override {
    log_.push_back(name_);
    triangles_ = scene.triangles.size();
    arena_threads_ = tbb::this_task_arena::max_concurrency();
    const auto start = std::chrono::steady_clock::now();
    std::this_thread::sleep_for(build_time_);
    build_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::size_t memory_bytes() const override { return 0; }
  void intersect(std::span<const Ray>, std::span<Hit>) const override {}
  void occluded(std::span<const Ray>, std::span<std::uint8_t>) const override {}
  std::size_t triangles_ = 0;
  int arena_threads_ = 0;
  std::chrono::microseconds build_time_{0};  // how long each build sleeps
  std::vector<double> build_ms_;              // how long each build took, as it measured itself

 private:
  std::string name_;
  std::vector<std::string>& log_;
};

TEST(BuildTiming, EveryBackendIsBuiltOnceUntimedThenOncePerRoundInTurn) {
  const Scene scene = make_procedural_scene("proc:sphere");
  std::vector<std::string> log;
  RecordingBackend a("a", log), b("b", log), c("c", log);
  const std::vector<Backend*> backends{&a, &b, &c};
  const TraceExecutor executor(1);
  const std::vector<std::vector<double>> ms = time_builds_interleaved(backends, scene, executor, 2);
  EXPECT_EQ(log, (std::vector<std::string>{"a", "b", "c", "a", "b", "c", "a", "b", "c"}));
  ASSERT_EQ(ms.size(), 3u);
  for (const std::vector<double>& samples : ms) {
    ASSERT_EQ(samples.size(), 2u) << "one sample per round, the warm-up not among them";
    for (double t : samples) EXPECT_GE(t, 0.0);
  }
  EXPECT_EQ(a.triangles_, scene.triangles.size());
}

TEST(BuildTiming, AtLeastOneRoundIsTimed) {
  const Scene scene = make_procedural_scene("proc:sphere");
  std::vector<std::string> log;
  RecordingBackend a("a", log);
  const std::vector<Backend*> backends{&a};
  const TraceExecutor executor(1);
  EXPECT_EQ(time_builds_interleaved(backends, scene, executor, 0).at(0).size(), 1u);
  EXPECT_EQ(log.size(), 2u);
}

// A build far shorter than the minimum time is timed many times per round
// (at most kMaxBuildsPerSample), one that takes as long or longer once, and
// one in between as often as its warm-up build says fits: each sample is the
// mean time of one build.
TEST(BuildTiming, ShortBuildsAreRepeatedWithinTheirRoundAndTheirMeanIsTheSample) {
  const Scene scene = make_procedural_scene("proc:sphere");
  std::vector<std::string> log;
  RecordingBackend fast("fast", log), medium("medium", log), slow("slow", log);
  medium.build_time_ = std::chrono::microseconds(5000);
  slow.build_time_ = std::chrono::microseconds(25000);
  // The slow backend first: its warm-up also starts the executor's workers.
  const std::vector<Backend*> backends{&slow, &medium, &fast};
  const std::vector<std::vector<double>> ms = time_builds_interleaved(backends, scene, TraceExecutor(1), 2, 0.02);
  const auto builds_of = [&](const std::string& name) { return std::count(log.begin(), log.end(), name); };
  // A warm-up build, then two rounds of k each.
  EXPECT_GT(builds_of("fast"), 1 + 2 * 4);
  EXPECT_LE(builds_of("fast"), 1 + 2 * kMaxBuildsPerSample);
  // The warm-up took at least 5 ms: at most ceil(20 / 5) = 4 per round, and more than one.
  EXPECT_GE(builds_of("medium"), 1 + 2 * 2);
  EXPECT_LE(builds_of("medium"), 1 + 2 * 4);
  EXPECT_EQ(builds_of("slow"), 1 + 2 * 1);
  ASSERT_EQ(ms.size(), 3u);
  for (const std::vector<double>& samples : ms) ASSERT_EQ(samples.size(), 2u) << "one sample per round";
  for (double t : ms[0]) EXPECT_GE(t, 25.0);
  for (double t : ms[1]) EXPECT_GE(t, 5.0);
  // The mean of one build, not the round's total: with k >= 2 builds in a
  // round, their mean is at most half their total (plus the executor's
  // overhead), as the backend measured its builds.
  const auto k = static_cast<std::size_t>(builds_of("medium") - 1) / 2;
  ASSERT_EQ(medium.build_ms_.size(), 1 + 2 * k);
  for (std::size_t round = 0; round < 2; ++round) {
    double total = 0.0;
    for (std::size_t i = 0; i < k; ++i) total += medium.build_ms_[1 + round * k + i];
    EXPECT_GE(ms[1][round], total / static_cast<double>(k));
    EXPECT_LT(ms[1][round], 0.75 * total) << "round " << round << ": the round's total, not its mean";
  }
}

TEST(BuildTiming, BuildsRunInTheExecutorsArenaOnItsThreadCount) {
  const Scene scene = make_procedural_scene("proc:sphere");
  std::vector<std::string> log;
  RecordingBackend a("a", log);
  const std::vector<Backend*> backends{&a};
  time_builds_interleaved(backends, scene, TraceExecutor(2), 1);
  EXPECT_EQ(a.arena_threads_, 2);
  time_builds_interleaved(backends, scene, TraceExecutor(1), 1);
  EXPECT_EQ(a.arena_threads_, 1);
}

}  // namespace
}  // namespace raybench
