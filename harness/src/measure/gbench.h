// What the suite runner and the kernel microbenchmarks share of Google
// Benchmark: one initialisation per process, and a reporter that keeps every
// repetition of every case (not only Google Benchmark's aggregates), so that
// medians, ranges and later noise-aware comparisons use the raw samples.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

namespace raybench {

double median(std::vector<double> samples);

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

}  // namespace raybench
