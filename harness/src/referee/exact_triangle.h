// The exact ray-triangle judgement behind the `reference` backend and the
// accuracy report: hit or miss, and t, as real-number arithmetic would answer
// for the float inputs actually given (every float is a rational number).
//
// Semantics (docs/accuracy.md; ../shared/EXTREMES.md, "Decide the
// semantics"): triangles are closed and two-sided; the ray covers
// (max(tnear, 0), tfar]; a degenerate (zero-area) triangle is never hit, and
// neither is a triangle whose plane contains the ray (G08, G19); an
// untraceable ray (is_traceable) hits nothing.
//
// Method: with a = v0 - o, b = v1 - o, c = v2 - o, the signed volumes
// e0 = d.(b x c), e1 = d.(c x a), e2 = d.(a x b) sum to den = d.n, where
// n = (v1 - v0) x (v2 - v0), and e_i / den are the barycentric coordinates of
// the point where the ray's line meets the plane (the Plücker-style test of
// Möller-Trumbore's and Woop's papers, here without rounding). The ray's line
// crosses the closed triangle iff den != 0 and no e_i has the opposite sign
// of den; t = (a.n) / den. Every sign is first decided in interval arithmetic
// (CGAL::Interval_nt); only when an interval straddles zero is it recomputed
// with GMP rationals (CGAL::Gmpq) — the filtered-predicate scheme EXTREMES.md
// measured ("Ground truth is affordable").
#pragma once

#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct ExactTriangleHit {
  bool hit = false;
  // The exact hit point lies on an edge or a vertex (some e_i is exactly 0):
  // the ray has several right answers when a neighbour shares that edge.
  bool on_boundary = false;
  // When hit, t_lower <= exact t <= t_upper, and t is the double nearest to
  // the exact t (with TValue::kEnclosed, only some double in the interval).
  double t = 0.0, t_lower = 0.0, t_upper = 0.0;
  // Approximate smallest barycentric coordinate of the line's crossing of
  // the plane (negative outside the triangle), NaN when there is no single
  // crossing. Near zero means "within rounding of an edge".
  double min_barycentric = 0.0;
  // Approximate t of that crossing (also for misses).
  double plane_t = 0.0;
  // The computation needed exact rationals (the interval filter could not decide).
  bool exact_fallback = false;
};

// How exactly t is wanted: rounded to nearest needs rationals for every hit;
// an enclosing interval a few double ulps wide usually does not.
enum class TValue { kNearest, kEnclosed };

ExactTriangleHit exact_intersect(const Ray& ray, const Triangle& triangle, TValue t_value = TValue::kNearest);

// Exact three-way comparison of the t at which the ray's line crosses the
// planes of two triangles, each crossed once (den != 0): -1, 0 or +1.
int compare_exact_t(const Ray& ray, const Triangle& a, const Triangle& b);

// Whether the ray's line crosses the planes of both triangles once and at
// exactly the same t (coincident or coplanar geometry): two tracers that
// report these two triangles have both found the nearest distance, each
// rounding its own way.
bool same_exact_t(const Ray& ray, const Triangle& a, const Triangle& b);

}  // namespace raybench
