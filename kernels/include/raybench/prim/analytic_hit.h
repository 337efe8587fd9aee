// Analytic primitives in a scene are surfaces (issue 31, docs/scenes.md): a
// ray hits a sphere, box or oriented box where it crosses its surface, at the
// first crossing in the ray's interval (tnear, tmax]. A ray that starts
// inside (or on the surface, pointing in) hits the far side: the exit. This
// is the sphere tests' own semantics (prim/sphere.h); a box test (prim/aabb.h)
// answers for the solid, so its answer is read as two crossings here.
//
// These are the scalar scene-level tests every one of our backends and the
// ray generators use, with the primitive test as a policy type (the fixed
// defaults SpherePrecise, Slab, Obb, or the seed-faithful variants). A hit
// fills t and leaves u = v = 0: analytic hits have no barycentrics; the
// normal follows from the hit point (sphere: (p - c) / r; box: the face
// whose plane holds p).
#pragma once

#include <limits>

#include "raybench/math/ray.h"
#include "raybench/prim/aabb.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/sphere.h"

namespace raybench {

// The first of two crossings t_in <= t_out lying in (lo, tmax], or false.
// A crossing at t = +inf is none: a box test gives t_exit = +inf to a ray
// starting inside whose direction is zero or so small that 1/d overflows,
// which crosses nothing (and a hit at infinite t is no answer: answer_check.h).
inline bool first_crossing(float t_in, float t_out, float lo, float tmax, float& t) {
  constexpr float kNever = std::numeric_limits<float>::infinity();
  if (t_in > lo && t_in <= tmax && t_in < kNever) {
    t = t_in;
    return true;
  }
  if (t_out > lo && t_out <= tmax && t_out < kNever) {
    t = t_out;
    return true;
  }
  return false;
}

template <typename SphereTest>
inline bool intersect_sphere_surface(const Ray& ray, float tmax, const Sphere& s, float& t) {
  SphereHit h;
  if (!SphereTest::intersect(ray, tmax, s, h)) return false;
  return first_crossing(h.t_near, h.t_far, ray.tnear, tmax, t);
}

// A box test asked over [tnear, +inf) gives the solid's entry (clipped to
// tnear when the ray starts inside) and its exit.
template <typename BoxTest>
inline bool intersect_box_surface(const typename BoxTest::Precomputed& pre, const Ray& ray, float tmax,
                                  const BBox& box, float& t) {
  BoxHit h;
  if (!BoxTest::intersect(pre, box, std::numeric_limits<float>::infinity(), h)) return false;
  return first_crossing(h.t_entry, h.t_exit, ray.tnear, tmax, t);
}

template <typename ObbTest>
inline bool intersect_obb_surface(const Ray& ray, float tmax, const OrientedBox& box, float& t) {
  BoxHit h;
  if (!ObbTest::intersect(ray, std::numeric_limits<float>::infinity(), box, h)) return false;
  return first_crossing(h.t_entry, h.t_exit, ray.tnear, tmax, t);
}

}  // namespace raybench
