// The triangle as every ray-triangle test receives it, and what a test returns.
#pragma once

#include <string_view>

#include "raybench/math/bbox.h"
#include "raybench/math/vec.h"

namespace raybench {

struct Triangle {
  Vec3f v0, v1, v2;
};

// The triangle's axis-aligned box.
inline BBox triangle_bounds(const Triangle& t) {
  BBox b;
  b.extend(t.v0);
  b.extend(t.v1);
  b.extend(t.v2);
  return b;
}

// What a ray-triangle test reports: distance along the ray and the
// barycentric coordinates of the hit, p = (1-u-v) v0 + u v1 + v v2.
struct TriangleHit {
  float t, u, v;
};

// Every ray-triangle test is a policy type with this shape (see triangle_mt.h):
//   name, description, accuracy          what the harness and the CSV call it
//   Prepared prepare(const Triangle&)    per-triangle data, stored by the BVH in leaf order
//   RayData precompute(const Ray&)       per-ray data, computed once per traversal
//   bool intersect(const RayData&, float tmax, const Prepared&, TriangleHit&)
//                                        hit at t in (tnear, tmax]? fills the hit
//   bool intersect(const Ray&, float tmax, const Triangle&, TriangleHit&)
//                                        the same without precomputation (tests, tools)
// No exceptions, no allocation; NaN input is a miss unless a seed-faithful
// variant documents otherwise.

// How far a variant's answers can be trusted; the harness reports it beside
// each kernel so that a user reads speed next to what was traded for it.
enum class AccuracyClass {
  kEpsilon,       // decides with absolute epsilons: answers depend on the scene's scale
  kFast,          // plain float arithmetic, no epsilons; cracks on shared edges possible
  kWatertight,    // no ray passes between triangles that share an edge or vertex
  kConservative,  // may report extra hits, never misses one (box tests)
  kReference,     // higher precision, for judging the others
};

constexpr std::string_view to_string(AccuracyClass c) {
  switch (c) {
    case AccuracyClass::kEpsilon: return "epsilon";
    case AccuracyClass::kFast: return "fast";
    case AccuracyClass::kWatertight: return "watertight";
    case AccuracyClass::kConservative: return "conservative";
    case AccuracyClass::kReference: return "reference";
  }
  return "unknown";
}

}  // namespace raybench
