#include "suite/suite_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <stdexcept>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "accuracy/judge.h"
#include "measure/agreement.h"
#include "measure/answer_check.h"
#include "io/atomic_file.h"
#include "backends/backend.h"
#include "measure/build_timing.h"
#include "io/error.h"
#include "measure/gbench.h"
#include "io/interrupt.h"
#include "results/metadata.h"
#include "io/npy.h"
#include "rays/rayset.h"
#include "rays/screening.h"
#include "referee/referee.h"
#include "scene/random.h"
#include "scene/scene.h"
#include "scene/tessellate.h"
#include "suite/results_table.h"
#include "suite/scene_selection.h"
#include "suite/settings_rules.h"
#include "measure/page_residency.h"
#include "measure/trace.h"

namespace raybench {
namespace {

void progress(const std::string& line) { print_stderr_line("raybench: " + line); }

// The build line's "4.0 MiB in huge pages" (build_timing.h's huge_page_bytes).
std::string describe_huge_pages(const std::optional<std::size_t>& bytes) {
  return bytes ? fmt::format("{:.1f} MiB in huge pages", *bytes / 1048576.0) : "huge pages unknown";
}

struct LoadedScene {
  SceneChoice choice;  // choice.entry: null for a scene given by path
  Scene scene;
};

struct RaySet {
  RaySetKind kind;
  std::vector<Ray> rays;               // as stored: what the referee judges
  ScreenedRays screened;               // what every backend traces (rays/screening.h)
  std::vector<std::int32_t> sources;   // accuracy runs, secondary rays: the triangle each starts from
  std::vector<RefereeVerdict> truth;   // accuracy runs: the referee's verdict per ray
};

// Rays are stored under a name that carries everything they depend on, so a
// later run (or a later commit) traces exactly the same rays. The scene's name
// is a safe file name: manifests (load_suite) and --scene (choose_scene) check
// every name with scene_name_problem before a run starts.
// With `sources`, the rays are made again (bit-identical) to learn where
// each secondary ray starts; they are not stored in the ray file.
std::vector<Ray> obtain_rays(const RayGenerator& generator, const Scene& scene, const RaySetSpec& spec,
                             const std::string& rays_dir, std::vector<std::int32_t>* sources = nullptr) {
  const std::string path = fmt::format("{}/{}.{}.n{}.{:016x}.npy", rays_dir, scene.name, to_string(spec.kind),
                                       spec.count, generator.key(spec));
  std::error_code ec;
  if (!sources && std::filesystem::exists(path, ec)) {
    try {
      std::vector<Ray> rays = read_ray_file(path);
      // shadow-tiled holds one ray per hit, at most the count asked for.
      if (has_exact_count(spec.kind) ? rays.size() == spec.count : rays.size() <= spec.count) {
        progress(fmt::format("  {} rays: reusing {}", to_string(spec.kind), path));
        return rays;
      }
    } catch (const InputError& e) {
      progress(fmt::format("  warning: stored ray set unusable, regenerating ({})", e.what()));
    }
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<Ray> rays = generator.generate(spec, sources);
  write_ray_file(path, rays);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  progress(fmt::format("  {} rays: generated {} in {:.0f} ms -> {}", to_string(spec.kind), rays.size(), ms, path));
  return rays;
}

struct SceneResults {
  std::vector<ResultRow> rows;
  std::vector<AccuracyRow> accuracy;  // runs with RunOptions::accuracy_csv only
  std::optional<CameraCoverage> camera;  // runs with the primary ray set
  std::vector<SkippedBackend> skipped;
};

// The seed of a scene's round orders: the run's seed and the scene's name,
// so that every scene is shuffled differently and every run alike.
std::uint64_t round_seed(std::uint64_t seed, const std::string& scene) {
  return hash_string(scene.c_str()) ^ (seed * 0x9e3779b97f4a7c15ull);
}

// What every representation of a scene is traced with: its ray sets (made
// or reused, and screened) and, in accuracy runs, the referee's verdicts.
struct SceneRays {
  std::vector<RaySet> raysets;
  std::unique_ptr<Referee> referee;  // accuracy runs: judges the scene as loaded (its analytic primitives)
};

// Scene `index` of `count`: its ray sets and the referee's verdicts on them.
SceneRays make_scene_rays(const RunOptions& options, const LoadedScene& loaded, std::size_t index, std::size_t count) {
  const Scene& scene = loaded.scene;
  const SuiteScene* entry = loaded.choice.entry;
  const SuiteSettings& settings = options.settings;
  SceneRays out;
  std::vector<RaySet>& raysets = out.raysets;
  progress(fmt::format("[{}/{}] {}: ray sets", index + 1, count, scene.name));
  {
    const RayGenerator generator(scene);
    const std::vector<std::string>& names =
        options.raysets_from_command_line || !entry || entry->raysets.empty() ? settings.raysets : entry->raysets;
    for (const std::string& name : names) {
      const RaySetKind kind = parse_rayset_kind(name);
      const std::optional<InsideBall> inside = entry ? entry->inside : std::nullopt;
      if (is_must_hit(kind) && !inside) {
        progress(fmt::format("  {}: skipped, the scene declares no inside ball (closed meshes only)", name));
        continue;
      }
      RaySetSpec spec{kind, settings.rays, settings.seed, entry ? entry->camera : std::nullopt,
                      entry ? entry->light : std::nullopt, inside};
      RaySet set{kind, {}, {}, {}, {}};
      const bool want_sources = !options.accuracy_csv.empty() && has_sources(kind);
      set.rays = obtain_rays(generator, scene, spec, options.rays_dir, want_sources ? &set.sources : nullptr);
      set.screened = screen_rays(set.rays);
      if (!set.screened.screened.empty() || set.screened.raised_tnear)
        progress(fmt::format("  {} rays: {} untraceable (misses for every backend), {} with tnear < 0 raised to 0",
                             name, set.screened.screened.size(), set.screened.raised_tnear));
      raysets.push_back(std::move(set));
    }
  }
  if (!options.accuracy_csv.empty() && !raysets.empty()) {
    const auto start = std::chrono::steady_clock::now();
    out.referee = std::make_unique<Referee>(scene);
    for (RaySet& rs : raysets) {
      rs.truth.resize(rs.rays.size());
      out.referee->judge(rs.rays, rs.truth);
    }
    progress(fmt::format("  referee: judged every ray exactly in {:.0f} ms",
                         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()));
  }
  return out;
}

// One representation of scene `index` of `count`: the scene as loaded
// (stand_in null), or its triangle stand-in traced with the same rays and
// judged by the same referee, its hits read as hits on the primitives they
// stand for. Every backend built, agreement with Embree (on the same
// representation), the timing of every case in rounds, and the ratios to the
// timing `reference` ("" for none) and to embree.
SceneResults measure_scene(const RunOptions& options, const std::string& reference, const LoadedScene& loaded,
                           const SceneRays& scene_rays, const StandIn* stand_in, std::size_t index,
                           std::size_t count) {
  const Scene& scene = stand_in ? stand_in->scene : loaded.scene;
  const SuiteScene* entry = loaded.choice.entry;
  const SuiteSettings& settings = options.settings;
  const std::vector<RaySet>& raysets = scene_rays.raysets;
  const Referee* referee = scene_rays.referee.get();
  const std::string representation =
      stand_in ? stand_in->tessellation.name() : scene.has_analytic() ? "analytic" : "triangles";
  SceneResults results;

  // Backends lacking a primitive type of the scene are skipped for it, with
  // a note: never given a scene they would trace wrongly (a plugin would see
  // only its triangles).
  const std::vector<std::string> runnable = backends_for_scene(settings.backends, scene, results.skipped);
  for (const SkippedBackend& s : results.skipped) progress(fmt::format("  {}: skipped, {}", s.backend, s.reason));

  struct Case {
    std::string name;
    ResultRow row;
    std::optional<AccuracyRow> accuracy;
    const Backend* backend;
    const TraceExecutor* executor;
    const RaySet* rayset;
  };
  std::vector<std::unique_ptr<TraceExecutor>> executors;
  std::vector<std::unique_ptr<Backend>> backends;
  std::vector<Case> cases;
  for (int threads : settings.threads) {
    executors.push_back(std::make_unique<TraceExecutor>(threads));
    const TraceExecutor& executor = *executors.back();
    // Embree's answers, per ray set, for agreement.
    std::unique_ptr<Backend> baseline = make_backend(kAgreementBackend, {threads, settings.huge_pages});
    if (const std::string problem = capability_problem(*baseline, scene); !problem.empty())
      throw std::logic_error("the agreement baseline must model every scene: " + problem);
    executor.run([&] { baseline->build(scene); });
    std::vector<std::vector<Hit>> ref_hits(raysets.size());
    std::vector<std::vector<std::uint8_t>> ref_occ(raysets.size());
    for (std::size_t r = 0; r < raysets.size(); ++r) {
      if (query_of(raysets[r].kind) == Query::kIntersect) ref_hits[r] = executor.answers(*baseline, raysets[r].screened);
      else ref_occ[r] = executor.occlusion_answers(*baseline, raysets[r].screened);
    }
    baseline.reset();
    // What the camera sees, once per scene: Embree's primary hits.
    for (std::size_t r = 0; r < raysets.size() && !results.camera && !stand_in; ++r) {
      if (raysets[r].kind != RaySetKind::kPrimary || ref_hits[r].empty()) continue;
      const auto hit = std::count_if(ref_hits[r].begin(), ref_hits[r].end(), [](const Hit& h) { return h.hit(); });
      results.camera = CameraCoverage{scene.name, static_cast<double>(hit) / static_cast<double>(ref_hits[r].size()),
                                      entry ? fmt::format("scripts/preview_camera {} --suite {}", scene.name,
                                                          options.suite.path)
                                            : fmt::format("scripts/preview_camera {}", loaded.choice.path)};
      if (sees_little(*results.camera)) progress("  warning: " + camera_warning(*results.camera));
    }

    std::vector<Backend*> built;
    for (const std::string& backend_name : runnable) {
      backends.push_back(make_backend(backend_name, {threads, settings.huge_pages}));
      built.push_back(backends.back().get());
    }
    std::vector<std::optional<std::size_t>> huge_page_bytes;
    const std::vector<std::vector<double>> build_times = time_builds_interleaved(
        built, scene, executor, settings.build_repetitions, settings.min_time, &huge_page_bytes);
    for (std::size_t bi = 0; bi < built.size(); ++bi) {
      const std::string& backend_name = runnable[bi];
      const Backend* backend = built[bi];
      const std::vector<double>& build_ms = build_times[bi];
      progress(fmt::format("  built {} ({} threads) in {:.1f} ms, {:.1f} MiB, {}", backend_name, threads,
                           median(build_ms), backend->memory_bytes() / 1048576.0,
                           describe_huge_pages(huge_page_bytes[bi])));
      for (std::size_t r = 0; r < raysets.size(); ++r) {
        const RaySet& rs = raysets[r];
        ResultRow row;
        row.scene = scene.name;
        row.triangles = scene.triangles.size();
        row.rayset = to_string(rs.kind);
        row.query = to_string(query_of(rs.kind));
        row.rays = rs.rays.size();
        row.backend = backend_name;
        row.threads = threads;
        row.build_ms = median(build_ms);
        row.build_ms_min = *std::min_element(build_ms.begin(), build_ms.end());
        row.build_ms_max = *std::max_element(build_ms.begin(), build_ms.end());
        row.memory_bytes = backend->memory_bytes();
        row.sah_cost = backend->sah_cost();
        row.plugin = backend->plugin_name();
        row.representation = representation;
        Agreement a;
        // Accuracy rows are single-run, single thread count: the first one.
        std::optional<AccuracyRow> accuracy;
        if (referee && threads == settings.threads.front()) {
          accuracy.emplace();
          accuracy->scene = scene.name;
          if (entry) {
            accuracy->scale = entry->scale;
            accuracy->offset_x = entry->offset[0];
            accuracy->offset_y = entry->offset[1];
            accuracy->offset_z = entry->offset[2];
          }
          accuracy->rayset = row.rayset;
          accuracy->query = row.query;
          accuracy->backend = backend_name;
          accuracy->accuracy_class = backend->accuracy_class();
          accuracy->representation = representation;
        }
        // Untimed: the answers that count, screened rays forced to misses;
        // the referee judges them against the rays as stored.
        if (query_of(rs.kind) == Query::kIntersect) {
          const std::vector<Hit> hits = executor.answers(*backend, rs.screened);
          require_valid_hits(*backend, hits, scene.primitive_count(), scene.name + "/" + row.rayset);
          a = compare_hits(hits, ref_hits[r], rs.screened.rays, scene.primitives());
          if (accuracy)
            judge_hits(*referee, rs.rays, rs.truth, stand_in ? analytic_hits(hits, *stand_in) : hits, rs.sources,
                       *accuracy);
        } else {
          const std::vector<std::uint8_t> occ = executor.occlusion_answers(*backend, rs.screened);
          require_valid_occlusion(*backend, occ, scene.name + "/" + row.rayset);
          a = compare_occlusion(occ, ref_occ[r]);
          if (accuracy) judge_occlusion(rs.rays, rs.truth, occ, *accuracy);
        }
        row.hit_rate = a.hit_rate();
        row.agree_hit = a.agree_hit();
        row.agree_prim = a.has_prims ? a.agree_prim() : std::nan("");
        row.prim_ties = a.prim_ties;
        row.t_relerr_max = a.has_prims ? a.t_relerr_max : std::nan("");
        row.t_relerr_p999 = a.has_prims ? a.t_relerr_p999 : std::nan("");
        row.disagreements = a.disagreements();
        if (is_must_hit(rs.kind)) row.leaks = a.rays - a.hits;
        const std::string name =
            fmt::format("trace/{}/{}/{}/threads:{}", scene.name, row.rayset, backend_name, threads);
        cases.push_back({name, row, accuracy, backend, &executor, &rs});
      }
    }
  }

  // Time every case of this scene in rounds: round r traces every case once,
  // in an order shuffled per round (measure/gbench.h, run_rounds), so that
  // sample r of every row is from the same stretch of time and a noisy
  // neighbour hits all backends of that round alike.
  std::vector<RoundCase> round_cases;
  for (const Case& c : cases) {
    const Case* cp = &c;
    round_cases.push_back({c.name, [cp](benchmark::State& state) {
                             const std::vector<Ray>& rays = cp->rayset->screened.rays;
                             std::vector<Hit> hits;
                             std::vector<std::uint8_t> occ;
                             const bool intersect = query_of(cp->rayset->kind) == Query::kIntersect;
                             if (intersect) hits.resize(rays.size());
                             else occ.resize(rays.size());
                             for (auto _ : state) {
                               if (intersect) cp->executor->intersect(*cp->backend, rays, hits);
                               else cp->executor->occluded(*cp->backend, rays, occ);
                               benchmark::DoNotOptimize(hits.data());
                               benchmark::DoNotOptimize(occ.data());
                               benchmark::ClobberMemory();
                             }
                             state.counters["rays"] = benchmark::Counter(static_cast<double>(rays.size()),
                                                                         benchmark::Counter::kIsIterationInvariantRate);
                           }});
  }
  progress(fmt::format("[{}/{}] {}: timing {} cases in {} round{}", index + 1, count, scene.name, cases.size(),
                       settings.repetitions, settings.repetitions == 1 ? "" : "s"));
  RoundSettings rounds;
  rounds.rounds = settings.repetitions;
  rounds.min_time = settings.min_time;
  rounds.warmup = settings.warmup;
  rounds.shuffle = options.interleave;
  rounds.seed = round_seed(settings.seed, scene.name);
  rounds.counter = "rays";
  rounds.scale = 1e-6;  // Mrays/s
  const std::vector<std::vector<double>> samples =
      run_rounds(round_cases, rounds, [&](int round, double seconds) {
        progress(fmt::format("  round {}/{} ({} cases) in {:.1f} s", round + 1, settings.repetitions, cases.size(),
                             seconds));
      });
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::vector<double>& s = samples[i];
    ResultRow& row = cases[i].row;
    row.mrays_s_samples = s;  // in round order
    row.reps = static_cast<int>(s.size());
    row.mrays_s = median(s);
    row.mrays_s_min = *std::min_element(s.begin(), s.end());
    row.mrays_s_max = *std::max_element(s.begin(), s.end());
  }
  // Ratios measured in the same run, paired by round (paired_median_ratio):
  // they survive a change of machine, and noise that hits a whole round
  // cancels. Both partner rows are in this scene, so the ratios are final here.
  const auto partner = [&](const Case& c, const std::string& backend) -> const Case* {
    for (const Case& other : cases)
      if (other.row.backend == backend && other.row.rayset == c.row.rayset && other.row.threads == c.row.threads)
        return &other;
    return nullptr;
  };
  for (Case& c : cases) {
    c.row.reference = reference;
    if (const Case* ref = reference.empty() ? nullptr : partner(c, reference))
      c.row.ratio_to_reference = paired_median_ratio(c.row.mrays_s_samples, ref->row.mrays_s_samples);
    if (const Case* embree = partner(c, "embree"))
      c.row.ratio_to_embree = paired_median_ratio(c.row.mrays_s_samples, embree->row.mrays_s_samples);
  }
  for (Case& c : cases) {
    results.rows.push_back(c.row);
    if (c.accuracy) {
      c.accuracy->mrays_s = c.row.mrays_s;
      c.accuracy->mrays_s_min = c.row.mrays_s_min;
      c.accuracy->mrays_s_max = c.row.mrays_s_max;
      results.accuracy.push_back(*c.accuracy);
    }
  }
  return results;
}

// The resolutions scene `loaded` is also traced at as a triangle stand-in
// (scene/tessellate.h): --tessellate's, else the scene's own `tessellate`,
// else the suite's defaults; none for a scene without analytic primitives.
// A scene without spheres is the same stand-in at every resolution (its
// boxes are 12 triangles each): traced once, at the first.
std::vector<Tessellation> stand_ins_of(const RunOptions& options, const LoadedScene& loaded) {
  const SuiteScene* entry = loaded.choice.entry;
  std::vector<Tessellation> list = options.tessellate_from_command_line || !entry || !entry->tessellate
                                       ? options.settings.tessellate
                                       : *entry->tessellate;
  if (!loaded.scene.has_analytic()) return {};
  if (loaded.scene.spheres.empty() && list.size() > 1) list.resize(1);
  return list;
}

// Scene `index` of `count`, then each of its stand-ins (stand_ins_of), one
// at a time, all with the scene's rays: the scene's rows first.
SceneResults measure_representations(const RunOptions& options, const std::string& reference,
                                      const LoadedScene& loaded, std::size_t index, std::size_t count) {
  const SceneRays rays = make_scene_rays(options, loaded, index, count);
  if (rays.raysets.empty()) {
    progress(fmt::format("[{}/{}] {}: no ray set applies, scene skipped", index + 1, count, loaded.scene.name));
    return {};
  }
  SceneResults results = measure_scene(options, reference, loaded, rays, nullptr, index, count);
  for (const Tessellation& t : stand_ins_of(options, loaded)) {
    const StandIn stand_in = tessellate(loaded.scene, t);
    progress(fmt::format("[{}/{}] {}: {} triangles standing for {}, traced with its rays", index + 1, count,
                         stand_in.scene.name, stand_in.scene.triangles.size(), loaded.scene.name));
    SceneResults more = measure_scene(options, reference, loaded, rays, &stand_in, index, count);
    results.rows.insert(results.rows.end(), more.rows.begin(), more.rows.end());
    results.accuracy.insert(results.accuracy.end(), more.accuracy.begin(), more.accuracy.end());
  }
  return results;
}

std::string partial_results_note(const RunOptions& options, std::size_t finished, std::size_t total) {
  return fmt::format("partial results ({} of {} scenes) in {}{}", finished, total, options.out_csv,
                     options.accuracy_csv.empty() ? "" : " and " + options.accuracy_csv);
}

// Rewrites the results (and accuracy) CSV with every finished row, and their
// metadata with status = "partial" and progress = "<k> of <n> scenes", or
// status = "complete" when every scene is done. Signals wait until a CSV and
// its metadata agree. Returns `finished`.
std::size_t write_finished_scenes(const RunOptions& options, const Metadata& run_description,
                                  const std::vector<ResultRow>& rows, const std::vector<AccuracyRow>& accuracy_rows,
                                  std::size_t finished, std::size_t total) {
  Metadata extra = run_description;
  extra.emplace_back("status", finished == total ? "complete" : "partial");
  extra.emplace_back("progress", fmt::format("{} of {} scenes", finished, total));
  const Metadata metadata = collect_metadata(extra);
  const SignalsDeferred deferred;
  write_results_csv(options.out_csv, rows);
  write_metadata(metadata_path_for(options.out_csv), metadata);
  if (!options.accuracy_csv.empty()) {
    write_accuracy_csv(options.accuracy_csv, accuracy_rows);
    write_metadata(metadata_path_for(options.accuracy_csv), metadata);
  }
  set_interrupt_message(finished == total
                            ? fmt::format("the run had finished; results in {}{}", options.out_csv,
                                          options.accuracy_csv.empty() ? "" : " and " + options.accuracy_csv)
                            : partial_results_note(options, finished, total));
  if (finished < total) progress(partial_results_note(options, finished, total));
  return finished;
}

}  // namespace

std::vector<std::string> backends_for_scene(const std::vector<std::string>& names, const Scene& scene,
                                            std::vector<SkippedBackend>& skipped) {
  std::vector<std::string> runnable;
  for (const std::string& name : names) {
    if (const std::string problem = capability_problem(*make_backend(name), scene); !problem.empty()) {
      const bool noted = std::any_of(skipped.begin(), skipped.end(),
                                     [&](const SkippedBackend& s) { return s.scene == scene.name && s.backend == name; });
      if (!noted) skipped.push_back({scene.name, name, problem});
    } else {
      runnable.push_back(name);
    }
  }
  return runnable;
}

std::string memory_policy_description(bool huge_pages, std::string_view thp_mode) {
  if (thp_mode == "always")
    return huge_pages ? "huge pages for every backend (transparent, the kernel's THP mode 'always')"
                      : "ordinary pages requested for every backend, but the kernel's THP mode 'always' may give any "
                        "of them huge pages";
  if (thp_mode == "never")
    return huge_pages ? "huge pages requested for every backend, but the kernel's THP mode 'never' gives none of them "
                        "huge pages"
                      : "ordinary pages for every backend";
  if (thp_mode == "madvise")
    return huge_pages ? "huge pages for every backend (transparent, madvise)" : "ordinary pages for every backend";
  return huge_pages ? "huge pages requested for every backend (transparent, madvise); the kernel's THP mode is unknown"
                    : "ordinary pages requested for every backend; the kernel's THP mode is unknown";
}

std::string timing_reference(const SuiteSettings& settings) {
  const auto in_run = [&](const std::string& name) {
    return std::find(settings.backends.begin(), settings.backends.end(), name) != settings.backends.end();
  };
  if (settings.reference.empty()) return in_run(kDefaultTimingReference) ? kDefaultTimingReference : "";
  if (!in_run(settings.reference))
    throw InputError(settings.reference_given.empty() ? "--reference" : settings.reference_given,
                     fmt::format("{} is not one of the run's backends ({}): add it to --backend or name one of them",
                                 settings.reference, fmt::join(settings.backends, ", ")));
  return settings.reference;
}

namespace {

// What a run knows before it loads a scene: its timing reference and the
// provenance of its backends (metadata). Validates everything cheap first,
// before minutes are spent loading and measuring.
struct RunChecks {
  std::string reference;
  Metadata provenance;
};

RunChecks check_run(const RunOptions& options) {
  const SuiteSettings& settings = options.settings;
  // Validate everything cheap before spending minutes.
  for (const std::string& k : settings.raysets) parse_rayset_kind(k);
  // Making each backend checks its name and options (a plugin: loads it);
  // what its results depend on beyond its name goes into the metadata.
  Metadata provenance;
  for (std::size_t i = 0; i < settings.backends.size(); ++i) {
    const std::string& b = settings.backends[i];
    // The run's memory policy: Embree's recorded device config depends on it.
    const auto backend = make_backend(b, {1, settings.huge_pages});
    if (std::find(settings.backends.begin(), settings.backends.begin() + i, b) != settings.backends.begin() + i) continue;
    for (const auto& [key, value] : backend->provenance()) {
      provenance.emplace_back(fmt::format("provenance.{}.{}", toml_key(b), toml_key(key)), value);
      if (key == "summary") progress(fmt::format("{}: {}", b, value));
    }
  }
  const std::string reference = timing_reference(settings);
  if (settings.rays == 0) throw InputError("", "--rays must be at least 1");
  if (settings.repetitions < 1) throw InputError("", "--reps must be at least 1");
  check_writable(options.out_csv);
  if (!options.accuracy_csv.empty()) check_writable(options.accuracy_csv);
  return {reference, provenance};
}

RunResults run_loaded_scenes(const RunOptions& options, const RunChecks& checks,
                             const std::vector<LoadedScene>& scenes);

}  // namespace

RunResults run_suite(const RunOptions& options) {
  const RunChecks checks = check_run(options);
  std::vector<SceneChoice> chosen = choose_scenes(options.scenes, options.suite);
  if (options.scenes.empty()) {
    for (const SuiteScene& s : options.suite.scenes) {
      if (s.available()) chosen.push_back(choose_scene(s.name, options.suite));
      else if (!s.optional) throw InputError(options.suite.path, fmt::format("scene '{}': {} not found (add optional = true to skip it when absent)", s.name, s.missing()));
      else progress(fmt::format("skipping scene '{}': {} not found", s.name, s.missing()));
    }
    if (chosen.empty()) throw InputError(options.suite.path, "no scene of the suite is available");
  }

  std::vector<LoadedScene> scenes;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    progress(fmt::format("[{}/{}] loading {}", i + 1, chosen.size(), chosen[i].arg));
    scenes.push_back({chosen[i], load_chosen_scene(chosen[i])});
    const Scene& s = scenes.back().scene;
    progress(fmt::format("  {}{}", describe_primitives(s),
                         s.skipped_points + s.skipped_lines
                             ? fmt::format(" ({} points and {} lines skipped)", s.skipped_points, s.skipped_lines)
                             : ""));
  }
  return run_loaded_scenes(options, checks, scenes);
}

RunResults run_scenes(const RunOptions& options, std::vector<Scene> made) {
  const RunChecks checks = check_run(options);
  std::vector<LoadedScene> scenes;
  for (Scene& scene : made) {
    if (const std::string problem = scene_name_problem(scene.name); !problem.empty())
      throw InputError(fmt::format("scene '{}'", printable(scene.name)), problem);
    const SceneChoice choice{scene.name, scene.name, nullptr, scene.source};
    scenes.push_back({choice, std::move(scene)});
  }
  return run_loaded_scenes(options, checks, scenes);
}

namespace {

RunResults run_loaded_scenes(const RunOptions& options, const RunChecks& checks,
                             const std::vector<LoadedScene>& scenes) {
  const SuiteSettings& settings = options.settings;
  const std::string& reference = checks.reference;
  const Metadata& provenance = checks.provenance;
  // A stand-in too large for int32 prim ids fails now, not after the scenes before it.
  for (const LoadedScene& loaded : scenes) {
    for (const Tessellation& t : stand_ins_of(options, loaded)) check_stand_in_size(loaded.scene, t);
    if (loaded.scene.has_analytic() && loaded.scene.spheres.empty() && stand_ins_of(options, loaded).size() == 1)
      progress(fmt::format("{}: no spheres, so one stand-in (boxes are 12 triangles at every resolution)",
                           loaded.scene.name));
  }

  std::vector<std::string> scene_names;
  for (const auto& s : scenes) scene_names.push_back(s.scene.name);
  const std::string thp_mode = transparent_huge_pages_mode();
  Metadata run_description = {
      {"command", options.command_line},
      {"suite", options.suite.path},
      {"scenes", fmt::format("{}", fmt::join(scene_names, ","))},
      {"raysets", fmt::format("{}", fmt::join(settings.raysets, ","))},
      {"backends", fmt::format("{}", fmt::join(settings.backends, ","))},
      {"threads", fmt::format("{}", fmt::join(settings.threads, ","))},
      {"rays", std::to_string(settings.rays)},
      {"seed", std::to_string(settings.seed)},
      {"repetitions", std::to_string(settings.repetitions)},
      {"min_time_s", fmt::format("{}", settings.min_time)},
      {"warmup_s", fmt::format("{}", settings.warmup)},
      {"interleaved", options.interleave ? "true" : "false"},
      {"timing", "rounds"},
      {"reference_backend", reference},
      {"agreement_backend", kAgreementBackend},
      {"memory_policy", memory_policy_description(settings.huge_pages, thp_mode)},
      {"thp", thp_mode},
  };
  std::vector<std::string> tessellate;
  for (const Tessellation& t : settings.tessellate) tessellate.push_back(t.spec());
  run_description.emplace_back("tessellate", fmt::format("{}", fmt::join(tessellate, ",")));
  run_description.insert(run_description.end(), provenance.begin(), provenance.end());

  // Rounds are ordered by run_rounds itself, reproducibly: Google Benchmark's
  // own random interleaving would reorder each round from a random device.
  initialize_google_benchmark({"--benchmark_enable_random_interleaving=false"});
  RunResults results;
  std::vector<ResultRow>& rows = results.rows;
  std::vector<AccuracyRow>& accuracy_rows = results.accuracy;
  std::size_t finished = 0;  // scenes whose rows are on disk
  set_interrupt_message(fmt::format("no scene had finished; nothing written to {}", options.out_csv));
  try {
    for (std::size_t si = 0; si < scenes.size(); ++si) {
      SceneResults scene = measure_representations(options, reference, scenes[si], si, scenes.size());
      rows.insert(rows.end(), scene.rows.begin(), scene.rows.end());
      accuracy_rows.insert(accuracy_rows.end(), scene.accuracy.begin(), scene.accuracy.end());
      if (scene.camera) results.cameras.push_back(*scene.camera);
      for (const SkippedBackend& s : scene.skipped) {
        run_description.emplace_back(fmt::format("skipped.{}.{}", toml_key(s.scene), toml_key(s.backend)), s.reason);
        results.skipped.push_back(s);
      }
      finished = write_finished_scenes(options, run_description, rows, accuracy_rows, si + 1, scenes.size());
    }
  } catch (const std::exception& e) {
    // What is on disk stays: the error says where, so that minutes of
    // measurement are not lost to a failure in a later scene.
    if (finished == 0) throw;
    const std::string what = dynamic_cast<const std::bad_alloc*>(&e) ? "out of memory" : e.what();
    throw std::runtime_error(fmt::format("{} (in scene {} of {}); {}", what, finished + 1, scenes.size(),
                                         partial_results_note(options, finished, scenes.size())));
  }
  if (!options.accuracy_csv.empty())
    progress(fmt::format("accuracy: {} ({} rows)", options.accuracy_csv, accuracy_rows.size()));
  return results;
}

}  // namespace

}  // namespace raybench
