// The results CSV: one row per (scene, ray set, backend, threads). The
// column list below is the schema, documented in docs/formats.md.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace raybench {

struct ResultRow {
  std::string scene;
  std::size_t triangles = 0;
  std::string rayset;
  std::string query;  // intersect | occluded
  std::size_t rays = 0;
  std::string backend;
  int threads = 1;
  double build_ms = 0, build_ms_min = 0, build_ms_max = 0;
  std::size_t memory_bytes = 0;
  double mrays_s = 0, mrays_s_min = 0, mrays_s_max = 0;
  int reps = 0;
  std::vector<double> mrays_s_samples;  // one per repetition, in run order
  double ratio_to_embree = 0;           // median / the embree row's median, same scene, ray set, threads; 0 if none
  double hit_rate = 0, agree_hit = 0;
  double agree_prim = 0;                 // NaN for occlusion queries
  std::size_t prim_ties = 0;
  double t_relerr_max = 0, t_relerr_p999 = 0;  // NaN for occlusion queries
  std::size_t disagreements = 0;
  // Must-hit ray sets only (G01-G03): rays this backend reports as misses.
  std::optional<std::size_t> leaks;
  // SAH cost of the backend's tree (Backend::sah_cost); NaN when not applicable.
  double sah_cost = std::numeric_limits<double>::quiet_NaN();
  // The run's timing reference (--reference, default embree) and this row's
  // speed relative to it: the median over the interleaved rounds of
  // (this row's sample / the reference's sample of the same round); 0 if none.
  std::string reference;
  double ratio_to_reference = 0;
  // Plugins (--backend plugin:PATH.so): the name the plugin reports; empty
  // for built-in backends.
  std::string plugin;
  // What the scene's primitives were traced as (issue 31): "triangles" (a
  // scene without analytic primitives), "analytic" (spheres, boxes and
  // oriented boxes as such), or "uv<S>x<R>" (the scene's triangle stand-in,
  // scene/tessellate.h, scene "<scene>@uv<S>x<R>"). Empty in older files.
  std::string representation;
};

// Column names in file order. Columns are only ever appended, so a reader
// that looks columns up by name reads older files too.
const std::vector<std::string>& result_columns();

// Writes header and rows atomically (see atomic_file.h). NaN is written as an
// empty field ("not applicable").
void write_results_csv(const std::string& path, const std::vector<ResultRow>& rows);

// Reads a results CSV into column -> value maps (tests and tools); throws
// InputError when the header lacks a schema column. Columns appended after
// the first schema (sah_cost ... representation) may be missing, as in files older than them:
// they read as the empty field, "not applicable". `lines`, when given,
// receives each row's line number (see read_csv_rows).
std::vector<std::map<std::string, std::string>> read_results_csv(const std::string& path,
                                                                 std::vector<std::size_t>* lines = nullptr);

}  // namespace raybench
