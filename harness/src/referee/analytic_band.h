// The ambiguity band of an analytic primitive (issue 31): where a float test
// may fairly answer either way because the ray passes within rounding of the
// primitive's silhouette, edges or corners. It plays the part that the
// barycentric distance from an edge (ExactTriangleHit::min_barycentric)
// plays for triangles, with the same relative width (kAmbiguityBand,
// referee/referee.h): a fraction of the primitive's own size, never of the
// ray's distance, so a far ray is judged as strictly as a near one.
//
// - Sphere: the ray's line passes the centre at distance h; it is within the
//   band when |r^2 - h^2| <= 2 band r^2, i.e. |h - r| <~ band r (tangent).
// - Box and OBB (in the box's frame, on the given axes): the hit point lies
//   within band * extent of the planes of two or more faces (an edge or a
//   corner; extent: the box's size along that axis); a miss is within the
//   band when the ray meets the box grown by band * extent on every side.
//
// Approximate on purpose: computed in double from the float inputs; only the
// hit/miss decision and t (referee/exact_primitives.h) must be exact, the
// band says which rays a fair judge should not count against a kernel.
#pragma once

#include "raybench/math/bbox.h"
#include "raybench/math/ray.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/sphere.h"

namespace raybench {

// A hit at (exact) t: is the hit within the band of a silhouette, edge or corner?
bool near_boundary(const Ray& ray, const Sphere& sphere, double t, double band);
bool near_boundary(const Ray& ray, const BBox& box, double t, double band);
bool near_boundary(const Ray& ray, const OrientedBox& box, double t, double band);

// A miss: the smallest t in (lo, hi] at which the ray passes within the band
// of the primitive (the closest approach to a sphere, the entry into the
// grown box), or +inf when it does not.
double near_miss_t(const Ray& ray, const Sphere& sphere, double lo, double hi, double band);
double near_miss_t(const Ray& ray, const BBox& box, double lo, double hi, double band);
double near_miss_t(const Ray& ray, const OrientedBox& box, double lo, double hi, double band);

}  // namespace raybench
