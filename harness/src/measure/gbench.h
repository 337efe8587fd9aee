// What the suite runner and the kernel microbenchmarks share of Google
// Benchmark: one initialisation per process, a reporter that keeps every
// repetition of every case (not only Google Benchmark's aggregates), so that
// medians, ranges and later noise-aware comparisons use the raw samples, and
// timing in rounds (run_rounds), so that sample i of every case comes from
// the same stretch of time.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

namespace raybench {

double median(std::vector<double> samples);

// The median over i of samples[i] / reference[i]: a row's speed relative to
// another's when sample i of both comes from the same round (run_rounds).
// NaN when the two differ in length, are empty, or a reference sample is not
// positive.
double paired_median_ratio(const std::vector<double>& samples, const std::vector<double>& reference);

// Initialises Google Benchmark once with the given --benchmark_* flags.
void initialize_google_benchmark(const std::vector<std::string>& flags);

class CollectingReporter : public benchmark::BenchmarkReporter {
 public:
  // counter: the rate counter each case sets; scale converts its per-second
  // value into the unit kept (1e-6 for Mrays/s, or 0 for "1e9 / rate" = ns per item).
  CollectingReporter(std::string counter, double scale, std::string unit, std::size_t total_cases);

  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>& runs) override;
  void Finalize() override {}

  // Samples of a case, by the name it was registered under; throws
  // std::runtime_error when the case failed or produced none.
  const std::vector<double>& samples(const std::string& name) const;

 private:
  double convert(double per_second) const;

  std::string counter_, unit_;
  double scale_;
  std::size_t total_, done_ = 0;
  std::map<std::string, std::vector<double>> samples_;
  std::map<std::string, std::string> errors_;
};

// A case timed in rounds: Google Benchmark runs `body` as a benchmark named
// `name` (names are unique); `body` sets the rate counter RoundSettings names.
struct RoundCase {
  std::string name;
  std::function<void(benchmark::State&)> body;
};

struct RoundSettings {
  int rounds = 1;
  double min_time = 0.05;  // seconds a sample lasts at least (round 1; later rounds replay its iteration count)
  double warmup = 0.05;    // untimed seconds per case before its first sample (round 1 only)
  bool shuffle = true;     // each round in its own random order (round_order); false: the cases' order
  std::uint64_t seed = 0;  // the shuffles' seed
  std::string counter;     // the rate counter each case sets, converted as CollectingReporter does
  double scale = 1.0;
};

// The order in which round `round` (0-based) runs `n` cases: a Fisher-Yates
// shuffle driven by SplitMix64 from (seed, round), the same on every machine
// and every run with the same seed.
std::vector<std::size_t> round_order(std::size_t n, std::uint64_t seed, int round);

// Times every case once per round: round r runs each case exactly once, in
// round_order(cases.size(), seed, r) (or in order), as one Google Benchmark
// run of cases registered with one repetition each. Round 1 warms each case
// up and finds its iteration count the way Google Benchmark does for a first
// repetition (grow until a sample lasts min_time); later rounds replay that
// count without warm-up, as Google Benchmark does for later repetitions. So
// the samples of different cases with the same index are from the same round.
// Returns samples[case][round], in the counter's unit after `scale`.
// `after_round(r, seconds)` is called after each round (progress). Clears
// Google Benchmark's registered benchmarks before and after. Needs
// initialize_google_benchmark with random interleaving off (it would reorder
// a round). Throws std::runtime_error naming a case that failed.
std::vector<std::vector<double>> run_rounds(const std::vector<RoundCase>& cases, const RoundSettings& settings,
                                            const std::function<void(int round, double seconds)>& after_round = {});

}  // namespace raybench
