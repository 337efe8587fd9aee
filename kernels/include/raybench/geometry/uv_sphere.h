// A closed UV sphere: the test mesh for watertightness (rays fired from
// inside must all hit) and part of the procedural scenes. Poles are fans, so
// no triangle is degenerate, and each grid vertex is computed once so shared
// edges are bit-identical in neighbouring triangles.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "raybench/prim/triangle.h"

namespace raybench {

// rings >= 2 latitude bands, segments >= 3 longitude slices:
// segments * (2 * rings - 2) triangles.
inline void append_uv_sphere(std::vector<Triangle>& out, Vec3f center, float radius, int rings, int segments) {
  // Vertex (ring r, segment s) for r in [1, rings-1]; the poles are single
  // vertices. Computed once per grid point so shared edges are bit-identical.
  const auto point = [&](int r, int s) {
    const double theta = std::numbers::pi * r / rings;
    const double phi = 2.0 * std::numbers::pi * (s % segments) / segments;
    return Vec3f{center.x + static_cast<float>(radius * std::sin(theta) * std::cos(phi)),
                 center.y + static_cast<float>(radius * std::cos(theta)),
                 center.z + static_cast<float>(radius * std::sin(theta) * std::sin(phi))};
  };
  std::vector<Vec3f> grid(static_cast<std::size_t>((rings - 1) * segments));
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) grid[static_cast<std::size_t>((r - 1) * segments + s)] = point(r, s);
  const auto at = [&](int r, int s) { return grid[static_cast<std::size_t>((r - 1) * segments + s % segments)]; };
  const Vec3f north{center.x, center.y + radius, center.z}, south{center.x, center.y - radius, center.z};
  for (int s = 0; s < segments; ++s) {
    out.push_back({north, at(1, s + 1), at(1, s)});
    for (int r = 1; r < rings - 1; ++r) {
      out.push_back({at(r, s), at(r, s + 1), at(r + 1, s + 1)});
      out.push_back({at(r, s), at(r + 1, s + 1), at(r + 1, s)});
    }
    out.push_back({south, at(rings - 1, s), at(rings - 1, s + 1)});
  }
}

}  // namespace raybench
