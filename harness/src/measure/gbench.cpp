#include "measure/gbench.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include <fmt/format.h>

namespace raybench {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
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

double CollectingReporter::convert(double per_second) const { return scale_ > 0 ? per_second * scale_ : 1e9 / per_second; }

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
    std::cerr << fmt::format("raybench:   [{}/{}] {}: {:.3g} {} (median of {})", ++done_, total_, name, m, unit_,
                             it == samples_.end() ? 0 : it->second.size())
              << std::endl;
  }
}

const std::vector<double>& CollectingReporter::samples(const std::string& name) const {
  if (const auto e = errors_.find(name); e != errors_.end())
    throw std::runtime_error(name + ": benchmark failed: " + e->second);
  const auto it = samples_.find(name);
  if (it == samples_.end() || it->second.empty()) throw std::runtime_error(name + ": benchmark produced no measurement");
  return it->second;
}

}  // namespace raybench
