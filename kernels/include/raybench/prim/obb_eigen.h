// Ray-OBB test: the ray moved into the box's frame with Eigen, then a slab
// test against the axis-aligned box [-h, h] written for every edge case.
//
// Source: the slab method of the ray-OBB seed note (../shared/seeds/004_*.txt,
// a Chinese blog post, "OBB与Ray求交", 2022; Kay &
// Kajiya, "Ray Tracing Complex Scenes", SIGGRAPH 1986), with its faults fixed
// (see obb_seed.h and ../shared/EXTREMES.md):
// - The running interval starts at [-inf, +inf], not at DBL_MIN, and the ray's
//   own [tnear, tmax] is applied at the end, closed at both ends: the box is a
//   closed solid, as in the slab tests of BVHs (pbrt-v4 Bounds3::IntersectP),
//   so an origin on a face hits whichever way the ray points (G11).
// - No epsilon: a direction component that is exactly 0 (of either sign)
//   means "parallel to this slab", decided by the origin lying in the closed
//   slab; any other component, however small, is divided by. This avoids
//   1/d's 0 * inf = NaN on a face and makes the answer independent of the
//   sign of zero (G09) and of |d| (G16).
// - Non-finite input, and a zero direction, are a miss, tested first: NaN would otherwise slip through
//   comparisons, and an infinite component turns into NaN under the rotation.
//   This is also what is_traceable (math/ray.h) screens.
//
// Semantics: true when a point of the closed box lies at t in [tnear, tmax];
// out gets that part of the ray, [max(entry, tnear), min(exit, tmax)], as
// BoxHit promises for every box test (aabb.h). An origin inside has a slab
// entry < 0, so it enters at tnear and the exit is where it leaves the box.
// On a miss out is untouched. The axes must be orthonormal (the rotation is
// their transpose, never inverted).
// Precision: the frame change and the slabs run in double (not a hot loop,
// and a float rotation would round the origin onto or off a face), so only
// the final distances are rounded to float.
#pragma once

#include <cmath>
#include <limits>
#include <string_view>
#include <utility>

// Eigen 3.4's AVX PacketMath.h has an unused variable (F32ToBf16) that
// -Wall reports when Eigen is included with -I rather than as a system
// header (CMake's Eigen3::Eigen target uses -isystem): silence it for Eigen
// only, not for this file.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-variable"
#include <Eigen/Dense>
#pragma GCC diagnostic pop

#include "raybench/math/ray.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct Obb {
  static constexpr std::string_view name = "obb";
  static constexpr std::string_view description =
      "ray-OBB: ray into the box frame (Eigen, double), epsilon-free closed slab test (the ray-OBB seed note's test, fixed)";
  static constexpr AccuracyClass accuracy = AccuracyClass::kFast;

  static bool intersect(const Ray& ray, float tmax, const OrientedBox& box, BoxHit& out) {
    if (!(is_finite(ray.org) && is_finite(ray.dir))) return false;
    if (ray.dir.x == 0.0f && ray.dir.y == 0.0f && ray.dir.z == 0.0f) return false;  // no direction, no ray
    const auto v = [](Vec3f p) { return Eigen::Vector3d(p.x, p.y, p.z); };
    Eigen::Matrix3d to_box;  // rows: the box axes, so to_box * w gives w's box coordinates
    to_box << v(box.axis[0]).transpose(), v(box.axis[1]).transpose(), v(box.axis[2]).transpose();
    const Eigen::Vector3d org = to_box * (v(ray.org) - v(box.center));
    const Eigen::Vector3d dir = to_box * v(ray.dir);
    const Eigen::Vector3d half = v(box.half_extent);
    // A NaN or infinite box (or an overflowing product) would leak NaN into the slabs.
    if (!(org.allFinite() && dir.allFinite() && half.allFinite())) return false;

    constexpr double kInf = std::numeric_limits<double>::infinity();
    double entry = -kInf, exit = kInf;
    for (int i = 0; i < 3; ++i) {
      if (!(half[i] >= 0.0)) return false;  // negative extent: an empty box
      if (dir[i] == 0.0) {                  // true for +0 and -0 alike
        if (!(org[i] >= -half[i] && org[i] <= half[i])) return false;
        continue;  // parallel, inside the closed slab: it does not narrow the interval
      }
      // Division, not a reciprocal: finite over finite nonzero, never NaN. In
      // double even a denormal float component gives a finite t; only the
      // float in out can round to +-inf, which still orders correctly.
      double t_lo = (-half[i] - org[i]) / dir[i];
      double t_hi = (half[i] - org[i]) / dir[i];
      if (t_lo > t_hi) std::swap(t_lo, t_hi);
      if (t_lo > entry) entry = t_lo;
      if (t_hi < exit) exit = t_hi;
    }
    // Closed at both ends; written so that a NaN tnear or tmax rejects.
    const double lo = entry > ray.tnear ? entry : static_cast<double>(ray.tnear);
    const double hi = exit < tmax ? exit : static_cast<double>(tmax);
    if (!(lo <= hi)) return false;
    out = {static_cast<float>(lo), static_cast<float>(hi)};
    return true;
  }
};

}  // namespace raybench
