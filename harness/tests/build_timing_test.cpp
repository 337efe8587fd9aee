// Specification of interleaved build timing (harness/src/build_timing.h).
#include "build_timing.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "procedural.h"

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
  }
  std::size_t memory_bytes() const override { return 0; }
  void intersect(std::span<const Ray>, std::span<Hit>) const override {}
  void occluded(std::span<const Ray>, std::span<std::uint8_t>) const override {}
  std::size_t triangles_ = 0;
  int arena_threads_ = 0;

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
