// The accuracy CSV (results/accuracy.csv and results/accuracy-kernels.csv):
// one row per (scene, transform, ray set, backend), every ray judged against
// the exact referee. The column list below is the schema, documented in
// docs/accuracy.md and docs/formats.md. Rates are fractions of the row's rays.
#pragma once

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace raybench {

struct AccuracyRow {
  std::string scene;
  // The scene as traced: every vertex v became float(scale * v + offset).
  double scale = 1.0;
  double offset_x = 0.0, offset_y = 0.0, offset_z = 0.0;
  std::string rayset;
  std::string query;    // intersect | occluded
  std::string backend;  // a backend name, or kernel:<variant> for single-primitive rows
  std::string accuracy_class;  // fast | epsilon | watertight | robust | conservative | reference | exact
  std::size_t rays = 0;
  double invalid = 0.0;     // untraceable rays (NaN, Inf, ...): the truth for them is a miss
  double truth_hits = 0.0;  // rays the referee says hit (are occluded)
  // Scenes: rays within the referee's ambiguity band of an edge or vertex,
  // or with tied nearest hits. Single primitives: rays that touch the
  // primitive only at t = max(tnear, 0) (a closed-at-tnear kernel hits them).
  double ambiguous = 0.0;
  double false_miss = 0.0;  // the referee says hit, the backend misses
  double false_hit = 0.0;   // the referee says miss, the backend hits
  double wrong_prim = 0.0;  // both hit, the backend's primitive is not one the referee accepts (unambiguous rays only)
  double self_hits = NAN;   // secondary rays: hits on the primitive the ray starts from
  // |t - t_exact| in units of the float ulp at t_exact, over rays both hit.
  double ulp_p50 = NAN, ulp_p99 = NAN, ulp_max = NAN;
  // Throughput of this backend on these rays (median of repetitions, one thread).
  double mrays_s = NAN, mrays_s_min = NAN, mrays_s_max = NAN;
  // |t - t_exact| / t_exact over the same rays as the ulps: the depth error
  // in relative terms (a tessellated sphere's is far above rounding).
  double t_relerr_p99 = NAN, t_relerr_max = NAN;
  // As in the results CSV (results_csv.h): triangles, analytic or
  // uv<S>x<R>, the stand-in of the scene before the '@' judged against that
  // scene's referee. Empty in files older than the column.
  std::string representation;

  double error_rate() const { return false_miss + false_hit + wrong_prim; }
};

const std::vector<std::string>& accuracy_columns();

// Writes header and rows atomically; NaN is an empty field.
void write_accuracy_csv(const std::string& path, const std::vector<AccuracyRow>& rows);
// Throws InputError on a missing column, a ragged line or a bad number. The
// columns appended with issue 31 (t_relerr_p99, t_relerr_max,
// representation) may be missing, as in older files: they read as empty.
std::vector<AccuracyRow> read_accuracy_csv(const std::string& path);

}  // namespace raybench
