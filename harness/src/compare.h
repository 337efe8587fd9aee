// Comparing two results CSVs (`raybench compare`) and gating on them
// (`raybench gate`). Rows are matched by (scene, rayset, backend, threads).
//
// Throughput is noisy: a change gets a verdict only when it is both large
// (at least min_effect, relative) and unlikely to be noise (two-sided exact
// Mann–Whitney U test on the per-repetition samples both runs recorded,
// p < alpha). The ratio to Embree measured in the same run is compared the
// same way, on each run's samples divided by that run's Embree median; it
// survives a change of machine or a noisy neighbour, so it is what CI gates.
// Agreement and accuracy columns are deterministic for the same rays and
// code: any change is reported as it is, without statistics.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace raybench {

struct ResultsFile {
  std::string path;
  std::vector<std::map<std::string, std::string>> rows;
  std::map<std::string, std::string> metadata;  // from the .meta.toml beside it; empty if absent
};

// Reads a results CSV and its metadata; throws InputError naming the file.
ResultsFile read_results_file(const std::string& path);

// Several independent runs of the same suite as one baseline: each row's
// repetitions are concatenated, with every run's samples rescaled by (pooled
// Embree median / that run's Embree median) so that each sample's ratio to
// Embree stays the ratio measured within its own run. Deterministic columns
// and metadata come from the first run; rows absent from it are dropped.
// One run is returned unchanged.
ResultsFile pool_runs(const std::vector<ResultsFile>& runs);

// Metadata keys whose difference makes absolute throughput incomparable.
const std::vector<std::string>& machine_keys();
// "key: base vs new" for each machine key that differs (or is missing).
std::vector<std::string> machine_differences(const ResultsFile& base, const ResultsFile& current);

enum class Verdict { kSame, kFaster, kSlower, kUnsure, kNotApplicable };
std::string to_string(Verdict v);

struct SampleComparison {
  double base = 0, current = 0;  // medians
  double change = 0;             // current / base - 1
  double p_value = 1;
  Verdict verdict = Verdict::kNotApplicable;
};

struct DeterministicChange {
  std::string column, base, current;
};

struct RowComparison {
  std::string scene, rayset, backend, threads;
  bool same_rays = true;  // the `rays` column matches
  SampleComparison throughput;
  SampleComparison ratio;  // ratio to Embree; kNotApplicable for the embree rows
  std::vector<DeterministicChange> changes;
  std::map<std::string, std::string> base_row, current_row;
};

struct CompareOptions {
  double alpha = 0.05;
  double min_effect = 0.05;
};

struct Comparison {
  std::vector<RowComparison> rows;
  std::vector<std::string> only_in_base, only_in_current;  // "scene/rayset/backend/threads"
};

Comparison compare_results(const ResultsFile& base, const ResultsFile& current, const CompareOptions& options);

enum class OutputFormat { kTable, kMarkdown, kJson };
std::string format_comparison(const Comparison& c, const ResultsFile& base, const ResultsFile& current,
                              OutputFormat format, bool colour);

// Gate thresholds (results/gate.toml; see README "Gating CI").
struct GateConfig {
  double max_ratio_drop = 0.10;       // relative drop of ratio_to_embree ...
  double alpha = 0.01;                // ... that the U test also calls real
  double max_agree_hit_drop = 1e-4;   // absolute
  double max_agree_prim_drop = 1e-3;  // absolute
  double min_agree_hit = 0.999;       // floor for every row of a non-seed backend
  std::vector<std::string> no_new_leaks{"watertight"};  // backends (by substring) whose leaks may not grow
  bool fail_on_missing_rows = true;   // a baseline row absent from the current run fails
};

// Throws InputError naming the file and key on a bad config.
GateConfig load_gate_config(const std::string& path);

struct GateResult {
  std::vector<std::string> failures;  // one line each: which row, what, by how much
  std::vector<std::string> notes;
};

// With several current runs (independent processes of the same build), a
// throughput regression counts only when every run shows it for the same
// row: a real slowdown reproduces, a one-process fluke (memory placement, a
// noisy neighbour) rarely hits the same row twice. Deterministic columns are
// checked on the first run.
GateResult run_gate(const ResultsFile& baseline, const std::vector<ResultsFile>& currents, const GateConfig& config);

}  // namespace raybench
