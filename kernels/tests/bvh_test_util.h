// What the BVH tests share: a random triangle soup with degenerate members,
// and the brute-force closest hit every traversal is checked against.
#pragma once

#include <limits>
#include <random>
#include <vector>

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

// The closest hit by testing every triangle (Möller–Trumbore), last on ties.
inline Hit brute_force_closest(const std::vector<Triangle>& tris, const Ray& ray) {
  Hit best;
  float tmax = ray.tfar;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    TriangleHit h;
    if (MollerTrumbore::intersect(ray, tmax, tris[i], h)) {
      tmax = h.t;
      best = {h.t, static_cast<std::int32_t>(i), h.u, h.v};
    }
  }
  return best;
}

}  // namespace raybench::testing
