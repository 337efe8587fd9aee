// The procedural scenes "proc:<name>" (scene/procedural.h): closed-form
// shapes and counter-based random numbers (scene/random.h), so a scene is
// the same primitives on every run and thread count (across machines, as far
// as their libm's sin and cos agree). The extreme-case scenes follow the
// catalogue ../shared/EXTREMES.md (its case numbers G.. are given where they
// are made).
#include "scene/procedural.h"

#include <algorithm>
#include <array>
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

// The balls of terrain_spheres: varied sizes, resting on (and sunk a little
// into) the terrain, placed by a seeded hash. The same balls, analytic or
// tessellated, in both forms of the scene.
std::vector<Sphere> terrain_balls(int count, double half_size) {
  std::vector<Sphere> balls;
  for (int s = 0; s < count; ++s) {
    Rng rng(0x5eed, hash_string("terrain_spheres"), static_cast<std::uint64_t>(s));
    const double x = (rng.next_double() * 2.0 - 1.0) * half_size * 0.9;
    const double z = (rng.next_double() * 2.0 - 1.0) * half_size * 0.9;
    const double r = 1.0 + 7.0 * rng.next_double() * rng.next_double();
    const Vec3f center{static_cast<float>(x), static_cast<float>(terrain_height(x, z) + 0.8 * r), static_cast<float>(z)};
    balls.push_back({center, static_cast<float>(r)});
  }
  return balls;
}

// The terrain with its balls as UV spheres (rings x segments triangles each),
// or as analytic spheres after the terrain's triangles (issue 31).
Scene terrain_spheres(int cells, int spheres, int rings, int segments, bool analytic = false) {
  Scene scene;
  append_terrain(scene.triangles, cells, 100.0);
  for (const Sphere& ball : terrain_balls(spheres, 100.0)) {
    if (analytic) scene.spheres.push_back(ball);
    else append_uv_sphere(scene.triangles, ball.center, ball.radius, rings, segments);
  }
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

// A unit vector in a direction uniform on the sphere, from two uniforms.
std::array<double, 3> random_direction(Rng& rng) {
  const double y = 2.0 * rng.next_double() - 1.0;
  const double phi = 2.0 * std::numbers::pi * rng.next_double();
  const double ring = std::sqrt(std::max(0.0, 1.0 - y * y));
  return {ring * std::cos(phi), y, ring * std::sin(phi)};
}

// lo * (hi / lo)^u: uniform in log scale.
double log_uniform(Rng& rng, double lo, double hi) { return lo * std::pow(hi / lo, rng.next_double()); }

Vec3f to_float(double x, double y, double z) {
  return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

// Spheres only, of radii from 1e-3 to 1e5 and at distances from 2 to 1e4 of
// the origin, every kind of sphere a renderer meets and a few it dreads
// (issue 31): a ground sphere of radius 1e5 whose top is the plane y = 0
// (huge and near: its quadratic cancels catastrophically in float), three
// spheres of radius 1e3 whose surfaces pass 70 from the origin (at -x, +x, -z),
// 3000 scattered spheres (log-uniform radius 1e-3..10, distance 2..2e3),
// 500 specks (radius 1e-3..1e-2) at 1e3..1e4 (small and far), 64 clusters
// of 8 overlapping spheres, and 32 nests of 5 spheres each strictly inside
// the one before (the first nest concentric). The camera of the manifests
// stands at (0, 12, 90) looking at (0, 2, 0), outside every sphere. 4,176
// spheres, in that order.
Scene sphere_field() {
  Scene scene;
  std::uint64_t index = 0;
  const auto rng = [&] { return Rng(0x5eed, hash_string("sphere_field"), index++); };
  scene.spheres.push_back({{0.0f, -1e5f, 0.0f}, 1e5f});
  for (const Vec3f c : {Vec3f{-1070.0f, 0.0f, 0.0f}, Vec3f{1070.0f, 0.0f, 0.0f}, Vec3f{0.0f, 0.0f, -1070.0f}})
    scene.spheres.push_back({c, 1e3f});
  const auto scatter = [&](int count, double r_lo, double r_hi, double d_lo, double d_hi) {
    for (int i = 0; i < count; ++i) {
      Rng g = rng();
      const double r = log_uniform(g, r_lo, r_hi);
      const double d = log_uniform(g, d_lo, d_hi);
      auto dir = random_direction(g);
      dir[1] = std::fabs(dir[1]);  // above the ground's top
      scene.spheres.push_back({to_float(d * dir[0], d * dir[1] + r, d * dir[2]), static_cast<float>(r)});
    }
  };
  scatter(3000, 1e-3, 10.0, 2.0, 2e3);
  scatter(500, 1e-3, 1e-2, 1e3, 1e4);
  for (int c = 0; c < 64; ++c) {
    Rng g = rng();
    const double cx = 100.0 * g.next_double() - 50.0, cy = 2.0 + 8.0 * g.next_double(), cz = 100.0 * g.next_double() - 50.0;
    for (int k = 0; k < 8; ++k) {
      const double r = 0.5 + 1.5 * g.next_double();  // members within 1 of the centre: each overlaps the others
      const auto dir = random_direction(g);
      const double d = g.next_double();
      scene.spheres.push_back({to_float(cx + d * dir[0], cy + d * dir[1], cz + d * dir[2]), static_cast<float>(r)});
    }
  }
  for (int n = 0; n < 32; ++n) {
    Rng g = rng();
    double r = 1.0 + 4.0 * g.next_double();
    double cx = 120.0 * g.next_double() - 60.0, cy = r + 0.5, cz = 120.0 * g.next_double() - 60.0;
    scene.spheres.push_back({to_float(cx, cy, cz), static_cast<float>(r)});
    for (int level = 1; level < 5; ++level) {
      // The inner sphere's centre within 0.4 (r - r_inner) of the outer's:
      // 0.6 (r - r_inner) of clearance, far above float rounding.
      const double inner = 0.5 * r;
      const double shift = n == 0 ? 0.0 : 0.4 * (r - inner) * g.next_double();
      const auto dir = random_direction(g);
      cx += shift * dir[0];
      cy += shift * dir[1];
      cz += shift * dir[2];
      r = inner;
      scene.spheres.push_back({to_float(cx, cy, cz), static_cast<float>(r)});
    }
  }
  return scene;
}

// The rotation of the unit quaternion (w, x, y, z): its columns as OBB axes.
void rotation_axes(double w, double x, double y, double z, Vec3f axis[3]) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n, x /= n, y /= n, z /= n;
  axis[0] = to_float(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y));
  axis[1] = to_float(2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x));
  axis[2] = to_float(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
}

// Every primitive type in one small scene, for tests and the accuracy suite
// (issue 31): a ground of 32 triangles (4 x 4 cells over [-8, 8]^2 at y = 0)
// and a tetrahedron of 4, then 8 spheres, 6 boxes and 6 oriented boxes on
// the ground, randomly rotated, some sunk into the ground, a sphere nested in
// another, a sphere cutting a box, two boxes sharing a face, an oriented box
// through a sphere. 56 primitives, in that order.
Scene analytic_mix() {
  Scene scene;
  const float h = 8.0f;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const auto p = [&](int a, int b) { return Vec3f{-h + 4.0f * static_cast<float>(i + a), 0.0f, -h + 4.0f * static_cast<float>(j + b)}; };
      scene.triangles.push_back({p(0, 0), p(1, 1), p(1, 0)});
      scene.triangles.push_back({p(0, 0), p(0, 1), p(1, 1)});
    }
  const Vec3f t0{-5.0f, 0.0f, 4.0f}, t1{-3.0f, 0.0f, 4.0f}, t2{-4.0f, 0.0f, 6.0f}, t3{-4.0f, 2.0f, 4.7f};
  scene.triangles.insert(scene.triangles.end(), {{t0, t2, t1}, {t0, t1, t3}, {t1, t2, t3}, {t2, t0, t3}});
  std::uint64_t index = 0;
  const auto rng = [&] { return Rng(0x5eed, hash_string("analytic_mix"), index++); };
  for (int k = 0; k < 5; ++k) {
    Rng g = rng();
    const double r = 0.3 + 1.2 * g.next_double();
    scene.spheres.push_back({to_float(12.0 * g.next_double() - 6.0, 0.8 * r, 12.0 * g.next_double() - 6.0), static_cast<float>(r)});
  }
  scene.spheres.push_back({{2.0f, 2.5f, -2.0f}, 1.5f});  // a nest: the next one inside it
  scene.spheres.push_back({{2.3f, 2.4f, -2.1f}, 0.6f});
  scene.spheres.push_back({{-1.0f, 1.0f, 5.0f}, 0.8f});  // cut by the next box
  scene.boxes.push_back({{-1.5f, 0.0f, 4.0f}, {-0.5f, 1.2f, 6.5f}});
  scene.boxes.push_back({{3.0f, 0.0f, 3.0f}, {4.0f, 1.0f, 4.0f}});  // two boxes sharing the face x = 4
  scene.boxes.push_back({{4.0f, 0.0f, 3.0f}, {5.5f, 0.5f, 4.0f}});
  for (int k = 0; k < 3; ++k) {
    Rng g = rng();
    const Vec3f lo = to_float(12.0 * g.next_double() - 6.0, -0.2 * g.next_double(), 12.0 * g.next_double() - 6.0);
    const Vec3f size = to_float(0.2 + 1.3 * g.next_double(), 0.2 + 1.3 * g.next_double(), 0.2 + 1.3 * g.next_double());
    scene.boxes.push_back({lo, lo + size});
  }
  for (int k = 0; k < 6; ++k) {
    Rng g = rng();
    OrientedBox o;
    // An oriented box through the first nest's outer sphere, the others scattered.
    o.center = k == 0 ? Vec3f{2.0f, 1.5f, -3.2f} : to_float(12.0 * g.next_double() - 6.0, 1.0, 12.0 * g.next_double() - 6.0);
    rotation_axes(g.next_double() - 0.5, g.next_double() - 0.5, g.next_double() - 0.5, g.next_double() - 0.5, o.axis);
    o.half_extent = to_float(0.2 + g.next_double(), 0.2 + g.next_double(), 0.2 + g.next_double());
    scene.obbs.push_back(o);
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
      {{"terrain_spheres_analytic", "terrain_spheres with its 120 balls as analytic spheres: 524,288 triangles, 120 spheres"},
       [] { return terrain_spheres(512, 120, 32, 64, true); }},
      {{"terrain_spheres_analytic_small", "terrain_spheres_small with its 6 balls analytic: 2,048 triangles, 6 spheres"},
       [] { return terrain_spheres(32, 6, 16, 32, true); }},
      {{"sphere_field", "4,176 spheres of radius 1e-3 to 1e5 at 2 to 1e4 from the origin: overlapping, nested, "
                        "small and far, huge and near; no triangles"},
       [] { return sphere_field(); }},
      {{"analytic_mix", "36 triangles, 8 spheres, 6 boxes, 6 rotated oriented boxes: every primitive type, touching "
                        "and nested"},
       [] { return analytic_mix(); }},
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
