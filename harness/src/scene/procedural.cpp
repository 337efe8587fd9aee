#include "scene/procedural.h"

#include <cmath>
#include <functional>
#include <numbers>

#include "io/error.h"
#include "scene/random.h"
#include "raybench/geometry/uv_sphere.h"

namespace raybench {
namespace {

// Height of the rolling terrain at (x, z): a few octaves of sines, smooth
// enough to look like ground and rough enough to give the BVH real work.
double terrain_height(double x, double z) {
  return 6.0 * std::sin(0.05 * x) * std::cos(0.04 * z) + 2.5 * std::sin(0.13 * x + 0.7) * std::sin(0.11 * z) +
         0.8 * std::cos(0.37 * x - 0.21 * z);
}

void append_terrain(std::vector<Triangle>& out, int cells, double half_size) {
  const double step = 2.0 * half_size / cells;
  const auto vertex = [&](int i, int j) {
    const double x = -half_size + i * step, z = -half_size + j * step;
    return Vec3f{static_cast<float>(x), static_cast<float>(terrain_height(x, z)), static_cast<float>(z)};
  };
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      const Vec3f a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
      out.push_back({a, c, b});
      out.push_back({a, d, c});
    }
  }
}

// Spheres of varied size resting on the terrain, placed by a seeded hash.
void append_spheres(std::vector<Triangle>& out, int count, double half_size, int rings, int segments) {
  for (int s = 0; s < count; ++s) {
    Rng rng(0x5eed, hash_string("terrain_spheres"), static_cast<std::uint64_t>(s));
    const double x = (rng.next_double() * 2.0 - 1.0) * half_size * 0.9;
    const double z = (rng.next_double() * 2.0 - 1.0) * half_size * 0.9;
    const double r = 1.0 + 7.0 * rng.next_double() * rng.next_double();
    const Vec3f center{static_cast<float>(x), static_cast<float>(terrain_height(x, z) + 0.8 * r), static_cast<float>(z)};
    append_uv_sphere(out, center, static_cast<float>(r), rings, segments);
  }
}

Scene terrain_spheres(int cells, int spheres, int rings, int segments) {
  Scene scene;
  append_terrain(scene.triangles, cells, 100.0);
  append_spheres(scene.triangles, spheres, 100.0, rings, segments);
  return scene;
}

Scene unit_sphere() {
  Scene scene;
  append_uv_sphere(scene.triangles, {0, 0, 0}, 1.0f, 24, 48);
  return scene;
}

// G05 of ../shared/EXTREMES.md: right triangles with legs 1e-3, 1e-5 and
// 1e-7, randomly oriented, 16 of each size near the origin and 16 near
// (1e3, 1e3, 1e3), where float spacing (6e-5) quantises the smallest ones
// into slivers or points. 0.01 apart, so none overlaps another.
Scene tiny_triangles() {
  Scene scene;
  const double legs[] = {1e-3, 1e-5, 1e-7};
  for (int size = 0; size < 3; ++size) {
    for (int far = 0; far < 2; ++far) {
      for (int k = 0; k < 16; ++k) {
        Rng rng(0x5eed, hash_string("tiny_triangles"), static_cast<std::uint64_t>((size * 2 + far) * 16 + k));
        const double base = far ? 1e3 : 0.0;
        const double c[3] = {base + 0.01 * k, base + 0.01 * size, base};
        // An orthonormal pair from a random rotation (Gram-Schmidt on two random vectors).
        double a[3], b[3];
        for (double* v : {a, b})
          for (int i = 0; i < 3; ++i) v[i] = rng.next_double() - 0.5;
        const auto norm = [](double* v) {
          const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
          for (int i = 0; i < 3; ++i) v[i] /= l;
        };
        norm(a);
        const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for (int i = 0; i < 3; ++i) b[i] -= ab * a[i];
        norm(b);
        const auto point = [&](double s, double t) {
          return Vec3f{static_cast<float>(c[0] + legs[size] * (s * a[0] + t * b[0])),
                       static_cast<float>(c[1] + legs[size] * (s * a[1] + t * b[1])),
                       static_cast<float>(c[2] + legs[size] * (s * a[2] + t * b[2]))};
        };
        scene.triangles.push_back({point(0, 0), point(1, 0), point(0, 1)});
      }
    }
  }
  return scene;
}

// G08 of ../shared/EXTREMES.md: (a) exactly collinear integer triangles
// (EXTREMES' (0,0,0), (3000,5000,7000), (5331,8885,12439), scaled and moved by
// exact integers), (b) repeated vertices, (c) needles of aspect 1e7. The
// truth for (a) and (b) is "never hit"; (c) are real, very thin triangles.
Scene degenerate_triangles() {
  Scene scene;
  for (int k = 0; k < 8; ++k) {
    const float m = static_cast<float>(1 + k % 4), dx = 20000.0f * k;
    scene.triangles.push_back({{dx, 0, 0}, {dx + 3000 * m, 5000 * m, 7000 * m}, {dx + 5331 * m, 8885 * m, 12439 * m}});
    scene.triangles.push_back({{dx, -20000, 0}, {dx + 3000, -15000, 7000}, {dx + 3000, -15000, 7000}});  // two equal
    scene.triangles.push_back({{dx, -40000, 0}, {dx, -40000, 0}, {dx, -40000, 0}});                      // a point
    // A needle 10000 long and 1e-3 wide, where float resolves 1e-3 (y near 0.5).
    scene.triangles.push_back({{dx, 0.5f, -5000}, {dx + 10000, 0.5f, -5000}, {dx + 5000, 0.501f, -5000}});
  }
  return scene;
}

// G09 and G17 of ../shared/EXTREMES.md: a 4 x 4 x 4 grid of axis-aligned unit
// cubes (12 triangles each), neighbours sharing faces, so that triangles lie
// in the BVH's slab planes and their bounding boxes have zero thickness.
Scene axis_boxes() {
  Scene scene;
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        if ((x + y + z) % 3 == 2) continue;  // gaps, so rays get between boxes
        const auto p = [&](int i, int j, int k) {
          return Vec3f{static_cast<float>(x + i), static_cast<float>(y + j), static_cast<float>(z + k)};
        };
        const Vec3f c[8] = {p(0, 0, 0), p(1, 0, 0), p(1, 1, 0), p(0, 1, 0), p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)};
        const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
        for (const auto& f : faces) {
          scene.triangles.push_back({c[f[0]], c[f[1]], c[f[2]]});
          scene.triangles.push_back({c[f[0]], c[f[2]], c[f[3]]});
        }
      }
  return scene;
}

struct Entry {
  ProceduralSceneInfo info;
  std::function<Scene()> make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {{"terrain_spheres", "rolling terrain (512x512 cells) with 120 UV spheres, 1,000,448 triangles"},
       [] { return terrain_spheres(512, 120, 32, 64); }},
      {{"terrain_spheres_small", "the same at test size: 32x32 cells, 6 spheres, 7,808 triangles"},
       [] { return terrain_spheres(32, 6, 16, 32); }},
      {{"sphere", "closed unit UV sphere at the origin, 2,208 triangles"}, [] { return unit_sphere(); }},
      {{"tiny_triangles", "G05: 96 right triangles with legs 1e-3, 1e-5, 1e-7, at the origin and at 1e3"},
       [] { return tiny_triangles(); }},
      {{"degenerate_triangles", "G08: collinear, repeated-vertex and point triangles, and needles of aspect 1e7"},
       [] { return degenerate_triangles(); }},
      {{"axis_boxes", "G09/G17: axis-aligned unit cubes sharing faces, 516 triangles"}, [] { return axis_boxes(); }},
  };
  return entries;
}

}  // namespace

std::vector<ProceduralSceneInfo> procedural_scenes() {
  std::vector<ProceduralSceneInfo> out;
  for (const Entry& e : registry()) out.push_back(e.info);
  return out;
}

Scene make_procedural_scene(const std::string& spec) {
  const std::string name = spec.substr(kProceduralPrefix.size());
  for (const Entry& e : registry()) {
    if (e.info.name == name) {
      Scene scene = e.make();
      scene.name = name;
      scene.source = spec;
      return scene;
    }
  }
  std::string known;
  for (const Entry& e : registry()) known += (known.empty() ? "" : ", ") + std::string(kProceduralPrefix) + e.info.name;
  throw InputError(spec, "unknown procedural scene (known: " + known + ")");
}

}  // namespace raybench
