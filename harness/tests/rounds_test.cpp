// Specification of timing in rounds (harness/src/measure/gbench.h): round r
// runs every case exactly once, in a reproducible shuffled order, so that
// sample r of every case comes from the same round; and the paired ratio.
#include "measure/gbench.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

namespace raybench {
namespace {

// Every case records its name whenever Google Benchmark runs it; the order
// of first appearances within a round is the order the round ran.
struct Recorder {
  std::vector<std::string> calls;
  std::vector<RoundCase> cases(std::size_t n) {
    std::vector<RoundCase> out;
    for (std::size_t i = 0; i < n; ++i) {
      const std::string name = "case" + std::to_string(i);
      out.push_back({name, [this, name, i](benchmark::State& state) {
                       if (calls.empty() || calls.back() != name) calls.push_back(name);
                       for (auto _ : state) benchmark::DoNotOptimize(i);
                       state.counters["items"] =
                           benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
                     }});
    }
    return out;
  }
};

RoundSettings quick(int rounds, bool shuffle) {
  initialize_google_benchmark({"--benchmark_enable_random_interleaving=false"});
  RoundSettings s;
  s.rounds = rounds;
  s.min_time = 0.001;
  s.warmup = 0.0;
  s.shuffle = shuffle;
  s.seed = 42;
  s.counter = "items";
  return s;
}

TEST(RoundOrder, IsAPermutationThatDependsOnlyOnTheSeedAndTheRound) {
  for (const std::size_t n : {0u, 1u, 2u, 7u, 40u}) {
    for (int round = 0; round < 5; ++round) {
      std::vector<std::size_t> order = round_order(n, 9, round);
      EXPECT_EQ(order, round_order(n, 9, round));
      std::sort(order.begin(), order.end());
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(order[i], i);
    }
  }
  // Different rounds and seeds give different orders (40! orders: equal by chance never).
  EXPECT_NE(round_order(40, 9, 0), round_order(40, 9, 1));
  EXPECT_NE(round_order(40, 9, 0), round_order(40, 10, 0));
}

TEST(RoundOrder, PutsEveryCaseFirstAboutEquallyOften) {
  std::vector<int> first(4, 0);
  for (int round = 0; round < 4000; ++round) ++first[round_order(4, 1, round)[0]];
  for (const int f : first) EXPECT_NEAR(f, 1000, 150);
}

TEST(RunRounds, EveryRoundRunsEveryCaseOnceInThatRoundsOrder) {
  Recorder recorder;
  const std::vector<RoundCase> cases = recorder.cases(3);
  std::vector<int> rounds_done;
  const auto samples = run_rounds(cases, quick(4, true), [&](int round, double seconds) {
    rounds_done.push_back(round);
    EXPECT_GE(seconds, 0.0);
  });
  EXPECT_EQ(rounds_done, (std::vector<int>{0, 1, 2, 3}));
  ASSERT_EQ(samples.size(), 3u);
  for (const auto& s : samples) {
    ASSERT_EQ(s.size(), 4u);
    for (const double x : s) EXPECT_GT(x, 0.0);
  }
  std::vector<std::string> expected;
  for (int round = 0; round < 4; ++round)
    for (const std::size_t i : round_order(3, 42, round)) expected.push_back(cases[i].name);
  // Consecutive rounds may end and start with the same case: compare with that run merged.
  expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
  EXPECT_EQ(recorder.calls, expected);
}

TEST(RunRounds, WithoutShufflingEveryRoundRunsTheCasesInTheirOrder) {
  Recorder recorder;
  const auto samples = run_rounds(recorder.cases(3), quick(2, false));
  EXPECT_EQ(recorder.calls, (std::vector<std::string>{"case0", "case1", "case2", "case0", "case1", "case2"}));
  for (const auto& s : samples) EXPECT_EQ(s.size(), 2u);
}

TEST(RunRounds, NoCasesIsNoSamples) {
  int rounds = 0;
  EXPECT_TRUE(run_rounds({}, quick(3, true), [&](int, double) { ++rounds; }).empty());
  EXPECT_EQ(rounds, 0);
}

TEST(RunRounds, ACaseThatFailsIsAnErrorNamingIt) {
  std::vector<RoundCase> cases{{"fails", [](benchmark::State& state) {
                                  for (auto _ : state) {
                                  }
                                  state.SkipWithError("no luck");
                                }}};
  try {
    run_rounds(cases, quick(1, true));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("fails: benchmark failed: no luck"), std::string::npos) << e.what();
  }
}

TEST(PairedMedianRatio, IsTheMedianOfThePerRoundRatios) {
  // Per round: 2, 0.5, 3 -> median 2; the ratio of the medians would be 12 / 6.
  EXPECT_DOUBLE_EQ(paired_median_ratio({12, 3, 30}, {6, 6, 10}), 2.0);
  EXPECT_DOUBLE_EQ(paired_median_ratio({1, 2, 3, 4}, {1, 2, 3, 4}), 1.0);
  EXPECT_DOUBLE_EQ(paired_median_ratio({2, 6}, {1, 2}), 2.5);  // even count: mean of the middle two
  EXPECT_TRUE(std::isnan(paired_median_ratio({}, {})));
  EXPECT_TRUE(std::isnan(paired_median_ratio({1, 2}, {1})));
  EXPECT_TRUE(std::isnan(paired_median_ratio({1, 2}, {1, 0})));
}

}  // namespace
}  // namespace raybench
