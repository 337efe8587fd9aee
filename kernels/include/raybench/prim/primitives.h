// A scene's primitives of every type, and the one numbering of them that
// every backend, the referee, the ray sets and the results share (issue 31):
// triangles first in their order, then spheres, then boxes, then oriented
// boxes, each in file order. A primitive's index in that order is its `prim`
// id in hits and results. Views only: the arrays belong to the caller (the
// harness's Scene).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "raybench/math/bbox.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/sphere.h"
#include "raybench/prim/triangle.h"

namespace raybench {

enum class PrimitiveKind : std::uint8_t { kTriangle, kSphere, kBox, kOrientedBox };

constexpr std::string_view to_string(PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::kTriangle: return "triangle";
    case PrimitiveKind::kSphere: return "sphere";
    case PrimitiveKind::kBox: return "box";
    case PrimitiveKind::kOrientedBox: return "obb";
  }
  return "?";
}

// The box of a sphere, widened by one float ulp outward on every side so
// that rounding center +- radius never cuts off a sliver of the sphere.
inline BBox sphere_bounds(const Sphere& s) {
  const float r = std::fabs(s.radius);
  BBox b;
  for (int a = 0; a < 3; ++a) {
    b.lower[a] = std::nextafter(s.center[a] - r, -INFINITY);
    b.upper[a] = std::nextafter(s.center[a] + r, INFINITY);
  }
  return b;
}

// The box of an oriented box: centre +- sum_i |axis_i| * half_extent_i per
// coordinate, widened outward by a relative 1e-6 (a few float ulps of the
// sum) so that the rounding of the sum never cuts off a corner.
inline BBox oriented_box_bounds(const OrientedBox& o) {
  BBox b;
  for (int a = 0; a < 3; ++a) {
    float reach = 0.0f;
    for (int i = 0; i < 3; ++i) reach += std::fabs(o.axis[i][a]) * std::fabs(o.half_extent[i]);
    reach = reach * (1.0f + 1e-6f) + 1e-30f;
    b.lower[a] = std::nextafter(o.center[a] - reach, -INFINITY);
    b.upper[a] = std::nextafter(o.center[a] + reach, INFINITY);
  }
  return b;
}

struct PrimitiveSpans {
  std::span<const Triangle> triangles;
  std::span<const Sphere> spheres;
  std::span<const BBox> boxes;
  std::span<const OrientedBox> obbs;

  std::size_t size() const { return triangles.size() + spheres.size() + boxes.size() + obbs.size(); }
  bool has_analytic() const { return !spheres.empty() || !boxes.empty() || !obbs.empty(); }

  // The first id of each type.
  std::size_t first_sphere() const { return triangles.size(); }
  std::size_t first_box() const { return first_sphere() + spheres.size(); }
  std::size_t first_obb() const { return first_box() + boxes.size(); }

  // The type of primitive `id` (< size()) and its index among its type.
  PrimitiveKind kind(std::size_t id) const {
    if (id < first_sphere()) return PrimitiveKind::kTriangle;
    if (id < first_box()) return PrimitiveKind::kSphere;
    if (id < first_obb()) return PrimitiveKind::kBox;
    return PrimitiveKind::kOrientedBox;
  }
  std::size_t local(std::size_t id) const {
    switch (kind(id)) {
      case PrimitiveKind::kTriangle: return id;
      case PrimitiveKind::kSphere: return id - first_sphere();
      case PrimitiveKind::kBox: return id - first_box();
      case PrimitiveKind::kOrientedBox: return id - first_obb();
    }
    return id;
  }
  // The axis-aligned box of primitive `id` (contains all of it).
  BBox bounds(std::size_t id) const {
    const std::size_t i = local(id);
    switch (kind(id)) {
      case PrimitiveKind::kTriangle: return triangle_bounds(triangles[i]);
      case PrimitiveKind::kSphere: return sphere_bounds(spheres[i]);
      case PrimitiveKind::kBox: return boxes[i];
      case PrimitiveKind::kOrientedBox: return oriented_box_bounds(obbs[i]);
    }
    return {};
  }
};

}  // namespace raybench
