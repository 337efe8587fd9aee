// Running a suite: load scenes, make or reuse the stored ray sets, build every
// backend, measure agreement with Embree per ray, time tracing through Google
// Benchmark, and write the results CSV with its metadata.
#pragma once

#include <string>
#include <vector>

#include "results/results_csv.h"
#include "suite/suite.h"

namespace raybench {

struct RunOptions {
  Suite suite;
  SuiteSettings settings;            // the suite's defaults with command-line overrides applied
  std::vector<std::string> scenes;   // suite scene names or mesh paths; empty: every available suite scene
  std::string out_csv;
  std::string rays_dir;              // where ray sets are stored and reused
  bool raysets_from_command_line = false;  // settings.raysets then override each scene's own list
  bool interleave = true;            // interleave repetitions of all cases of a scene
  std::string command_line;          // recorded in the metadata
  // When set, every ray is also judged by the exact referee and the accuracy
  // CSV (accuracy/accuracy_csv.h) is written here, with its throughput taken
  // from this run's timing (the first thread count).
  std::string accuracy_csv;
};

// The baseline every backend's agreement and speed ratio are measured
// against (not the exact referee, which is the backend named "reference").
inline constexpr const char* kReferenceBackend = "embree";

// Runs the suite and writes the CSV, its .meta.toml and a table on stdout.
// Throws InputError on bad input, before any benchmark runs where possible.
std::vector<ResultRow> run_suite(const RunOptions& options);

// The aligned per-scene table printed at the end of a run.
std::string format_results_table(const std::vector<ResultRow>& rows);

}  // namespace raybench
