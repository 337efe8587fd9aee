// Running a suite: load scenes, make or reuse the stored ray sets, build every
// backend, measure agreement with Embree per ray, time tracing through Google
// Benchmark, and write the results CSV with its metadata.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "accuracy/accuracy_csv.h"
#include "results/results_csv.h"
#include "scene/scene.h"
#include "suite/results_table.h"
#include "suite/suite.h"

namespace raybench {

struct RunOptions {
  Suite suite;
  SuiteSettings settings;            // the suite's defaults with command-line overrides applied
  std::vector<std::string> scenes;   // --scene arguments (scene_selection.h); empty: every available suite scene
  std::string out_csv;
  std::string rays_dir;              // where ray sets are stored and reused
  bool raysets_from_command_line = false;  // settings.raysets then override each scene's own list
  bool tessellate_from_command_line = false;  // settings.tessellate then overrides each scene's own list
  bool interleave = true;            // each timing round in its own random order (false: the cases' order)
  std::string command_line;          // recorded in the metadata
  // When set, every ray is also judged by the exact referee and the accuracy
  // CSV (accuracy/accuracy_csv.h) is written here, with its throughput taken
  // from this run's timing (the first thread count).
  std::string accuracy_csv;
};

// The baseline every backend's agreement (agree_hit, agree_prim, ...) is
// measured against, always built for it whatever the run's backends; not the
// exact referee (the backend named "reference"), and not the timing
// reference below.
inline constexpr const char* kAgreementBackend = "embree";

// The timing reference of a run without --reference (or [defaults]
// reference) when the run has this backend; ratio_to_reference is relative
// to it. Without it, a run has no timing reference (ratio_to_reference empty).
inline constexpr const char* kDefaultTimingReference = "embree";

// The run's timing reference: the one the settings name, which must be one of
// the run's backends (InputError naming where it was given and the run's
// backends otherwise), else kDefaultTimingReference when the run has it,
// else "" (none).
std::string timing_reference(const SuiteSettings& settings);

// The run's memory policy as its metadata records it (memory_policy = ...),
// given the kernel's THP mode (measure/page_residency.h; recorded beside it
// as thp), which decides what the policy can do: under "madvise" it holds
// ("huge pages for every backend (transparent, madvise)" or "ordinary pages
// for every backend"); under "always" nothing is advised off huge pages (and
// Embree's memory cannot be), so "off" only requests ordinary pages; under
// "never" no backend gets huge pages; any other mode ("unavailable") says the
// mode is unknown.
std::string memory_policy_description(bool huge_pages, std::string_view thp_mode);

// A backend a run did not trace on a scene because the scene has a primitive
// type the backend's capabilities() lack (plugins: anything not a triangle).
// Printed when it happens and recorded in the metadata as
// skipped.<scene>.<backend> = <reason>; the pair has no rows.
struct SkippedBackend {
  std::string scene;
  std::string backend;
  std::string reason;  // capability_problem (backends/backend.h)
};

// The backends of `names` (in order, repeats kept) that can model every
// primitive type of `scene`; one SkippedBackend per other name is appended to
// `skipped` (once per name). Makes each backend to ask its capabilities().
std::vector<std::string> backends_for_scene(const std::vector<std::string>& names, const Scene& scene,
                                            std::vector<SkippedBackend>& skipped);

// What a run measured: its rows as written, and what each scene's camera saw.
struct RunResults {
  std::vector<ResultRow> rows;
  std::vector<AccuracyRow> accuracy;    // --accuracy runs
  std::vector<CameraCoverage> cameras;  // scenes traced with the primary ray set
  std::vector<SkippedBackend> skipped;  // backends that cannot model a scene
};

// Runs the suite and writes the CSV (and the accuracy CSV) with metadata;
// the tables (results_table.h) are the caller's to print. Throws InputError
// on bad input, before any benchmark runs where possible.
RunResults run_suite(const RunOptions& options);

// Runs scenes made in memory as run_suite runs a suite's scenes, with the
// settings' ray sets and tessellations (no manifest entry: no camera, light
// or inside ball of their own); options.scenes and the suite's scenes are
// not consulted. For callers that make their scenes themselves (tests).
// Throws InputError for a scene name scene_name_problem refuses.
RunResults run_scenes(const RunOptions& options, std::vector<Scene> scenes);

}  // namespace raybench
