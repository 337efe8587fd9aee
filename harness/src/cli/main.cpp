// raybench: how fast is a ray-tracing kernel, and how often is it wrong, next
// to Embree, on real meshes and the same rays. See README.md.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <sstream>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "accuracy/accuracy_gate.h"
#include "accuracy/kernel_accuracy.h"
#include "measure/agreement.h"
#include "build_info.h"
#include "backends/backend.h"
#include "results/compare.h"
#include "io/default_paths.h"
#include "io/error.h"
#include "io/atomic_file.h"
#include "io/input_file.h"
#include "io/interrupt.h"
#include "suite/kernel_bench.h"
#include "results/metadata.h"
#include "io/npy.h"
#include "scene/procedural.h"
#include "rays/rayset.h"
#include "rays/screening.h"
#include "scene/scene.h"
#include "scene/tessellate.h"
#include "suite/scene_selection.h"
#include "suite/settings_rules.h"
#include "suite/suite.h"
#include "suite/suite_run.h"
#include "measure/answer_check.h"
#include "measure/trace.h"

namespace raybench {
namespace {

// The source tree's files from the build tree, else the installed ones and
// the current directory (io/default_paths.h, docs/install.md).
const std::string kDefaultSuite = default_paths().suite;
const std::string kDefaultOut = default_paths().out_csv;
const std::string kDefaultRaysDir = default_paths().rays_dir;

// A scene argument is a suite scene's name or a mesh path / proc: spec.
struct SceneArg {
  Scene scene;
  const SuiteScene* entry = nullptr;
};

SceneArg resolve_scene(const std::string& arg, const Suite* suite) {
  SceneArg out;
  out.entry = suite ? suite->find(arg) : nullptr;
  out.scene = out.entry ? load_suite_scene(*out.entry) : load_scene(arg);
  return out;
}

// The default suite is read only when a command needs a scene name from it;
// a broken or absent default manifest must not stop `trace FILE`.
const Suite* suite_if_readable(const std::string& path, bool explicit_path, Suite& storage) {
  try {
    storage = load_suite(path);
    return &storage;
  } catch (const InputError&) {
    if (explicit_path) throw;
    return nullptr;
  }
}

// A numeric flag, given as text so that its rule (settings_rules.h), not
// CLI11's conversion, judges it and names the flag.
template <typename Rule>
auto flag_value(const char* flag, const std::string& text, Rule rule) {
  return rule(GivenValue::from_flag(flag, text));
}

// A file a command reads or writes, as the user named it.
struct FileArg {
  std::string flag;  // "--out"
  std::string path;
  std::string what;  // for messages: "--out results.csv", "the metadata of --out results.csv"
};

FileArg output(const std::string& flag, const std::string& path) { return {flag, path, flag + " " + path}; }
FileArg metadata_of(const std::string& flag, const std::string& path) {
  const std::string meta = metadata_path_for(path);
  return {flag, meta, fmt::format("the metadata of {} {} ({})", flag, path, meta)};
}

// True when a and b name the same file: the same path once `.`, `..` and
// symbolic links are resolved, or (both existing) the same inode.
bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec1, ec2;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec1), ec1), cb = fs::weakly_canonical(fs::absolute(b, ec2), ec2);
  if (!ec1 && !ec2 && ca == cb) return true;
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec);
}

// Before anything is read or computed: every output is a regular file or
// absent (check_output_file: /dev/null, a FIFO or a directory is refused, not
// replaced), and no output is another output or an input of the same command
// (--accuracy equal to --out, or their .meta.toml files colliding, would
// silently overwrite one result with the other).
void check_outputs(const std::vector<FileArg>& outputs, const std::vector<FileArg>& inputs = {}) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const FileArg& o = outputs[i];
    if (o.path.empty()) continue;
    try {
      check_output_file(o.path);
    } catch (const InputError& e) {
      throw InputError(o.flag, e.what());
    }
    for (std::size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && same_file(o.path, outputs[j].path))
        throw InputError("", fmt::format("{} is the same file as {}: each result needs its own file", o.what,
                                         outputs[j].what));
    for (const FileArg& in : inputs)
      if (!in.path.empty() && same_file(o.path, in.path))
        throw InputError("", fmt::format("{} is the same file as the input {}: it would be overwritten", o.what,
                                         in.what));
  }
}

// An output a command cannot do without: '' would fail only when the
// results are written, after the whole run.
void check_named(const std::string& flag, const std::string& path) {
  if (path.empty()) throw InputError(flag, "must name a file, got ''");
}

// A folder raybench writes into: absent (it is created) or a directory.
void check_output_folder(const std::string& flag, const std::string& path) {
  std::error_code ec;
  if (!path.empty() && std::filesystem::exists(path, ec) && !std::filesystem::is_directory(path, ec))
    throw InputError(flag, path + " exists and is not a directory");
}

std::string command_line(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) {
    if (i) s += ' ';
    s += argv[i];
  }
  return s;
}

int run(int argc, char** argv) {
  CLI::App app{"raybench: throughput and per-ray agreement of ray-tracing kernels against Embree, on the same rays.\n"
               "Exit status: 0 success, 1 a regression (gate), 2 bad usage or input (one error line), 130/143 stopped by SIGINT/SIGTERM."};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show help for every command");

  // raybench run
  RunOptions run_options;
  std::string suite_path = kDefaultSuite;
  std::vector<std::string> run_raysets, run_backends, run_threads, run_tessellate;
  std::string run_rays, run_reps, run_build_reps, run_seed, run_min_time, run_warmup, run_reference, run_huge_pages;
  bool no_interleave = false, list_only = false;
  run_options.out_csv = kDefaultOut;
  run_options.rays_dir = kDefaultRaysDir;
  CLI::App* run_cmd = app.add_subcommand("run", "Run a benchmark suite: every scene x ray set x backend x thread count");
  run_cmd->add_option("--suite", suite_path, "Suite manifest (TOML)")->capture_default_str();
  run_cmd->add_option("--scene,-s", run_options.scenes,
                      "Scenes to run: names from the suite, mesh paths, proc:<name>, or NAME=PATH to name a mesh (default: every "
                      "available suite scene)")
      ->delimiter(',');
  run_cmd->add_option("--rayset,-r", run_raysets, fmt::format("Ray sets: {} (default: the suite's)", fmt::join(rayset_kind_names(), ", ")))
      ->delimiter(',');
  run_cmd->add_option("--rays,-n", run_rays, "Rays per ray set (default: the suite's, 262144)")->type_name("INT");
  run_cmd->add_option("--backend,-b", run_backends, "Backends, e.g. embree,embree:high,bvh2 (see 'raybench backends'); 'bvh2:*' is bvh2 with every triangle test")
      ->delimiter(',');
  run_cmd->add_option("--threads,-t", run_threads, "Thread counts, e.g. 1,2 (default: 1)")->delimiter(',')->type_name("INT");
  run_cmd->add_option("--reps", run_reps, "Timed rounds: each round traces every case of a scene once, in a shuffled order; the median is reported (default: 5)")->type_name("INT");
  run_cmd->add_option("--reference", run_reference,
                      "Backend of the run that ratio_to_reference and the table's 'x NAME' are relative to, paired round by "
                      "round, e.g. plugin:old.so (default: embree when the run has it)")
      ->type_name("NAME");
  run_cmd->add_option("--build-reps", run_build_reps, "Timed rounds of builds per backend, interleaved across backends after one untimed build each; a build shorter than --min-time is repeated within its round (default: 3)")->type_name("INT");
  run_cmd->add_option("--seed", run_seed, "Ray generation seed (default: 1)")->type_name("INT");
  run_cmd->add_option("--min-time", run_min_time, "Minimum seconds per repetition, of a trace or of a round of builds (default: 0.05)")->type_name("SECONDS");
  run_cmd->add_option("--warmup", run_warmup, "Untimed warm-up seconds per case, before its first round (default: 0.05)")->type_name("SECONDS");
  run_cmd->add_option("--out,-o", run_options.out_csv, "Results CSV; metadata goes beside it as .meta.toml")->capture_default_str();
  run_cmd->add_option("--rays-dir", run_options.rays_dir, "Where ray sets are stored and reused")->capture_default_str();
  run_cmd->add_option("--huge-pages", run_huge_pages,
                      "Memory policy of every backend's acceleration structure: on (transparent huge pages, where the "
                      "kernel allows them) or off (ordinary pages) (default: the suite's, on)")
      ->type_name("on|off");
  run_cmd->add_flag("--no-interleave", no_interleave, "Run every round's cases in the same order (backends as listed) instead of a shuffled one");
  run_cmd->add_flag("--list", list_only, "List the suite's scenes and whether they are available, then exit");
  run_cmd->add_option("--accuracy", run_options.accuracy_csv,
                      "Also judge every ray with the exact referee and write the accuracy CSV here "
                      "(e.g. results/accuracy.csv; see scripts/accuracy)");
  run_cmd->add_option("--tessellate", run_tessellate,
                      "The tessellation study: also trace each scene with analytic primitives as triangle stand-ins "
                      "<scene>@uv<S>x<R>, spheres as UV spheres of S segments by R rings, boxes as 12 triangles, "
                      "e.g. 8x4,32x16,256x128; with the scene's own rays, judged against its referee with --accuracy; "
                      "'none' for no stand-in (default: the suite's tessellate)")
      ->delimiter(',')
      ->type_name("SxR");

  // raybench rays
  std::string rays_scene, rays_kind = "primary", rays_out, rays_suite = kDefaultSuite;
  std::string rays_count = "262144", rays_seed = "1";
  CLI::App* rays_cmd = app.add_subcommand("rays", "Generate a ray set and store it as .npy, float32 (N, 8): ox oy oz tnear dx dy dz tfar");
  rays_cmd->add_option("--scene,-s", rays_scene, "Mesh path, proc:<name>, or a suite scene name (uses its camera)")->required();
  rays_cmd->add_option("--kind,-k", rays_kind, fmt::format("Ray set: {}", fmt::join(rayset_kind_names(), ", ")))->capture_default_str();
  rays_cmd->add_option("--count,-n", rays_count, "Number of rays")->capture_default_str()->type_name("INT");
  rays_cmd->add_option("--seed", rays_seed, "Seed")->capture_default_str()->type_name("INT");
  rays_cmd->add_option("--suite", rays_suite, "Suite manifest to look scene names up in")->capture_default_str();
  rays_cmd->add_option("--out,-o", rays_out, "Output .npy file")->required();

  // raybench trace
  std::string trace_scene, trace_rays, trace_backend = "bvh2", trace_out, trace_suite = kDefaultSuite;
  bool trace_occluded = false;
  std::string trace_threads = "1";
  CLI::App* trace_cmd = app.add_subcommand(
      "trace", "Trace a ray file with one backend and write hits as .npy, float64 (N, 4): t prim u v (t=inf, prim=-1 on a miss)");
  trace_cmd->add_option("--scene,-s", trace_scene, "Mesh path, proc:<name>, or a suite scene name")->required();
  trace_cmd->add_option("--rays", trace_rays, "Ray file (.npy, float32, shape (N, 8))")->required();
  trace_cmd->add_option("--backend,-b", trace_backend, "Backend name (see 'raybench backends')")->capture_default_str();
  trace_cmd->add_option("--out,-o", trace_out, "Output .npy file")->required();
  trace_cmd->add_flag("--occluded", trace_occluded,
                      "Any-hit occlusion query instead of closest hit; writes float64 (N, 1): 1 occluded, 0 not");
  trace_cmd->add_option("--threads,-t", trace_threads, "Threads")->capture_default_str()->type_name("INT");
  std::string trace_huge_pages = "on";
  trace_cmd->add_option("--huge-pages", trace_huge_pages,
                        "Memory policy of the backend's acceleration structure: on (transparent huge pages) or off")
      ->capture_default_str()
      ->type_name("on|off");
  trace_cmd->add_option("--suite", trace_suite, "Suite manifest to look scene names up in")->capture_default_str();

  // raybench kernels
  KernelBenchOptions kernel_options;
  kernel_options.out_csv = default_paths().kernels_csv;
  kernel_options.out_json = default_paths().kernels_json;
  CLI::App* kernels_cmd = app.add_subcommand(
      "kernels", "Microbenchmark every kernel variant alone: ns per ray-primitive test, hit- and miss-heavy, scalar and 8-wide");
  kernels_cmd->add_option("--out,-o", kernel_options.out_csv, "Results CSV (+ .meta.toml beside it)")->capture_default_str();
  kernels_cmd->add_option("--json", kernel_options.out_json, "Google Benchmark JSON output ('' for none)")->capture_default_str();
  kernels_cmd->add_option("--filter", kernel_options.filter, "Only cases whose name contains this, e.g. triangle/ or /miss");
  std::string kernels_reps = std::to_string(kernel_options.repetitions), kernels_min_time = fmt::format("{}", kernel_options.min_time),
              kernels_pairs = std::to_string(kernel_options.pairs);
  kernels_cmd->add_option("--reps", kernels_reps, "Timed repetitions per case")->capture_default_str()->type_name("INT");
  kernels_cmd->add_option("--min-time", kernels_min_time, "Minimum seconds per repetition")->capture_default_str()->type_name("SECONDS");
  kernels_cmd->add_option("--pairs", kernels_pairs, "Ray-primitive pairs per family and input")->capture_default_str()->type_name("INT");

  // raybench accuracy-kernels
  KernelAccuracyOptions kernel_accuracy_options;
  kernel_accuracy_options.out_csv = default_paths().accuracy_kernels_csv;
  CLI::App* accuracy_kernels_cmd = app.add_subcommand(
      "accuracy-kernels", "Judge every box, OBB, sphere and triangle kernel variant alone on the extreme ray sets "
                          "against exact referees, and time it (accuracy CSV)");
  accuracy_kernels_cmd->add_option("--out,-o", kernel_accuracy_options.out_csv, "Accuracy CSV (+ .meta.toml beside it)")
      ->capture_default_str();
  accuracy_kernels_cmd->add_option("--filter", kernel_accuracy_options.filter,
                                   "Only rows whose <scene>/<rayset>/<backend> contains this, e.g. prim:sphere or kernel:slab_seed");
  std::string kernel_accuracy_rays = std::to_string(kernel_accuracy_options.rays),
              kernel_accuracy_seed = std::to_string(kernel_accuracy_options.seed);
  accuracy_kernels_cmd->add_option("--rays,-n", kernel_accuracy_rays, "Rays per ray set")->capture_default_str()->type_name("INT");
  accuracy_kernels_cmd->add_option("--seed", kernel_accuracy_seed, "Ray generation seed")->capture_default_str()->type_name("INT");
  kernel_accuracy_options.rays_dir = kDefaultRaysDir;
  accuracy_kernels_cmd->add_option("--rays-dir", kernel_accuracy_options.rays_dir,
                                   "Where each ray set is stored as .npy (rays, and the primitive of each ray); '' for nowhere")
      ->capture_default_str();

  // raybench compare
  std::string compare_base, compare_current, compare_format = "table", compare_out;
  bool compare_force = false;
  CompareOptions compare_options;
  CLI::App* compare_cmd = app.add_subcommand(
      "compare", "Compare two results CSVs row by row: throughput and ratio to the runs' reference backend (embree "
                 "unless the run chose another) with a noise-aware verdict, deterministic columns exactly");
  compare_cmd->add_option("base", compare_base, "Baseline results CSV")->required();
  compare_cmd->add_option("current", compare_current, "Results CSV to compare with it")->required();
  compare_cmd->add_option("--format,-f", compare_format, "table, md or json")
      ->capture_default_str()
      ->check(CLI::IsMember({"table", "md", "json"}));
  compare_cmd->add_option("--out,-o", compare_out, "Write to this file instead of stdout");
  compare_cmd->add_flag("--force", compare_force, "Compare even when the machine metadata differ");
  std::string compare_alpha = fmt::format("{}", compare_options.alpha),
              compare_min_effect = fmt::format("{}", compare_options.min_effect);
  compare_cmd->add_option("--alpha", compare_alpha, "Significance level of the Mann-Whitney U test")->capture_default_str()->type_name("FLOAT");
  compare_cmd->add_option("--min-effect", compare_min_effect, "Smallest relative change that gets a verdict")
      ->capture_default_str()->type_name("FLOAT");

  // raybench gate
  std::string gate_config = default_paths().gate_config;
  std::vector<std::string> gate_baselines, gate_currents, gate_candidates;
  std::string gate_accuracy_csv, gate_json;
  bool gate_verbose = false;
  CLI::App* gate_cmd = app.add_subcommand(
      "gate", "Fail (exit 1) when the current results regress against a baseline (--baseline), or when a candidate "
              "backend is slower or less accurate than the run's reference backend (--candidate), beyond the "
              "thresholds of a gate config");
  gate_cmd->add_option("--baseline", gate_baselines,
                       "Baseline results CSV; give it more than once to pool independent runs of the baseline "
                       "(each repetition keeps the ratio to the reference of its own run)");
  gate_cmd->add_option("--current", gate_currents,
                       "Current results CSV; give it more than once (independent runs) to count a throughput "
                       "regression only when every run shows it")
      ->required();
  gate_cmd->add_option("--candidate", gate_candidates,
                       "Gate within the --current run (no --baseline): this backend, as named in the run (e.g. "
                       "plugin:cand.so), against the run's reference backend, round by round; more than once for several");
  gate_cmd->add_option("--accuracy", gate_accuracy_csv,
                       "With --candidate: the run's accuracy CSV (run --accuracy); a candidate whose referee error counts "
                       "exceed the reference's fails");
  gate_cmd->add_option("--json", gate_json, "Also write the verdicts as JSON to this file (docs/gating.md)");
  gate_cmd->add_option("--config", gate_config, "Thresholds (TOML)")->capture_default_str();
  gate_cmd->add_flag("--verbose,-v", gate_verbose, "Also print the full comparison table (with --baseline) or every candidate row's paired ratio (with --candidate)");

  // raybench backends / scenes
  CLI::App* backends_cmd = app.add_subcommand("backends", "List backend names");
  std::string scenes_suite = kDefaultSuite;
  CLI::App* scenes_cmd = app.add_subcommand("scenes", "List the suite's scenes and the procedural scenes");
  scenes_cmd->add_option("--suite", scenes_suite, "Suite manifest")->capture_default_str();
  bool scenes_bounds = false;
  std::vector<std::string> scenes_names;
  scenes_cmd->add_flag("--bounds", scenes_bounds,
                       "Load each scene and print its triangle count, bounds and the camera its primary rays use");
  scenes_cmd->add_option("--scene,-s", scenes_names,
                         "With --bounds: only these scenes (names from the suite, mesh paths, proc:<name>, NAME=PATH)")
      ->delimiter(',');

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    raybench::print_stderr_line("raybench: error: " + raybench::printable(e.what()) + " (see 'raybench --help')");
    return 2;
  }

  if (*compare_cmd) {
    compare_options.alpha = flag_value("--alpha", compare_alpha, alpha_setting);
    compare_options.min_effect = flag_value("--min-effect", compare_min_effect, min_effect_setting);
    check_input_file(compare_base, "results CSV");
    check_input_file(compare_current, "results CSV");
    check_outputs({output("--out", compare_out)},
                  {{"base", compare_base, "base " + compare_base}, {"current", compare_current, "current " + compare_current}});
    const ResultsFile base = read_results_file(compare_base);
    const ResultsFile current = read_results_file(compare_current);
    if (const auto diffs = machine_differences(base, current); !diffs.empty() && !compare_force) {
      std::string all;
      for (const auto& d : diffs) all += (all.empty() ? "" : "; ") + d;
      throw InputError(compare_current, "not comparable with " + compare_base + ": " + all + " (ratios to " +
                                            current.reference + " still are: use --force to compare anyway)");
    }
    const Comparison c = compare_results(base, current, compare_options);
    const OutputFormat format = compare_format == "md" ? OutputFormat::kMarkdown
                                : compare_format == "json" ? OutputFormat::kJson
                                                           : OutputFormat::kTable;
    const bool colour = compare_out.empty() && format == OutputFormat::kTable && ::isatty(1);
    const std::string text = format_comparison(c, base, current, format, colour);
    if (compare_out.empty()) std::cout << text;
    else write_file_atomically(compare_out, [&](std::ostream& o) { o << text; });
    return 0;
  }
  if (*gate_cmd) {
    const bool within_run = !gate_candidates.empty();
    if (within_run && !gate_baselines.empty())
      throw InputError("--candidate", "gates within one run, --baseline against another run: give one or the other");
    if (!within_run && gate_baselines.empty())
      throw InputError("gate", "give --baseline FILE (gate against another run) or --candidate NAME (within the --current run)");
    if (!within_run && !gate_accuracy_csv.empty())
      throw InputError("--accuracy", "judges candidates within one run: give --candidate NAME, not --baseline");
    check_input_file(gate_config, "gate config (TOML)");
    for (const std::string& path : gate_baselines) check_input_file(path, "results CSV");
    for (const std::string& path : gate_currents) check_input_file(path, "results CSV");
    if (!gate_accuracy_csv.empty()) check_input_file(gate_accuracy_csv, "accuracy CSV");
    std::vector<FileArg> gate_inputs;
    for (const std::string& path : gate_baselines) gate_inputs.push_back({"--baseline", path, "--baseline " + path});
    for (const std::string& path : gate_currents) gate_inputs.push_back({"--current", path, "--current " + path});
    gate_inputs.push_back({"--accuracy", gate_accuracy_csv, "--accuracy " + gate_accuracy_csv});
    gate_inputs.push_back({"--config", gate_config, "--config " + gate_config});
    check_outputs({output("--json", gate_json)}, gate_inputs);
    const GateConfig config = load_gate_config(gate_config);
    std::vector<ResultsFile> currents;
    for (const std::string& path : gate_currents) currents.push_back(read_results_file(path));
    const ResultsFile& current = currents.front();
    GateResult g;
    std::string summary;
    if (within_run) {
      g = run_within_run_gate(currents, gate_candidates, config);
      if (!gate_accuracy_csv.empty())
        gate_accuracy(read_accuracy_csv(gate_accuracy_csv), gate_accuracy_csv, current.reference, gate_candidates, config, g);
      summary = fmt::format("{} against the reference {} in {}", fmt::join(gate_candidates, ", "), current.reference,
                            current.path);
      if (gate_verbose) std::cout << format_paired_speeds(g) << "\n";
    } else {
      std::vector<ResultsFile> baseline_runs;
      for (const std::string& path : gate_baselines) baseline_runs.push_back(read_results_file(path));
      const ResultsFile baseline = pool_runs(baseline_runs);
      g = run_gate(baseline, currents, config);
      if (gate_verbose) {
        CompareOptions o;
        o.alpha = config.alpha;
        o.min_effect = config.max_ratio_drop;
        std::cout << format_comparison(compare_results(baseline, current, o), baseline, current, OutputFormat::kTable,
                                       ::isatty(1)) << "\n";
      }
      summary = fmt::format("{} rows compared against {}", current.rows.size(), baseline.path);
    }
    for (const auto& n : g.notes) std::cout << "note: " << n << "\n";
    for (const auto& f : g.failures) std::cout << "FAIL: " << f.message << "\n";
    std::cout << fmt::format("gate: {} ({}, {} failure{})\n", g.failures.empty() ? "PASS" : "FAIL", summary,
                             g.failures.size(), g.failures.size() == 1 ? "" : "s");
    if (!gate_json.empty()) {
      const std::string json = format_gate_json(g, gate_currents, gate_baselines, gate_candidates);
      write_file_atomically(gate_json, [&](std::ostream& o) { o << json; });
    }
    return g.failures.empty() ? 0 : 1;
  }
  if (*accuracy_kernels_cmd) {
    kernel_accuracy_options.rays = flag_value("--rays", kernel_accuracy_rays, kernel_rays_setting);
    kernel_accuracy_options.seed = flag_value("--seed", kernel_accuracy_seed, seed_setting);
    if (!kernel_accuracy_options.out_csv.empty())
      check_outputs({output("--out", kernel_accuracy_options.out_csv), metadata_of("--out", kernel_accuracy_options.out_csv)});
    check_output_folder("--rays-dir", kernel_accuracy_options.rays_dir);
    kernel_accuracy_options.command_line = command_line(argc, argv);
    const std::vector<AccuracyRow> rows = run_kernel_accuracy(kernel_accuracy_options);
    std::cout << format_kernel_accuracy_table(rows);
    fmt::print("results: {} ({} rows)\n", kernel_accuracy_options.out_csv, rows.size());
    return 0;
  }
  if (*kernels_cmd) {
    kernel_options.repetitions = flag_value("--reps", kernels_reps, repetitions_setting);
    kernel_options.min_time = flag_value("--min-time", kernels_min_time, min_time_setting);
    kernel_options.pairs = flag_value("--pairs", kernels_pairs, pairs_setting);
    check_named("--out", kernel_options.out_csv);
    check_outputs({output("--out", kernel_options.out_csv), metadata_of("--out", kernel_options.out_csv),
                   output("--json", kernel_options.out_json)});
    kernel_options.command_line = command_line(argc, argv);
    const std::vector<KernelResult> results = run_kernel_benchmarks(kernel_options);
    std::cout << format_kernel_table(results);
    fmt::print("results: {} ({} rows){}\n", kernel_options.out_csv, results.size(),
               kernel_options.out_json.empty() ? "" : ", Google Benchmark JSON: " + kernel_options.out_json);
    return 0;
  }
  if (*backends_cmd) {
    const std::vector<BackendInfo> backends = list_backends();
    std::size_t width = 0;  // names aligned in one column, however long the longest
    for (const BackendInfo& b : backends) width = std::max(width, b.name.size());
    for (const BackendInfo& b : backends) fmt::print("{:<{}}  {}\n", b.name, width, b.description);
    return 0;
  }
  if (*scenes_cmd && (scenes_bounds || !scenes_names.empty())) {
    const Suite suite = load_suite(scenes_suite);
    std::vector<SceneChoice> chosen = choose_scenes(scenes_names, suite);
    if (scenes_names.empty())
      for (const SuiteScene& s : suite.scenes)
        if (s.available()) chosen.push_back(choose_scene(s.name, suite));
    for (const SceneChoice& c : chosen) {
      const Scene scene = load_chosen_scene(c);
      const BBox b = scene.bounds();
      const bool suite_camera = c.entry && c.entry->camera;
      const Camera cam = suite_camera ? *c.entry->camera : RayGenerator(scene).default_camera();
      const auto v = [](Vec3f p) { return fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x, p.y, p.z); };
      fmt::print("{}: {}\n  bounds {} - {}, size {}\n  camera ({}) position {} look_at {} up {} fov {:.6g}\n",
                 printable(scene.name), describe_primitives(scene), v(b.lower), v(b.upper), v(b.upper - b.lower),
                 suite_camera ? "the suite's" : "default: frames the bounds from outside", v(cam.position),
                 v(cam.look_at), v(cam.up), cam.fov_degrees);
    }
    return 0;
  }
  if (*scenes_cmd || (*run_cmd && list_only)) {
    const Suite suite = load_suite(*scenes_cmd ? scenes_suite : suite_path);
    fmt::print("suite {}:\n", suite.path);
    std::size_t width = 18;  // names aligned in one column, however long the longest
    for (const SuiteScene& s : suite.scenes) width = std::max(width, s.name.size());
    for (const SuiteScene& s : suite.scenes)
      fmt::print("  {:<{}} {:<9} {}\n", s.name, width, s.available() ? "available" : "missing", s.sources());
    fmt::print("procedural scenes (use as proc:<name>):\n");
    width = 22;
    for (const ProceduralSceneInfo& p : procedural_scenes()) width = std::max(width, p.name.size());
    for (const ProceduralSceneInfo& p : procedural_scenes()) fmt::print("  {:<{}} {}\n", p.name, width, p.description);
    return 0;
  }
  if (*run_cmd) {
    // Every flag is judged before the manifest is read or a scene loaded;
    // a flag given overrides the manifest's value, whatever that value.
    std::vector<std::function<void(SuiteSettings&)>> overrides;
    const auto override_with = [&](const char* flag, const std::string& text, auto rule, auto member) {
      if (run_cmd->count(flag)) overrides.push_back([member, v = flag_value(flag, text, rule)](SuiteSettings& s) { s.*member = v; });
    };
    if (!run_threads.empty()) {
      std::vector<int> threads;
      for (const std::string& t : run_threads) threads.push_back(flag_value("--threads", t, threads_setting));
      overrides.push_back([threads](SuiteSettings& s) { s.threads = threads; });
    }
    override_with("--rays", run_rays, rays_setting, &SuiteSettings::rays);
    override_with("--reps", run_reps, repetitions_setting, &SuiteSettings::repetitions);
    override_with("--build-reps", run_build_reps, build_repetitions_setting, &SuiteSettings::build_repetitions);
    override_with("--seed", run_seed, seed_setting, &SuiteSettings::seed);
    override_with("--min-time", run_min_time, min_time_setting, &SuiteSettings::min_time);
    override_with("--warmup", run_warmup, warmup_setting, &SuiteSettings::warmup);
    override_with("--huge-pages", run_huge_pages, huge_pages_setting, &SuiteSettings::huge_pages);
    if (run_cmd->count("--reference"))
      overrides.push_back([v = flag_value("--reference", run_reference, reference_setting)](SuiteSettings& s) {
        s.reference = v;
        s.reference_given = "--reference";
      });
    if (run_cmd->count("--tessellate")) {
      const std::vector<Tessellation> list =
          run_tessellate == std::vector<std::string>{"none"} ? std::vector<Tessellation>{}
                                                              : parse_tessellations(run_tessellate, "--tessellate");
      overrides.push_back([list](SuiteSettings& s) { s.tessellate = list; });
      run_options.tessellate_from_command_line = true;
    }
    check_named("--out", run_options.out_csv);
    if (run_options.rays_dir.empty()) throw InputError("--rays-dir", "must name a folder, got ''");
    check_outputs({output("--out", run_options.out_csv), metadata_of("--out", run_options.out_csv),
                   output("--accuracy", run_options.accuracy_csv),
                   run_options.accuracy_csv.empty() ? FileArg{} : metadata_of("--accuracy", run_options.accuracy_csv)},
                  {{"--suite", suite_path, "--suite " + suite_path}});
    check_output_folder("--rays-dir", run_options.rays_dir);

    run_options.suite = load_suite(suite_path);
    SuiteSettings& s = run_options.settings;
    s = run_options.suite.settings;
    if (!run_raysets.empty()) s.raysets = run_raysets;
    run_options.raysets_from_command_line = !run_raysets.empty();
    if (!run_backends.empty()) s.backends = expand_backend_patterns(run_backends);
    for (const auto& apply : overrides) apply(s);
    run_options.interleave = !no_interleave;
    run_options.command_line = command_line(argc, argv);
    const RunResults results = run_suite(run_options);
    std::cout << format_results_table(results.rows, results.cameras);
    if (!run_options.accuracy_csv.empty()) std::cout << format_accuracy_table(results.accuracy);
    std::cout << std::endl;
    fmt::print("results: {} ({} rows), metadata: {}\n", run_options.out_csv, results.rows.size(),
               metadata_path_for(run_options.out_csv));
    return 0;
  }
  if (*rays_cmd) {
    const std::size_t count = flag_value("--count", rays_count, rays_setting);
    const std::uint64_t seed = flag_value("--seed", rays_seed, seed_setting);
    check_named("--out", rays_out);
    check_outputs({output("--out", rays_out)}, {{"--scene", rays_scene, "--scene " + rays_scene}});
    Suite storage;
    const Suite* suite = suite_if_readable(rays_suite, rays_cmd->count("--suite") > 0, storage);
    const RaySetKind kind = parse_rayset_kind(rays_kind);
    const SceneArg s = resolve_scene(rays_scene, suite);
    const RayGenerator generator(s.scene);
    RaySetSpec spec{kind, count, seed, s.entry ? s.entry->camera : std::nullopt,
                    s.entry ? s.entry->light : std::nullopt, s.entry ? s.entry->inside : std::nullopt};
    const std::vector<Ray> rays = generator.generate(spec);
    write_ray_file(rays_out, rays);
    fmt::print("wrote {} {} rays for {} ({}) to {}\n", rays.size(), rays_kind, s.scene.name,
               describe_primitives(s.scene), rays_out);
    return 0;
  }
  if (*trace_cmd) {
    const int threads = flag_value("--threads", trace_threads, threads_setting);
    const bool huge_pages = flag_value("--huge-pages", trace_huge_pages, huge_pages_setting);
    check_input_file(trace_rays, "ray file (.npy)");
    check_named("--out", trace_out);
    check_outputs({output("--out", trace_out)},
                  {{"--rays", trace_rays, "--rays " + trace_rays}, {"--scene", trace_scene, "--scene " + trace_scene}});
    Suite storage;
    const Suite* suite = suite_if_readable(trace_suite, trace_cmd->count("--suite") > 0, storage);
    std::unique_ptr<Backend> backend = make_backend(trace_backend, {threads, huge_pages});
    // What every backend traces (rays/screening.h); untraceable rays answer misses.
    const ScreenedRays screened = screen_rays(read_ray_file(trace_rays));
    const std::vector<Ray>& rays = screened.rays;
    const SceneArg s = resolve_scene(trace_scene, suite);
    // A run skips such a pair with a note; tracing one explicitly is bad usage.
    if (const std::string problem = capability_problem(*backend, s.scene); !problem.empty())
      throw InputError("--backend", problem + " (raybench run skips such a pair)");
    const TraceExecutor executor(threads);
    executor.run([&] { backend->build(s.scene); });
    std::size_t hits = 0;
    if (trace_occluded) {
      const std::vector<std::uint8_t> occ = executor.occlusion_answers(*backend, screened);
      require_valid_occlusion(*backend, occ, fmt::format("{} ({})", s.scene.name, trace_rays));
      std::vector<double> out(occ.begin(), occ.end());
      for (std::uint8_t o : occ) hits += o;
      write_npy_f64(trace_out, out, rays.size(), 1);
      fmt::print("occlusion query: {} of {} rays occluded; wrote (N, 1) occlusion flags (not hit records) to {}\n", hits,
                 rays.size(), trace_out);
    } else {
      const std::vector<Hit> h = executor.answers(*backend, screened);
      require_valid_hits(*backend, h, s.scene.primitive_count(), fmt::format("{} ({})", s.scene.name, trace_rays));
      std::vector<double> out(rays.size() * 4);
      for (std::size_t i = 0; i < h.size(); ++i) {
        out[4 * i + 0] = h[i].t;
        out[4 * i + 1] = h[i].prim;
        out[4 * i + 2] = h[i].hit() ? h[i].u : 0.0;
        out[4 * i + 3] = h[i].hit() ? h[i].v : 0.0;
        hits += h[i].hit();
      }
      write_npy_f64(trace_out, out, rays.size(), 4);
      fmt::print("closest hit: {} of {} rays hit; wrote (N, 4) t prim u v to {}\n", hits, rays.size(), trace_out);
    }
    return 0;
  }
  return 2;
}

}  // namespace
}  // namespace raybench

// Every error is one line (printable: a newline in a user's file or scene
// name is written as \x0a), so scripts can take the last line of stderr.
int main(int argc, char** argv) {
  try {
    raybench::record_source_state();  // the sources as built, before a long run
    raybench::install_interrupt_handler();  // SIGINT/SIGTERM: temporary files removed, exit 130/143 (interrupt.h)
    return raybench::run(argc, argv);
  } catch (const raybench::InputError& e) {
    raybench::print_stderr_line("raybench: error: " + raybench::printable(e.what()));
    return 2;
  } catch (const std::bad_alloc&) {
    raybench::print_stderr_line("raybench: error: out of memory");
    return 2;
  } catch (const std::exception& e) {
    raybench::print_stderr_line("raybench: error: " + raybench::printable(e.what()));
    return 2;
  }
}
