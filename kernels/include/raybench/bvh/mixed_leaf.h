// What the leaves of our BVHs over mixed primitive types (issue 31:
// triangles, spheres, boxes, oriented boxes; mixed_bvh2.h, mixed_wide_bvh.h)
// test beyond triangles: the analytic primitives, copied in leaf order, each
// reached through a 32-bit reference (its kind in the top two bits, its index
// among the leaf-ordered primitives of that kind below), and the scene-level
// surface tests of prim/analytic_hit.h that judge them.
//
// The tests are our defaults, SpherePrecise, Slab and Obb, or, chosen per
// type, the seed-faithful SphereSeed, SlabSeed and ObbSeed, so that what the
// seed notes get wrong shows at scene level (backends: bvh2:sphere_seed,
// :box_seed, :obb_seed). The choice is a flag read per primitive, not a
// template parameter: the branch it costs is predictable and small beside a
// test of tens of operations (the OBB test alone rotates the ray in
// double), and it keeps one instantiation of each mixed traversal per
// triangle test and box test, where templates would make eight.
// Semantics (analytic_hit.h): a hit is the first surface crossing in
// (tnear, tmax]; a ray starting inside hits the exit; u = v = 0.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raybench/bvh/analytic_test_choice.h"
#include "raybench/bvh/huge_pages.h"
#include "raybench/math/ray.h"
#include "raybench/prim/aabb_slab.h"
#include "raybench/prim/aabb_slab_seed.h"
#include "raybench/prim/analytic_hit.h"
#include "raybench/prim/obb_eigen.h"
#include "raybench/prim/obb_seed.h"
#include "raybench/prim/primitives.h"
#include "raybench/prim/sphere_precise.h"
#include "raybench/prim/sphere_seed.h"

namespace raybench {

// A leaf's reference to a primitive: kind (PrimitiveKind) in bits 30-31,
// the index among the leaf-ordered primitives of that kind in bits 0-29.
inline constexpr std::uint32_t kMixedRefIndexBits = 30;
inline constexpr std::uint32_t kMixedRefIndexMask = (1u << kMixedRefIndexBits) - 1u;
// The most primitives of one kind a mixed BVH holds (the index's range).
inline constexpr std::size_t kMaxMixedPrimsPerKind = std::size_t{1} << kMixedRefIndexBits;

constexpr std::uint32_t mixed_ref(PrimitiveKind kind, std::size_t index) {
  return static_cast<std::uint32_t>(kind) << kMixedRefIndexBits | static_cast<std::uint32_t>(index);
}
constexpr PrimitiveKind mixed_ref_kind(std::uint32_t ref) { return static_cast<PrimitiveKind>(ref >> kMixedRefIndexBits); }
constexpr std::uint32_t mixed_ref_index(std::uint32_t ref) { return ref & kMixedRefIndexMask; }

// What the analytic tests need of a ray, computed once per traversal: the
// ray (the sphere and OBB tests, SlabSeed's Precomputed is the ray itself)
// and Slab's reciprocal direction.
struct AnalyticRay {
  Ray ray;
  Slab::Precomputed slab;

  static AnalyticRay precompute(const Ray& ray) { return {ray, Slab::precompute(ray)}; }
};

// The analytic primitives of a mixed BVH in leaf order, and the tests that
// judge them.
struct AnalyticLeafPrims {
  std::vector<Sphere> spheres;
  std::vector<BBox> boxes;
  std::vector<OrientedBox> obbs;
  AnalyticTestChoice tests;

  // Appends analytic primitive `id` of `prims` (kind(id) != kTriangle);
  // returns its reference.
  std::uint32_t add(const PrimitiveSpans& prims, std::size_t id) {
    const std::size_t i = prims.local(id);
    switch (prims.kind(id)) {
      case PrimitiveKind::kSphere: spheres.push_back(prims.spheres[i]); return mixed_ref(PrimitiveKind::kSphere, spheres.size() - 1);
      case PrimitiveKind::kBox: boxes.push_back(prims.boxes[i]); return mixed_ref(PrimitiveKind::kBox, boxes.size() - 1);
      case PrimitiveKind::kOrientedBox: obbs.push_back(prims.obbs[i]); return mixed_ref(PrimitiveKind::kOrientedBox, obbs.size() - 1);
      case PrimitiveKind::kTriangle: break;
    }
    return mixed_ref(PrimitiveKind::kTriangle, 0);  // not reached: triangles are the caller's
  }

  std::size_t memory_bytes() const {
    return spheres.size() * sizeof(Sphere) + boxes.size() * sizeof(BBox) + obbs.size() * sizeof(OrientedBox);
  }

  // The surface hit of the analytic primitive `ref` in (ray.tnear, tmax]: t
  // and true, or false (t untouched).
  bool intersect(const AnalyticRay& r, float tmax, std::uint32_t ref, float& t) const {
    const std::uint32_t i = mixed_ref_index(ref);
    switch (mixed_ref_kind(ref)) {
      case PrimitiveKind::kSphere:
        return tests.sphere_seed ? intersect_sphere_surface<SphereSeed>(r.ray, tmax, spheres[i], t)
                                 : intersect_sphere_surface<SpherePrecise>(r.ray, tmax, spheres[i], t);
      case PrimitiveKind::kBox:
        return tests.box_seed ? intersect_box_surface<SlabSeed>(SlabSeed::Precomputed{r.ray}, r.ray, tmax, boxes[i], t)
                              : intersect_box_surface<Slab>(r.slab, r.ray, tmax, boxes[i], t);
      case PrimitiveKind::kOrientedBox:
        return tests.obb_seed ? intersect_obb_surface<ObbSeed>(r.ray, tmax, obbs[i], t)
                              : intersect_obb_surface<Obb>(r.ray, tmax, obbs[i], t);
      case PrimitiveKind::kTriangle: break;
    }
    return false;
  }
};

// The boxes the mixed BVHs are built over: prims.bounds(id) for every id,
// computed on every thread into memory not zeroed first (the serial loop
// was 4 % of a mixed build's one-thread profile: docs/notes/kernels-builders.md).
inline HugePageVector<BBox> primitive_bounds(const PrimitiveSpans& prims) {
  HugePageVector<BBox> bounds;
  bounds.resize(prims.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bounds.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t id = r.begin(); id != r.end(); ++id) bounds[id] = prims.bounds(id);
  });
  return bounds;
}

}  // namespace raybench
