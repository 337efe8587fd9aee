// Microbenchmarks of every kernel variant in isolation (`raybench kernels`):
// nanoseconds per ray-primitive test on hit-heavy and miss-heavy inputs,
// scalar and 8-wide batched, timed with Google Benchmark. The inputs are
// classified by each family's most accurate variant, so the measured hit
// fraction also shows where a fast variant answers differently.
#pragma once

#include <string>
#include <vector>

namespace raybench {

struct KernelBenchOptions {
  std::string out_csv;
  std::string out_json;  // Google Benchmark's own JSON; empty: none
  std::string filter;    // substring of the case name; empty: all
  int repetitions = 5;
  double min_time = 0.05;
  std::size_t pairs = 4096;  // ray-primitive pairs per family and input
  std::string command_line;
};

struct KernelResult {
  std::string family, variant, form, input, accuracy;
  std::size_t tests_per_iteration = 0;
  double ns_per_test = 0, ns_min = 0, ns_max = 0;
  int reps = 0;
  std::vector<double> samples;
  // Of the timed tests, the fraction reported as hits. The batched triangle
  // form returns only the closest of its 8 lanes: there, the fraction of rays
  // with a hit.
  double hit_fraction = 0;
};

// Runs the microbenchmarks; writes the CSV (+ .meta.toml) and the JSON.
std::vector<KernelResult> run_kernel_benchmarks(const KernelBenchOptions& options);

std::string format_kernel_table(const std::vector<KernelResult>& results);

}  // namespace raybench
