// `raybench accuracy-kernels`: every kernel variant of the box, OBB, sphere
// and triangle families (variants.h), alone, on the primitive-level extreme
// ray sets of ../shared/EXTREMES.md (accuracy/prim_raysets.h), every ray
// judged against an exact referee (referee/exact_primitives.h for boxes,
// OBBs and spheres; referee/exact_triangle.h for triangles). One row per
// (ray set, variant) in the accuracy CSV schema (accuracy/accuracy_csv.h):
//   scene          prim:box | prim:obb | prim:sphere | prim:triangle
//   rayset         the EXTREMES.md name, with a parameter suffix where swept
//   backend        kernel:<variant name>; accuracy_class its AccuracyClass
//   query          intersect
//   invalid        rays that are no ray (is_exact_ray: NaN/Inf in origin or
//                  direction, NaN tnear/tfar, d = 0): the truth is a miss.
//                  They are NOT screened here: the kernel sees them, so a
//                  kernel that hits a NaN ray shows a false hit (G15)
//   truth_hits     rays the referee says hit
//   ambiguous      rays whose answer is a policy, not a number: the
//                  primitive is touched at t = max(tnear, 0) only (G09, G11:
//                  an origin on the surface pointing outward). The referee's
//                  interval is open there and calls them misses; box tests
//                  close it ([tnear, tmax], prim/aabb.h) and hit. They are
//                  counted in false_hit too, and listed here so that a reader
//                  can tell the policy difference from an error
//   false_miss, false_hit   against the referee; wrong_prim 0 (one primitive)
//   ulp_*          |t - t_exact| / (float ulp at t_exact) over rays both hit,
//                  nearest-rank p50, p99 and max; t_exact beyond FLT_MAX is
//                  left out (no float can hold it); a non-finite kernel t
//                  counts as an infinite error. Which t: the entry (box,
//                  OBB), near root (sphere) or t (triangle) when the referee's
//                  first crossing is the entry; the exit / far root when the
//                  ray starts inside (G10), as the variants report them
//   mrays_s[_min,_max]  million ray-primitive tests per second (one thread):
//                  the loop over the set's rays, each call including the
//                  variant's per-ray precomputation (triangles: per-triangle
//                  data prepared beforehand, as a BVH stores it); median,
//                  min and max of `repetitions` timed repetitions, each
//                  repeating the loop for at least 2 ms
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "accuracy/accuracy_csv.h"

namespace raybench {

struct KernelAccuracyOptions {
  std::string out_csv;      // written with a .meta.toml beside it; empty: nothing written
  std::string filter;       // substring of "<scene>/<rayset>/<backend>"; empty: all
  std::size_t rays = 4096;  // per ray set
  std::uint64_t seed = 1;
  int repetitions = 5;
  std::string command_line;
  // When set, every ray set judged is stored here as two .npy files, like
  // every raybench ray set: <scene>.<rayset>.n<N>.seed<S>.rays.npy (float32,
  // (N, 8), the ray-file format) and ….prims.npy (float64, (N, K): the
  // primitive each ray is tested against, its K floats in declaration order).
  std::string rays_dir;
};

// Builds the ray sets, judges every ray, times every variant; writes the CSV
// (and metadata) when out_csv is set. Throws InputError on bad options or a
// filter that matches nothing.
std::vector<AccuracyRow> run_kernel_accuracy(const KernelAccuracyOptions& options);

std::string format_kernel_accuracy_table(const std::vector<AccuracyRow>& rows);

}  // namespace raybench
