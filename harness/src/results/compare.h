// Comparing two results CSVs (`raybench compare`) and gating on them
// (`raybench gate`). Rows are matched by (scene, rayset, backend, threads),
// through hash maps: linear in the number of rows.
//
// Throughput is noisy: a change gets a verdict only when it is both large
// (at least min_effect, relative) and unlikely to be noise (two-sided
// Mann–Whitney U test on the per-repetition samples both runs recorded,
// p < alpha; exact where affordable, see mann_whitney.h). The ratio to Embree
// measured in the same run is compared the same way, on each run's samples
// divided by that run's Embree median; it survives a change of machine or a
// noisy neighbour, so it is what CI gates. Agreement and accuracy columns are
// deterministic for the same rays and code: any change is reported as it is,
// without statistics. What compare and gate refuse as unreadable: the rule
// above read_results_file.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace raybench {

// A results file that `raybench run` wrote before its last scene was done
// (metadata status = "partial"): it holds the rows of the finished scenes.
struct PartialFile {
  std::string path;
  std::string progress;  // the metadata's `progress`, e.g. "2 of 5 scenes"; "" if absent
};

struct ResultsFile {
  std::string path;
  std::vector<std::map<std::string, std::string>> rows;
  std::vector<std::size_t> lines;               // each row's line in the file, for messages
  std::map<std::string, std::string> metadata;  // from the .meta.toml beside it; empty if absent
  std::vector<PartialFile> partial;             // this file if partial; pooled: every partial run
};

// What compare and gate refuse. Neither ever passes on a value it cannot read
// as a number. The rule: what makes a file unreadable as results is bad input
// (InputError, exit 2, naming the file, the row's line and key, and the
// column); what the current run's code could have caused is a FAIL of the
// gate (exit 1, naming the row).
//   Bad input, either file, compare and gate alike (read_results_file):
//   - a file without rows (a header only);
//   - an mrays_s_samples field that is empty, or has a sample that is not a
//     finite number > 0 (NaN, inf, 0, -3, '', 'abc');
//   - agree_hit that is not a number in [0, 1]; agree_prim likewise, where it
//     may be empty only on an occluded row (no primitive to compare);
//   - leaks that is neither empty nor a count (a whole number >= 0);
//   - two rows with the same (scene, rayset, backend, threads);
//   - metadata whose `status` is neither "partial" nor "complete".
//   Bad input, the gate's baseline only (pool_runs, run_gate): a row of a
//   backend other than Embree without the Embree row of its scene, ray set
//   and threads: its ratio to Embree, what the gate checks, has no reference
//   (the baseline must be measured with the embree backend).
//   FAIL, the gate's current runs (run_gate), besides the regressions of
//   GateConfig: a baseline row whose Embree row is absent from a current run
//   (its ratio cannot be checked there, whatever fail_on_missing_rows says);
//   agree_hit, agree_prim or leaks that the baseline recorded and the current
//   run left empty. A baseline is a reference someone chose and must
//   regenerate if it is wrong; a current run is the code under test, and what
//   it fails to record is its failure.
//   Partial files (a run still going or interrupted: metadata status =
//   "partial") are read; compare and gate print a note naming the file and
//   its progress.

// Reads a results CSV and its metadata, and checks every row (see the rules
// above); throws InputError naming the file, and the row and column.
ResultsFile read_results_file(const std::string& path);

// One line per partial file in `f`: "PATH is partial (PROGRESS): ...".
std::vector<std::string> partial_notes(const ResultsFile& f);

// Several independent runs of the same suite as one baseline: each row's
// repetitions are concatenated, with every run's samples rescaled by (pooled
// Embree median / that run's Embree median) so that each sample's ratio to
// Embree stays the ratio measured within its own run. Deterministic columns
// and metadata come from the first run; rows absent from it are dropped.
// One run is returned unchanged. Throws InputError naming the run when a row
// of a backend other than Embree lacks its Embree row (no ratio to Embree).
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
  // The matched rows, in the two ResultsFiles compared (which outlive this).
  const std::map<std::string, std::string>* base_row = nullptr;
  const std::map<std::string, std::string>* current_row = nullptr;
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

// --format json: {"base", "current", "rows": [...], "only_in_base", "only_in_current",
// "notes"}. Each row has scene, rayset, backend, threads, "reference" (true on
// the Embree rows, the reference of every ratio), same_rays, changes, and two
// comparisons {base, current, change, p_value, verdict}: "mrays_s" and
// "ratio_to_embree". The reference rows' ratio is what the CSV says, 1 in
// both runs: {base 1, current 1, change 0, p_value null, verdict "reference"}.
// A comparison not made (the runs traced different ray counts) has null
// numbers and verdict "-".
enum class OutputFormat { kTable, kMarkdown, kJson };
std::string format_comparison(const Comparison& c, const ResultsFile& base, const ResultsFile& current,
                              OutputFormat format, bool colour);

// Gate thresholds (results/gate.toml; see docs/gating.md).
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
// checked on the first run. Throws InputError when the baseline lacks an
// Embree row (see the rules above).
GateResult run_gate(const ResultsFile& baseline, const std::vector<ResultsFile>& currents, const GateConfig& config);

}  // namespace raybench
