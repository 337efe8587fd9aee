// Comparing two results CSVs (`raybench compare`) and gating on them
// (`raybench gate`). Rows are matched by (scene, rayset, backend, threads),
// through hash maps: linear in the number of rows.
//
// Throughput is noisy: a change gets a verdict only when it is both large
// (at least min_effect, relative) and unlikely to be noise (two-sided
// Mann–Whitney U test on the per-repetition samples both runs recorded,
// p < alpha; exact where affordable, see mann_whitney.h). The ratio to the
// run's reference backend (ResultsFile::reference: `embree` unless the run
// chose another) is compared the same way, on each run's ratio samples; it
// survives a change of machine or a noisy neighbour, so it is what CI gates.
// A run timed in rounds (metadata timing = "rounds") pairs its samples: its
// ratio samples are row sample i / reference sample i, of the same round, so
// noise that hits both cancels; older runs give samples / reference median.
// Agreement and accuracy columns are deterministic for the same rays and
// code: any change is reported as it is, without statistics. What compare
// and gate refuse as unreadable: the rule above read_results_file.
//
// The gate has two modes: against a baseline run (run_gate), and within one
// run, candidates against the run's reference (run_within_run_gate; the
// referee's counts are judged in accuracy/accuracy_gate.h). Both give
// GateFailures, written as text lines or as JSON (format_gate_json).
#pragma once

#include <cstddef>
#include <limits>
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
  // The backend every ratio of this file is relative to: the metadata's
  // `reference_backend`, else the rows' `reference` column, else "embree"
  // (files older than --reference).
  std::string reference = "embree";
  // Metadata timing = "rounds": sample i of every row of a scene comes from
  // the same interleaved round, so ratios pair sample by sample.
  bool paired = false;
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
//   - metadata whose `status` is neither "partial" nor "complete";
//   - a row whose `reference` column names another backend than the
//     metadata's reference_backend (or than another row's, without metadata);
//   - in a file timed in rounds, a row with another number of samples than
//     its reference row (the samples could not pair round by round).
//   Bad input, compare and gate alike: two files whose references differ
//   (compare_results, naming both).
//   Bad input, the gate's baseline only (pool_runs, run_gate): a row of a
//   backend other than the reference without the reference's row of its
//   scene, ray set and threads: its ratio, what the gate checks, has no
//   reference (the baseline must be measured with its reference backend).
//   FAIL, the gate's current runs (run_gate), besides the regressions of
//   GateConfig: a baseline row whose reference row is absent from a current
//   run (its ratio cannot be checked there, whatever fail_on_missing_rows says);
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
// repetitions are concatenated, with every sample rescaled so that its ratio
// to the pooled reference median is the ratio measured within its own run:
// by (pooled reference median / that run's reference median), or, in a run
// timed in rounds, by (pooled reference median / the reference's sample of
// the same round), which keeps each pair's ratio. The pooled file is then
// not `paired`. Deterministic columns and metadata come from the first run;
// rows absent from it are dropped. One run is returned unchanged. Throws
// InputError naming the run when a row of a backend other than the reference
// lacks its reference row, or when two runs' references differ.
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
  SampleComparison ratio;  // ratio to the reference; kNotApplicable on the reference's rows
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

// Throws InputError naming both files when their references differ.
Comparison compare_results(const ResultsFile& base, const ResultsFile& current, const CompareOptions& options);

// --format json: {"base", "current", "reference_backend", "rows": [...],
// "only_in_base", "only_in_current", "notes"}. Each row has scene, rayset,
// backend, threads, "reference" (true on the reference backend's rows),
// same_rays, changes, and comparisons {base, current, change, p_value,
// verdict}: "mrays_s", "ratio_to_reference" and "ratio_to_embree" (the same
// as ratio_to_reference when the reference is embree; not made otherwise).
// The reference rows' ratio is what the CSV says, 1 in both runs: {base 1,
// current 1, change 0, p_value null, verdict "reference"}. A comparison not
// made (different ray counts, another reference) has null numbers and
// verdict "-".
enum class OutputFormat { kTable, kMarkdown, kJson };
std::string format_comparison(const Comparison& c, const ResultsFile& base, const ResultsFile& current,
                              OutputFormat format, bool colour);

// Gate thresholds (results/gate.toml; see docs/gating.md).
struct GateConfig {
  double max_ratio_drop = 0.10;       // relative drop of the ratio to the reference ...
  double alpha = 0.01;                // ... that the U (or, within a run, signed-rank) test also calls real
  double max_agree_hit_drop = 1e-4;   // absolute
  double max_agree_prim_drop = 1e-3;  // absolute
  double min_agree_hit = 0.999;       // floor for every row of a non-seed backend
  std::vector<std::string> no_new_leaks{"watertight"};  // backends (by substring) whose leaks may not grow
  bool fail_on_missing_rows = true;   // a baseline row absent from the current run fails
};

// Throws InputError naming the file and key on a bad config.
GateConfig load_gate_config(const std::string& path);

// A number a failed check does not have.
inline constexpr double kNoNumber = std::numeric_limits<double>::quiet_NaN();

// One failed check of one row. `message` is the line the gate prints after
// "FAIL: " (it begins with the row); the numbers are NaN where a check has
// none (JSON null). See docs/gating.md for what each check's numbers hold.
struct GateFailure {
  std::string scene, rayset, backend;
  std::string threads;  // "" for accuracy rows (one thread)
  std::string check;    // speed | agree_hit | agree_prim | leaks | referee | missing | rays
  std::string message;
  std::string kind;     // referee: false_miss | false_hit | wrong_prim | self_hits; else ""
  double value = kNoNumber;    // the gated row's: ratio median, agreement, leaks, error count
  double against = kNoNumber;  // what it is held to: the baseline's or the reference row's
  double change = kNoNumber;   // speed: relative change of the ratio
  double p_value = kNoNumber;  // speed: the test's p
  double limit = kNoNumber;    // the config's threshold for this check
};

// The within-run gate's speed measurement of one candidate row (--verbose).
struct PairedSpeed {
  std::string scene, rayset, backend, threads;
  std::size_t rounds = 0;
  double ratio = 0, ratio_min = 0, ratio_max = 0;  // median and range of the paired ratios
  double p_value = 1;                              // one-sided signed-rank test: slower than the reference
};

struct GateResult {
  std::string mode = "runs";   // runs | within-run
  std::string reference;       // the reference backend of the ratios
  std::vector<GateFailure> failures;
  std::vector<std::string> notes;
  std::vector<PairedSpeed> speeds;  // within-run: every candidate row measured
};

// The within-run gate's speeds as an aligned table (gate --verbose).
std::string format_paired_speeds(const GateResult& g);

// With several current runs (independent processes of the same build), a
// throughput regression counts only when every run shows it for the same
// row: a real slowdown reproduces, a one-process fluke (memory placement, a
// noisy neighbour) rarely hits the same row twice. Deterministic columns are
// checked on the first run. Throws InputError when the baseline lacks an
// Embree row (see the rules above).
// Throws InputError when the baseline lacks a reference row (see the rules
// above) or a current run's reference differs from the baseline's.
GateResult run_gate(const ResultsFile& baseline, const std::vector<ResultsFile>& currents, const GateConfig& config);

// The gate within one run: each candidate backend's rows against the run's
// reference rows of the same scene, ray set and threads. FAIL (GateFailure
// check):
//   - speed: the paired ratios candidate / reference of the rounds have a
//     median below 1 - max_ratio_drop AND the one-sided signed-rank test on
//     their logs gives p < alpha (signed_rank.h). Fewer rounds than the test
//     needs to ever reach alpha give a note, not a failure;
//   - agree_hit, agree_prim: lower than the reference row's by more than
//     max_agree_hit_drop / max_agree_prim_drop, or empty where the
//     reference's is not;
//   - leaks: more than the reference row's (or empty where it is not);
//   - missing: a candidate's or the reference's row absent for a scene, ray
//     set and threads that the run has (a note instead with
//     fail_on_missing_rows = false);
//   - rays: the two rows traced different ray counts;
//   - missing, without a row: the run is partial (metadata status =
//     "partial": it stopped before its last scene, perhaps by a candidate's
//     crash), so the rows of its unfinished scenes cannot be judged.
// Bad input (InputError): a run not timed in rounds ("re-run with this
// raybench"), a candidate the run does not have (listing those it has), the
// reference given as a candidate, no candidate.
GateResult run_within_run_gate(const ResultsFile& run, const std::vector<std::string>& candidates,
                               const GateConfig& config);

// The same over several runs (independent processes of the same builds): as
// in run_gate, a speed failure counts only when every run shows it for the
// same row (a note names the rows slower in some runs only); every other
// check is the first run's. Throws InputError when the runs' references
// differ.
GateResult run_within_run_gate(const std::vector<ResultsFile>& runs, const std::vector<std::string>& candidates,
                               const GateConfig& config);

// The gate's verdicts as JSON (docs/gating.md): {"verdict", "mode",
// "reference", "current", "baseline", "candidates", "failures", "notes"}.
std::string format_gate_json(const GateResult& g, const std::vector<std::string>& currents,
                             const std::vector<std::string>& baselines, const std::vector<std::string>& candidates);

// A JSON string literal and number (null when not finite), for the JSON
// writers of compare and gate.
std::string json_string(const std::string& s);
std::string json_number(double v);

}  // namespace raybench
