// What every ray-box (AABB) test shares: the hit record, and the contract.
//
// A box test is a policy type (aabb_slab_seed.h, aabb_slab.h,
// aabb_slab_robust.h) with `name`, `description`, `accuracy`, a per-ray
// `Precomputed`, `precompute(ray)` and
//   intersect(const Precomputed&, const BBox&, float tmax, BoxHit& out)
// which is true when the ray's parameter interval [ray.tnear, tmax] (tnear as
// given, both ends closed) meets the closed box [lower, upper]. A box test is
// a culling test, not a surface hit: closing both ends keeps a primitive
// lying exactly at tnear or tmax reachable, and the primitive test decides.
// On a hit, out is the overlap of that interval with the box's interval
// along the ray (SlabRobust pads t_exit by its error bound); on a miss out is
// left untouched (as the triangle tests do).
#pragma once

#include "raybench/math/bbox.h"
#include "raybench/math/ray.h"
#include "raybench/prim/triangle.h"  // AccuracyClass

namespace raybench {

// The part of the ray inside the box, clipped to the ray's interval:
// t_entry <= t_exit. A ray starting inside the box has t_entry = tnear.
struct BoxHit {
  float t_entry, t_exit;
};

}  // namespace raybench
