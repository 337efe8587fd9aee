// The Google Benchmark glue (measure/gbench.h): one initialisation per
// process, a reporter that keeps every repetition's raw sample, and timing
// in rounds.
#include "measure/gbench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "io/interrupt.h"
#include "scene/random.h"

namespace raybench {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double paired_median_ratio(const std::vector<double>& samples, const std::vector<double>& reference) {
  if (samples.empty() || samples.size() != reference.size()) return std::nan("");
  std::vector<double> ratios(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!(reference[i] > 0)) return std::nan("");
    ratios[i] = samples[i] / reference[i];
  }
  return median(std::move(ratios));
}

void initialize_google_benchmark(const std::vector<std::string>& flags) {
  static bool initialized = false;
  if (initialized) return;
  initialized = true;
  static std::vector<std::string> storage;  // argv must outlive the library's use of it
  storage = {"raybench"};
  storage.insert(storage.end(), flags.begin(), flags.end());
  static std::vector<char*> argv;
  for (std::string& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  int argc = static_cast<int>(storage.size());
  benchmark::Initialize(&argc, argv.data());
}

CollectingReporter::CollectingReporter(std::string counter, double scale, std::string unit, std::size_t total_cases)
    : counter_(std::move(counter)), unit_(std::move(unit)), scale_(scale), total_(total_cases) {}

namespace {

// A rate per second in the unit kept: times scale, or (scale 0) 1e9 / rate.
double convert_rate(double per_second, double scale) { return scale > 0 ? per_second * scale : 1e9 / per_second; }

}  // namespace

double CollectingReporter::convert(double per_second) const { return convert_rate(per_second, scale_); }

void CollectingReporter::ReportRuns(const std::vector<Run>& runs) {
  for (const Run& run : runs) {
    if (run.run_type != Run::RT_Iteration) continue;
    const std::string& name = run.run_name.function_name;
    if (run.error_occurred) {
      errors_[name] = run.error_message;
      continue;
    }
    samples_[name].push_back(convert(run.counters.at(counter_).value));
  }
  // Google Benchmark reports a case twice: its repetitions, then aggregates.
  if (!runs.empty() && runs.front().run_type == Run::RT_Iteration) {
    const std::string& name = runs.front().run_name.function_name;
    const auto it = samples_.find(name);
    const double m = it == samples_.end() ? std::nan("") : median(it->second);
    print_stderr_line(fmt::format("raybench:   [{}/{}] {}: {:.3g} {} (median of {})", ++done_, total_, name, m, unit_,
                                    it == samples_.end() ? 0 : it->second.size()));
  }
}

const std::vector<double>& CollectingReporter::samples(const std::string& name) const {
  if (const auto e = errors_.find(name); e != errors_.end())
    throw std::runtime_error(name + ": benchmark failed: " + e->second);
  const auto it = samples_.find(name);
  if (it == samples_.end() || it->second.empty()) throw std::runtime_error(name + ": benchmark produced no measurement");
  return it->second;
}

namespace {

// One round's single repetition of every case: its sample and the iteration
// count it ran, or the error it reported.
class RoundReporter : public benchmark::BenchmarkReporter {
 public:
  RoundReporter(const std::string& counter, double scale) : counter_(counter), scale_(scale) {}
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration) continue;
      const std::string& name = run.run_name.function_name;
      if (run.error_occurred) {
        errors[name] = run.error_message;
        continue;
      }
      const auto counter = run.counters.find(counter_);
      if (counter == run.counters.end()) {
        errors[name] = "no counter '" + counter_ + "'";
        continue;
      }
      results[name] = {convert_rate(counter->second.value, scale_), run.iterations};
    }
  }
  void Finalize() override {}

  std::map<std::string, std::pair<double, benchmark::IterationCount>> results;
  std::map<std::string, std::string> errors;

 private:
  std::string counter_;
  double scale_;
};

}  // namespace

std::vector<std::size_t> round_order(std::size_t n, std::uint64_t seed, int round) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  Rng rng(seed, static_cast<std::uint64_t>(round), 0);  // one stream per round (scene/random.h)
  for (std::size_t i = n; i > 1; --i) {
    // An unbiased index in [0, i): reject the top remainder of the 64-bit range.
    const std::uint64_t limit = ~std::uint64_t{0} - (~std::uint64_t{0} % i);
    std::uint64_t x = rng.next_u64();
    while (x >= limit) x = rng.next_u64();
    std::swap(order[i - 1], order[static_cast<std::size_t>(x % i)]);
  }
  return order;
}

std::vector<std::vector<double>> run_rounds(const std::vector<RoundCase>& cases, const RoundSettings& settings,
                                            const std::function<void(int round, double seconds)>& after_round) {
  std::vector<std::vector<double>> samples(cases.size());
  std::vector<benchmark::IterationCount> iterations(cases.size(), 0);
  if (cases.empty()) return samples;  // Google Benchmark would complain of no benchmark to run
  for (int round = 0; round < settings.rounds; ++round) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::size_t> order(cases.size());
    if (settings.shuffle) order = round_order(cases.size(), settings.seed, round);
    else std::iota(order.begin(), order.end(), std::size_t{0});
    benchmark::ClearRegisteredBenchmarks();
    for (const std::size_t i : order) {
      benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(cases[i].name.c_str(), cases[i].body);
      b->Repetitions(1)->UseRealTime()->Unit(benchmark::kMillisecond);
      if (round == 0) b->MinTime(settings.min_time)->MinWarmUpTime(settings.warmup);
      else b->Iterations(iterations[i]);
    }
    RoundReporter reporter(settings.counter, settings.scale);
    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::ClearRegisteredBenchmarks();
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const std::string& name = cases[i].name;
      if (const auto e = reporter.errors.find(name); e != reporter.errors.end())
        throw std::runtime_error(name + ": benchmark failed: " + e->second);
      const auto r = reporter.results.find(name);
      if (r == reporter.results.end()) throw std::runtime_error(name + ": benchmark produced no measurement");
      samples[i].push_back(r->second.first);
      if (round == 0) iterations[i] = std::max<benchmark::IterationCount>(1, r->second.second);
    }
    if (after_round)
      after_round(round, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return samples;
}

}  // namespace raybench
