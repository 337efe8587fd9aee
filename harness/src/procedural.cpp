#include "procedural.h"

#include <cmath>
#include <functional>
#include <numbers>

#include "error.h"
#include "random.h"
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
