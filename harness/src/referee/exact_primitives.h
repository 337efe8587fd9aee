// Exact referees for one box (AABB), one oriented box (OBB) or one sphere:
// hit or miss, and t, as real-number arithmetic answers for the float inputs
// actually given (every float is a rational number). They judge the
// single-primitive kernels (prim/aabb_*.h, prim/obb_*.h, prim/sphere_*.h) in
// `raybench accuracy-kernels`; referee/exact_triangle.h is the triangle one.
//
// The semantics they decide and the accuracy of t: above ExactPrimitiveHit.
#pragma once

#include <limits>

#include "raybench/math/bbox.h"
#include "raybench/math/ray.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/sphere.h"

namespace raybench {

// Semantics (../shared/EXTREMES.md, "Decide the semantics"):
// - The ray: o + t d for t in (lo, tfar], lo = max(tnear, 0): open at lo,
//   closed at tfar (math/ray.h). tnear and tfar may be infinite; an empty
//   interval hits nothing.
// - A ray is judged only when is_exact_ray() holds: origin and direction
//   finite, tnear and tfar not NaN, d != 0. Anything else hits nothing (G15:
//   the truth for an invalid ray is a miss). The length of d is no criterion:
//   hit/miss must not depend on it (G16), so a direction of length 1e-40 or
//   FLT_MAX is a ray like any other, and so are coordinates beyond Embree's
//   1.844e18 (is_traceable is Embree's range, not geometry).
// - Box: the closed solid lower <= p <= upper. Along the ray it occupies
//   [E, X]: per axis, d_i != 0 gives the slab's t-range between
//   (lower_i - o_i) / d_i and (upper_i - o_i) / d_i; d_i = +0 or -0 keeps
//   every t when lower_i <= o_i <= upper_i (closed) and none otherwise, so the
//   sign of zero never matters (G09). Hit when [E, X] meets (lo, tfar].
//   t = E when E > lo (entering); otherwise the ray starts in or on the box
//   and t = min(X, tfar), the exit (G10), flagged `exit`. A box test reports
//   these as BoxHit::t_entry / t_exit (prim/aabb.h).
// - OBB: the set { p : |(p - c).a_i| <= h_i, i = 0, 1, 2 } with the float
//   axes a_i taken exactly as given: they are only approximately unit length
//   and orthogonal, and are neither normalised nor orthogonalised. That is
//   the set prim/obb_eigen.h's frame change describes (to_box * (p - c)
//   projects onto the given axes). Then as for the box, per axis with
//   e_i = (o - c).a_i and f_i = d.a_i (f_i = 0: inside iff |e_i| <= h_i).
// - Sphere: the surface |p - c|^2 = r^2 (r^2 of the float r, exact), not the
//   ball, as the sphere tests report surface crossings (prim/sphere.h). With
//   f = o - c, a = d.d, b = f.d, C = f.f - r^2 and D = b^2 - aC, the roots
//   t0 <= t1 are (-b -/+ sqrt(D)) / a. Hit when a root lies in (lo, tfar]; a
//   tangent ray (D = 0) hits; a ray from inside hits the far side. t is the
//   first root in the interval; `exit` when that is t1 (origin inside, G10).
//   Every decision compares a root with a rational v without a square root:
//   sign(root - v) = sign(w +/- sqrt(D)) with w = -b - a v, and
//   sign(w + sqrt(D)) is +1 for w >= 0 (unless w = D = 0) and sign(D - w^2)
//   for w < 0 (and mirrored for the minus root).
// - `start_contact`: the ray misses, but the primitive contains the point at
//   t = lo exactly (e.g. the origin on a face, pointing outward: G11). Box
//   tests close their interval at tnear ([tnear, tmax], prim/aabb.h) and count
//   such a ray as a hit; raybench's ray interval, open at lo, does not. Which
//   one is right is a policy (EXTREMES.md: Embree's two modes differ), so the
//   harness counts these rays as ambiguous.
//
// Accuracy of t. Box and OBB: t is a rational, rounded to the nearest double
// (MPFR at 53 bits, round-to-nearest: correctly rounded). Sphere: the chosen
// root of a quadratic with exact rational coefficients, evaluated with 256-bit
// MPFR in the cancellation-free form q = -(b + sign(b) sqrt(D)), roots q/a and
// C/q (Haines et al., Ray Tracing Gems ch. 7, eq. 7.7); which of q/a and C/q
// is t0 is decided exactly by the sign of b. Each MPFR step rounds once at
// 2^-256 relative, so the root is within 2^-250 relative of the exact value
// before it is rounded to double: the nearest double, except when the exact
// root lies within 2^-250 (relative) of a midpoint between two doubles, and
// in every case within one double ulp, i.e. 2^-29 float ulps.
//
// Primitives must be finite: a NaN or infinite coordinate, radius or half
// extent throws std::invalid_argument, except the empty box (lower > upper on
// some axis, as BBox starts), which nothing hits. A negative half extent is
// an empty OBB; a negative radius is the sphere of radius |r| (only r^2 is used).
struct ExactPrimitiveHit {
  bool hit = false;
  // Hits: the double nearest the exact t (see the accuracy note above); NaN on a miss.
  double t = std::numeric_limits<double>::quiet_NaN();
  // Hits: t is the second crossing (the box's exit, the sphere's far root)
  // because the ray starts inside, or on the surface pointing in.
  bool exit = false;
  // Misses: the primitive is touched at t = lo exactly (see above).
  bool start_contact = false;
};

// The rays the referees judge: origin and direction finite, tnear and tfar
// not NaN, direction not zero. Any length of direction is a ray.
bool is_exact_ray(const Ray& ray);

ExactPrimitiveHit exact_intersect(const Ray& ray, const BBox& box);
ExactPrimitiveHit exact_intersect(const Ray& ray, const OrientedBox& box);
ExactPrimitiveHit exact_intersect(const Ray& ray, const Sphere& sphere);

// The same primitives as the surfaces of a scene (issue 31,
// prim/analytic_hit.h): the ray hits at the first crossing of the boundary
// in (lo, tfar]. For a box or OBB the solid occupies [E, X] along the ray:
// t = E when E lies in (lo, tfar]; otherwise t = X (`exit`) when X does;
// otherwise a miss. It differs from exact_intersect's solid answer only for
// a ray that starts inside and ends inside (X > tfar): no crossing, a miss.
// A sphere's answer is exact_intersect's (already a surface).
// `start_contact` here means the surface contains the point at t = lo
// exactly, for hits too: the origin lies on the surface (E = lo, pointing in:
// the hit is the exit; X = lo, pointing out: a miss). A float test sees such
// an origin on either side of the surface, so the referee counts the ray as
// ambiguous.
ExactPrimitiveHit exact_intersect_surface(const Ray& ray, const BBox& box);
ExactPrimitiveHit exact_intersect_surface(const Ray& ray, const OrientedBox& box);
ExactPrimitiveHit exact_intersect_surface(const Ray& ray, const Sphere& sphere);

}  // namespace raybench
