// What the BVH tests share: a random triangle soup with degenerate members,
// a small mesh with shared edges, rays of the kinds a renderer shoots at it,
// the brute-force closest hit every traversal is checked against, and the
// check that boxes cover a triangle (a spatial-split BVH's leaves).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string_view>
#include <vector>

#include "raybench/math/bbox.h"

#include "raybench/geometry/uv_sphere.h"
#include "raybench/prim/triangle_mt.h"

namespace raybench::testing {

// n random small triangles in [-10, 10]^3, plus two degenerate ones (real
// meshes have them: conference.ply, 16 %) that must stay in the tree.
inline std::vector<Triangle> random_soup(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-10.0f, 10.0f), off(-1.0f, 1.0f);
  std::vector<Triangle> tris;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f c{pos(rng), pos(rng), pos(rng)};
    tris.push_back({c, c + Vec3f{off(rng), off(rng), off(rng)}, c + Vec3f{off(rng), off(rng), off(rng)}});
  }
  tris.push_back({{1, 1, 1}, {1, 1, 1}, {2, 2, 2}});
  tris.push_back({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}});
  return tris;
}

// A small real mesh: closed UV spheres with bit-identical shared edges, a
// unit sphere and eight smaller ones of different sizes around it (the shape
// of proc:terrain_spheres_small without its terrain); 4,000 triangles.
inline std::vector<Triangle> sphere_cluster() {
  std::vector<Triangle> tris;
  append_uv_sphere(tris, {0, 0, 0}, 1.0f, 24, 48);
  for (int i = 0; i < 8; ++i) {
    const Vec3f c{(i & 1) ? 2.0f : -2.0f, (i & 2) ? 1.5f : -1.5f, (i & 4) ? 2.5f : -2.5f};
    append_uv_sphere(tris, c, 0.3f + 0.1f * static_cast<float>(i), 8, 16);
  }
  return tris;
}

// Rays at a mesh centred near the origin, as a renderer makes them:
//   inside   from inside the unit sphere (radius 0.5 ball), any direction;
//   aimed    from a shell of radius 8 at an interior point of a random
//            triangle (camera rays that hit);
//   segment  the same, with tfar a random 0-1.2 of the distance (shadow rays,
//            some blocked, some reaching their light);
//   random   origins in [-6, 6]^3, any direction (mostly misses).
inline constexpr std::string_view kRayKinds[] = {"inside", "aimed", "segment", "random"};

inline std::vector<Ray> rays_at(const std::vector<Triangle>& tris, std::string_view kind, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), bary(0.05f, 0.45f), frac(0.0f, 1.2f);
  std::uniform_int_distribution<std::size_t> pick(0, tris.size() - 1);
  const auto direction = [&] {
    for (;;) {
      const Vec3f d{u(rng), u(rng), u(rng)};
      if (dot(d, d) > 1e-4f) return normalize(d);
    }
  };
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    Ray r;
    if (kind == "inside") {
      r.org = direction() * (0.5f * std::abs(u(rng)));
      r.dir = direction();
    } else if (kind == "random") {
      r.org = Vec3f{u(rng), u(rng), u(rng)} * 6.0f;
      r.dir = direction();
    } else {  // aimed, segment
      r.org = direction() * 8.0f;
      const Triangle& t = tris[pick(rng)];
      const float b1 = bary(rng), b2 = bary(rng);
      const Vec3f target = t.v0 * (1.0f - b1 - b2) + t.v1 * b1 + t.v2 * b2;
      const Vec3f to = target - r.org;
      r.dir = normalize(to);
      if (kind == "segment") r.tfar = frac(rng) * length(to);
    }
    rays.push_back(r);
  }
  return rays;
}

// The closest hit by testing every triangle (Möller–Trumbore unless told
// otherwise), last on ties.
template <typename Test = MollerTrumbore>
inline Hit brute_force_closest(const std::vector<Triangle>& tris, const Ray& ray) {
  Hit best;
  float tmax = ray.tfar;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    TriangleHit h;
    if (Test::intersect(ray, tmax, Test::prepare(tris[i]), h)) {
      tmax = h.t;
      best = {h.t, static_cast<std::int32_t>(i), h.u, h.v};
    }
  }
  return best;
}

// A point of triangle t that no box of `boxes` holds, if there is one among
// the points that decide it: t's vertices, the points where its edges cross
// the boxes' faces (where one box ends and the next must take over), and a
// grid of 153 interior points, all in double. A point is held when a box
// contains it within 2^-40 of t's largest coordinate: room for the double
// rounding of the points, far below a float ulp, so a box rounded inward by
// one ulp where it cuts t is caught. For finite triangles.
inline std::optional<std::array<double, 3>> uncovered_point(const Triangle& t, const std::vector<BBox>& boxes) {
  using P = std::array<double, 3>;
  const P v[3] = {{t.v0.x, t.v0.y, t.v0.z}, {t.v1.x, t.v1.y, t.v1.z}, {t.v2.x, t.v2.y, t.v2.z}};
  double largest = 0.0;
  for (const P& p : v)
    for (double c : p) largest = std::max(largest, std::fabs(c));
  const double tol = std::ldexp(largest, -40);
  const auto held = [&](const P& p) {
    return std::any_of(boxes.begin(), boxes.end(), [&](const BBox& b) {
      for (int a = 0; a < 3; ++a)
        if (!(b.lower[a] - tol <= p[a] && p[a] <= b.upper[a] + tol)) return false;
      return true;
    });
  };
  std::vector<P> points(v, v + 3);
  for (const BBox& b : boxes)
    for (int axis = 0; axis < 3; ++axis)
      for (const double plane : {static_cast<double>(b.lower[axis]), static_cast<double>(b.upper[axis])})
        for (int e = 0; e < 3; ++e) {
          const P& a = v[e];
          const P& c = v[(e + 1) % 3];
          if (!((a[axis] < plane && plane < c[axis]) || (c[axis] < plane && plane < a[axis]))) continue;
          const double s = (plane - a[axis]) / (c[axis] - a[axis]);
          P p;
          for (int j = 0; j < 3; ++j) p[j] = a[j] + s * (c[j] - a[j]);
          p[axis] = plane;
          points.push_back(p);
        }
  constexpr int kGrid = 16;
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; i + j <= kGrid; ++j) {
      const double b1 = static_cast<double>(i) / kGrid, b2 = static_cast<double>(j) / kGrid;
      P p;
      for (int a = 0; a < 3; ++a) p[a] = v[0][a] * (1.0 - b1 - b2) + v[1][a] * b1 + v[2][a] * b2;
      points.push_back(p);
    }
  for (const P& p : points)
    if (!held(p)) return p;
  return std::nullopt;
}

}  // namespace raybench::testing
