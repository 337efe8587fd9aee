#include "accuracy/prim_raysets.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>

#include <fmt/format.h>

#include "scene/random.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// --- Geometry in double, rounded to float once at the end --------------------

struct V3 {
  double x = 0, y = 0, z = 0;
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double length(V3 a) { return std::sqrt(dot(a, a)); }
V3 normalized(V3 a) { return a * (1.0 / length(a)); }
V3 to_d(Vec3f v) { return {v.x, v.y, v.z}; }
Vec3f to_f(V3 v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }

double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * rng.next_double(); }
// n is tiny (<= 33): the modulo bias is below 2^-58.
int uniform_int(Rng& rng, int n) { return static_cast<int>(rng.next_u64() % static_cast<std::uint64_t>(n)); }
bool coin(Rng& rng) { return (rng.next_u64() >> 63) != 0; }
V3 uniform_in_cube(Rng& rng, double half) {
  return {uniform(rng, -half, half), uniform(rng, -half, half), uniform(rng, -half, half)};
}
V3 unit_vector(Rng& rng) {
  const double z = uniform(rng, -1, 1), phi = uniform(rng, 0, 2 * std::numbers::pi);
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}
// A random unit vector perpendicular to the unit vector n.
V3 perpendicular_unit(Rng& rng, V3 n) {
  for (;;) {
    const V3 v = unit_vector(rng);
    const V3 p = v - n * dot(v, n);
    if (length(p) > 0.1) return normalized(p);
  }
}

Ray make_ray(Vec3f org, Vec3f dir) {
  Ray r;
  r.org = org;
  r.dir = dir;
  return r;  // tnear = 0, tfar = +inf
}
// The float ray from the float origin towards target: the direction is
// computed from the origin as rounded, normalised in double, rounded once.
Ray aimed(Vec3f org, V3 target) { return make_ray(org, to_f(normalized(target - to_d(org)))); }

std::string power_of_ten(int e) { return e == 0 ? "1" : fmt::format("1e{}", e); }

// One set: ray i from Rng(seed, hash("<scene>/<stream>"), i). `stream`
// defaults to the set's name; sets that must share their rays (G16's
// lengths) share a stream.
template <typename Prim, typename F>
PrimRaySet<Prim> make_set(const std::string& scene, const std::string& rayset, std::size_t n, std::uint64_t seed, F&& one,
                          const std::string& stream = "") {
  PrimRaySet<Prim> set{scene, rayset, {}, {}};
  const std::uint64_t id = hash_string((scene + "/" + (stream.empty() ? rayset : stream)).c_str());
  set.rays.reserve(n);
  set.prims.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Rng rng(seed, id, i);
    std::pair<Ray, Prim> rp = one(rng, i);
    set.rays.push_back(rp.first);
    set.prims.push_back(rp.second);
  }
  return set;
}

// --- Random primitives -------------------------------------------------------

// A primitive with what the generic sets aim at: a point well inside it, a
// point near it (inside about half the time), its centre and size.
template <typename Prim>
struct Sample {
  Prim prim;
  V3 centre;
  double size = 1;  // distance from the centre to the farthest point of the primitive
  std::function<V3(Rng&)> inside, near;
};

// Axis-aligned box, centre in [-1,1]^3, half sizes in [0.1, 1].
Sample<BBox> random_box(Rng& rng) {
  const V3 c = uniform_in_cube(rng, 1);
  const V3 h{uniform(rng, 0.1, 1), uniform(rng, 0.1, 1), uniform(rng, 0.1, 1)};
  BBox b;
  b.lower = to_f(c - h);
  b.upper = to_f(c + h);
  const V3 mid = (to_d(b.lower) + to_d(b.upper)) * 0.5, half = (to_d(b.upper) - to_d(b.lower)) * 0.5;
  const auto at = [mid, half](Rng& r, double spread) {
    return V3{mid.x + half.x * spread * uniform(r, -1, 1), mid.y + half.y * spread * uniform(r, -1, 1),
              mid.z + half.z * spread * uniform(r, -1, 1)};
  };
  return {b, mid, length(half), [at](Rng& r) { return at(r, 0.9); }, [at](Rng& r) { return at(r, 1.5); }};
}

// Oriented box with a uniformly random rotation (a normalised random
// quaternion) whose axes are rounded to float: nearly, not exactly, unit and
// orthogonal, as any float OBB is. The referee takes them as given.
Sample<OrientedBox> random_obb(Rng& rng) {
  double w = uniform(rng, -1, 1), x = uniform(rng, -1, 1), y = uniform(rng, -1, 1), z = uniform(rng, -1, 1);
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n, x /= n, y /= n, z /= n;
  const V3 columns[3] = {{1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)},
                         {2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)},
                         {2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)}};
  OrientedBox b;
  b.center = to_f(uniform_in_cube(rng, 1));
  V3 axes[3], half;
  for (int i = 0; i < 3; ++i) {
    b.axis[i] = to_f(columns[i]);
    axes[i] = to_d(b.axis[i]);
    b.half_extent[i] = static_cast<float>(uniform(rng, 0.1, 1));
    half[i] = b.half_extent[i];
  }
  const V3 c = to_d(b.center);
  const auto at = [c, axes, half](Rng& r, double spread) {
    V3 p = c;
    for (int i = 0; i < 3; ++i) p = p + axes[i] * (half[i] * spread * uniform(r, -1, 1));
    return p;
  };
  return {b, c, length(half), [at](Rng& r) { return at(r, 0.9); }, [at](Rng& r) { return at(r, 1.5); }};
}

// Sphere, centre in [-1,1]^3, radius in [0.1, 1].
Sample<Sphere> random_sphere(Rng& rng) {
  const Sphere s{to_f(uniform_in_cube(rng, 1)), static_cast<float>(uniform(rng, 0.1, 1))};
  const V3 c = to_d(s.center);
  const double r = s.radius;
  return {s, c, r, [c, r](Rng& g) { return c + unit_vector(g) * (0.9 * r * std::cbrt(g.next_double())); },
          [c, r](Rng& g) { return c + uniform_in_cube(g, 1.5 * r); }};
}

// A point of the float triangle with barycentric coordinates at least
// `margin` (uniform over that inner triangle), in double.
V3 interior_point(Rng& rng, const Triangle& t, double margin) {
  double b1 = rng.next_double(), b2 = rng.next_double();
  if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
  b1 = margin + (1 - 3 * margin) * b1;
  b2 = margin + (1 - 3 * margin) * b2;
  const V3 v0 = to_d(t.v0);
  return v0 + (to_d(t.v1) - v0) * b1 + (to_d(t.v2) - v0) * b2;
}
V3 normal_of(const Triangle& t) { return normalized(cross(to_d(t.v1) - to_d(t.v0), to_d(t.v2) - to_d(t.v0))); }

// A well-shaped triangle (edges >= 0.3, angle at v0 between 12 and 168
// degrees) with vertices in [-1,1]^3.
Triangle random_triangle(Rng& rng) {
  for (;;) {
    const Triangle t{to_f(uniform_in_cube(rng, 1)), to_f(uniform_in_cube(rng, 1)), to_f(uniform_in_cube(rng, 1))};
    const V3 e1 = to_d(t.v1) - to_d(t.v0), e2 = to_d(t.v2) - to_d(t.v0), e3 = to_d(t.v2) - to_d(t.v1);
    if (std::min({length(e1), length(e2), length(e3)}) < 0.3) continue;
    if (length(cross(e1, e2)) < 0.2 * length(e1) * length(e2)) continue;
    return t;
  }
}

Sample<Triangle> random_triangle_sample(Rng& rng) {
  const Triangle t = random_triangle(rng);
  const V3 c = (to_d(t.v0) + to_d(t.v1) + to_d(t.v2)) * (1.0 / 3);
  const double size = std::max({length(to_d(t.v0) - c), length(to_d(t.v1) - c), length(to_d(t.v2) - c)});
  return {t, c, size, [t](Rng& r) { return interior_point(r, t, 0.1); },
          [t](Rng& r) {  // barycentrics in [-0.2, 1.2]: about a third inside
            const V3 v0 = to_d(t.v0);
            return v0 + (to_d(t.v1) - v0) * uniform(r, -0.2, 1.2) + (to_d(t.v2) - v0) * uniform(r, -0.2, 1.2);
          }};
}

// --- Sets every family shares --------------------------------------------------

// G20 control-random: origins uniform in the scene bounds [-3,3]^3 (some
// inside the primitive), aimed at a point near the primitive.
template <typename Prim>
std::pair<Ray, Prim> control_ray(Rng& rng, Sample<Prim> (*sample)(Rng&)) {
  const Sample<Prim> s = sample(rng);
  const Vec3f o = to_f(uniform_in_cube(rng, 3));
  V3 target = s.near(rng);
  if (length(target - to_d(o)) == 0) target = target + V3{1, 0, 0};
  return {aimed(o, target), s.prim};
}

// A ray from outside (3 sizes from the centre) aimed well inside: every
// valid kernel hits it, so what G15 does to it shows as a false hit.
template <typename Prim>
std::pair<Ray, Prim> hitting_ray(Rng& rng, Sample<Prim> (*sample)(Rng&)) {
  const Sample<Prim> s = sample(rng);
  const Vec3f o = to_f(s.centre + unit_vector(rng) * (3 * s.size));
  return {aimed(o, s.inside(rng)), s.prim};
}

// G15 invalid-rays: a hitting ray with one corruption, cycling through
//  0-17  NaN, +Inf, -Inf in each of org.xyz and dir.xyz
//  18    all-NaN direction (the AABB seed hits with it, EXTREMES.md)
//  19    all-NaN origin
//  20    tnear NaN            21  tfar NaN
//  22    tnear > tfar (tnear = 10, tfar = 5: the hit lies before tnear)
//  23    d = (+0, +0, +0)     24  d = (-0, +0, -0)
//  25    tnear = +inf         26  tfar = -1
// The truth for each is a miss: a non-ray (0-21, 23, 24) hits nothing, and
// 22, 25, 26 have empty intervals. Denormal and FLT_MAX-long directions are
// valid rays and have their own set (extreme_d_ray).
constexpr int kInvalidCases = 27;
Ray corrupt(Ray r, int c) {
  if (c < 18) {
    const float value = c < 6 ? kNaN : (c < 12 ? kInf : -kInf);
    const int component = c % 6;
    if (component < 3) r.org[component] = value;
    else r.dir[component - 3] = value;
    return r;
  }
  switch (c) {
    case 18: r.dir = {kNaN, kNaN, kNaN}; break;
    case 19: r.org = {kNaN, kNaN, kNaN}; break;
    case 20: r.tnear = kNaN; break;
    case 21: r.tfar = kNaN; break;
    case 22: r.tnear = 10.0f, r.tfar = 5.0f; break;
    case 23: r.dir = {0.0f, 0.0f, 0.0f}; break;
    case 24: r.dir = {-0.0f, 0.0f, -0.0f}; break;
    case 25: r.tnear = kInf; break;
    case 26: r.tfar = -1.0f; break;
  }
  return r;
}

// invalid-rays:extreme-d (from G15's list: denormal d, |d| = FLT_MAX), valid
// rays judged exactly: i % 4 = 0, 1: |d| = 1e-40 (denormal components),
// 2, 3: |d| = FLT_MAX; even i aimed inside the primitive, odd i aimed 2.5
// sizes to the side of its centre (a sure miss).
template <typename Prim>
std::pair<Ray, Prim> extreme_d_ray(Rng& rng, std::size_t i, Sample<Prim> (*sample)(Rng&)) {
  const Sample<Prim> s = sample(rng);
  const V3 o = s.centre + unit_vector(rng) * (3 * s.size);
  const V3 target = i % 2 == 0 ? s.inside(rng) : s.centre + perpendicular_unit(rng, normalized(s.centre - o)) * (2.5 * s.size);
  const V3 u = normalized(target - to_d(to_f(o)));
  const double len = i % 4 < 2 ? 1e-40 : static_cast<double>(FLT_MAX);
  return {make_ray(to_f(o), to_f(u * len)), s.prim};
}

// The sets above, for one family.
template <typename Prim>
void add_common_sets(std::vector<PrimRaySet<Prim>>& sets, const std::string& scene, std::size_t n, std::uint64_t seed,
                     Sample<Prim> (*sample)(Rng&)) {
  sets.push_back(make_set<Prim>(scene, "invalid-rays", n, seed, [&](Rng& rng, std::size_t i) {
    auto [ray, prim] = hitting_ray(rng, sample);
    return std::pair{corrupt(ray, static_cast<int>(i % kInvalidCases)), prim};
  }));
  sets.push_back(make_set<Prim>(scene, "invalid-rays:extreme-d", n, seed,
                                [&](Rng& rng, std::size_t i) { return extreme_d_ray(rng, i, sample); }));
  // G16 direction-scaling: the control rays (one shared stream) with the unit
  // direction multiplied by 2^k, exactly (see kDirectionScaleExponents).
  for (const int k : kDirectionScaleExponents) {
    const int decimal = static_cast<int>(std::lround(k * std::log10(2.0)));
    sets.push_back(make_set<Prim>(
        scene, "direction-scaling:|d|=" + power_of_ten(decimal), n, seed,
        [&](Rng& rng, std::size_t) {
          auto [ray, prim] = control_ray(rng, sample);
          for (int a = 0; a < 3; ++a) ray.dir[a] = std::ldexp(ray.dir[a], k);
          return std::pair{ray, prim};
        },
        "direction-scaling"));
  }
  sets.push_back(make_set<Prim>(scene, "control-random", n, seed, [&](Rng& rng, std::size_t) { return control_ray(rng, sample); }));
}

// --- Boxes with exact faces (G09, G11) --------------------------------------------

// A box whose axes are a signed permutation of the world axes, with centre
// and half extents multiples of 1/8: every face, edge and corner point is a
// float, so origins can lie exactly on them. The same frame gives the AABB
// (lower/upper) and the OBB (exact unit axes).
struct Frame {
  V3 centre, half;
  int perm[3];
  double sign[3];

  V3 world(V3 local) const {
    V3 p = centre;
    for (int i = 0; i < 3; ++i) p[perm[i]] += sign[i] * local[i];
    return p;
  }
  V3 world_dir(V3 local) const {
    V3 d;
    for (int i = 0; i < 3; ++i) d[perm[i]] = sign[i] * local[i];
    return d;
  }
  BBox bbox() const {
    BBox b;
    for (int i = 0; i < 3; ++i) {
      b.lower[perm[i]] = static_cast<float>(centre[perm[i]] - half[i]);
      b.upper[perm[i]] = static_cast<float>(centre[perm[i]] + half[i]);
    }
    return b;
  }
  OrientedBox obb() const {
    OrientedBox b;
    b.center = to_f(centre);
    for (int i = 0; i < 3; ++i) {
      b.axis[i] = {0, 0, 0};
      b.axis[i][perm[i]] = static_cast<float>(sign[i]);
      b.half_extent[i] = static_cast<float>(half[i]);
    }
    return b;
  }
};

Frame exact_frame(Rng& rng) {
  static constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  Frame f;
  const int p = uniform_int(rng, 6);
  for (int i = 0; i < 3; ++i) {
    f.perm[i] = kPermutations[p][i];
    f.sign[i] = coin(rng) ? 1.0 : -1.0;
    f.centre[i] = (uniform_int(rng, 33) - 16) / 8.0;  // [-2, 2]
    f.half[i] = (2 + uniform_int(rng, 7)) / 8.0;      // [0.25, 1]
  }
  return f;
}

// G09 axis-parallel-signed-zero. Origin: on a face (one local coordinate on
// a plane, the others inside), an edge (two), a corner (three), or on a slab
// plane outside the box (one on a plane, another outside). Direction: one of
// the 26 patterns {-1,0,+1}^3 \ {0} with magnitudes in [0.25, 2]. Rays come
// in twins, 2j and 2j+1, identical except that every zero component has the
// opposite sign: the exact answer is the same, so a kernel that depends on
// the sign of zero gets one of the twins wrong.
std::pair<Ray, Frame> signed_zero_ray(Rng& rng, bool twin) {
  const Frame f = exact_frame(rng);
  enum Where { kLower, kUpper, kInside, kBelow, kAbove };
  const auto plane = [&] { return coin(rng) ? kLower : kUpper; };
  const auto outside = [&] { return coin(rng) ? kBelow : kAbove; };
  Where where[3] = {kInside, kInside, kInside};
  const int a = uniform_int(rng, 3), b = (a + 1) % 3, c = (a + 2) % 3;
  switch (uniform_int(rng, 4)) {
    case 0: where[a] = plane(); break;                                   // face
    case 1: where[a] = plane(), where[b] = plane(); break;               // edge
    case 2: where[a] = plane(), where[b] = plane(), where[c] = plane(); break;  // corner
    default:                                                             // slab plane, outside
      where[a] = plane();
      where[b] = outside();
      if (coin(rng)) where[c] = outside();
  }
  V3 local;
  for (int i = 0; i < 3; ++i) {
    const double h = f.half[i];
    switch (where[i]) {
      case kLower: local[i] = -h; break;
      case kUpper: local[i] = h; break;
      case kInside: local[i] = h * uniform(rng, -0.9, 0.9); break;
      case kBelow: local[i] = -h - uniform(rng, 0.1, 1); break;
      case kAbove: local[i] = h + uniform(rng, 0.1, 1); break;
    }
  }
  const int k = uniform_int(rng, 26);
  const int code = k < 13 ? k : k + 1;  // 13 is (0, 0, 0)
  V3 dir_local;
  for (int i = 0, c3 = code; i < 3; ++i, c3 /= 3) dir_local[i] = (c3 % 3 - 1) * uniform(rng, 0.25, 2);
  Vec3f dir = to_f(f.world_dir(dir_local));
  for (int j = 0; j < 3; ++j) {
    const bool negative = coin(rng) != twin;  // drawn for every axis, so both twins draw alike
    if (dir[j] == 0.0f) dir[j] = negative ? -0.0f : 0.0f;
  }
  return {make_ray(to_f(f.world(local)), dir), f};
}

// G11 origin-on-surface: origin on a random face, exactly (i % 3 == 0), one
// float step outside (1) or inside (2); direction uniform in the outward or
// inward half space with at least 0.1 of it across the face (rays along the
// face are G09's).
std::pair<Ray, Frame> on_surface_ray(Rng& rng, std::size_t i, bool outward) {
  const Frame f = exact_frame(rng);
  const int a = uniform_int(rng, 3);
  const double side = coin(rng) ? 1.0 : -1.0;
  V3 local;
  for (int k = 0; k < 3; ++k) local[k] = f.half[k] * uniform(rng, -0.9, 0.9);
  local[a] = side * f.half[a];
  Vec3f org = to_f(f.world(local));
  const int j = f.perm[a];
  const float out = f.sign[a] * side > 0 ? kInf : -kInf;  // the world direction leaving the box
  if (i % 3 == 1) org[j] = std::nextafter(org[j], out);
  if (i % 3 == 2) org[j] = std::nextafter(org[j], -out);
  V3 v = unit_vector(rng);
  v[a] = std::max(std::fabs(v[a]), 0.1) * (outward ? side : -side);
  return {make_ray(org, to_f(normalized(f.world_dir(normalized(v))))), f};
}

}  // namespace

namespace {

// The box and the OBB get the same sets, the primitive made from the same
// frames: G09 (twins differing only in the sign of zero; exact-float faces,
// signed-permutation axes), G10 origin-inside (uniform in the box with a 10 %
// margin, uniform directions), G11 on the surface outward and inward, and the
// common sets.
template <typename Prim>
std::vector<PrimRaySet<Prim>> slab_raysets(const std::string& scene, std::size_t n, std::uint64_t seed,
                                           Prim (Frame::*from_frame)() const, Sample<Prim> (*random)(Rng&)) {
  std::vector<PrimRaySet<Prim>> sets;
  const std::uint64_t pairs = hash_string((scene + "/axis-parallel-signed-zero/pairs").c_str());
  sets.push_back(make_set<Prim>(scene, "axis-parallel-signed-zero", n, seed, [&](Rng&, std::size_t i) {
    Rng pair_rng(seed, pairs, i / 2);
    auto [ray, frame] = signed_zero_ray(pair_rng, i % 2 == 1);
    return std::pair{ray, (frame.*from_frame)()};
  }));
  sets.push_back(make_set<Prim>(scene, "origin-inside", n, seed, [&](Rng& rng, std::size_t) {
    const Sample<Prim> s = random(rng);
    return std::pair{make_ray(to_f(s.inside(rng)), to_f(unit_vector(rng))), s.prim};
  }));
  for (const bool outward : {true, false})
    sets.push_back(make_set<Prim>(scene, outward ? "origin-on-surface:outward" : "origin-on-surface:inward", n, seed,
                                  [&](Rng& rng, std::size_t i) {
                                    auto [ray, frame] = on_surface_ray(rng, i, outward);
                                    return std::pair{ray, (frame.*from_frame)()};
                                  }));
  add_common_sets<Prim>(sets, scene, n, seed, random);
  return sets;
}

}  // namespace

std::vector<PrimRaySet<BBox>> box_raysets(std::size_t n, std::uint64_t seed) {
  return slab_raysets<BBox>("prim:box", n, seed, &Frame::bbox, random_box);
}

std::vector<PrimRaySet<OrientedBox>> obb_raysets(std::size_t n, std::uint64_t seed) {
  return slab_raysets<OrientedBox>("prim:obb", n, seed, &Frame::obb, random_obb);
}

std::vector<PrimRaySet<Sphere>> sphere_raysets(std::size_t n, std::uint64_t seed) {
  const std::string scene = "prim:sphere";
  std::vector<PrimRaySet<Sphere>> sets;
  // G10 origin-inside: uniform in the ball (radius 0.9 r), uniform
  // directions: about half have the centre behind the origin, where seed 003's
  // `projoc < 0` rejects.
  sets.push_back(make_set<Sphere>(scene, "origin-inside", n, seed, [](Rng& rng, std::size_t) {
    const Sample<Sphere> s = random_sphere(rng);
    return std::pair{make_ray(to_f(s.inside(rng)), to_f(unit_vector(rng))), s.prim};
  }));
  // G12 far-small-sphere: the unit sphere at the origin seen from distance
  // D, aimed at a lateral offset h ~ U[0, 2] from the centre (about half hit).
  for (int e = 2; e <= 10; ++e) {
    const double distance = std::pow(10.0, e);
    sets.push_back(make_set<Sphere>(scene, "far-small-sphere:D=" + power_of_ten(e), n, seed, [distance](Rng& rng, std::size_t) {
      const V3 u = unit_vector(rng);
      const Vec3f o = to_f(u * distance);
      const V3 target = perpendicular_unit(rng, u) * uniform(rng, 0, 2);
      return std::pair{aimed(o, target), Sphere{{0, 0, 0}, 1.0f}};
    }));
  }
  // G13 tiny-sphere: radius r at distance 1-10, aimed at a lateral offset
  // h r with h ~ U[0, 1.2], and one ray in three near tangent
  // (h = 1 +/- 1e-3). At r = 1e-7 the float direction's resolution (~6e-8
  // rad) is comparable to r: the exact truth then decides which rays hit.
  for (int e = -3; e >= -7; --e) {
    const double radius = std::pow(10.0, e);
    sets.push_back(make_set<Sphere>(scene, "tiny-sphere:r=" + power_of_ten(e), n, seed, [radius](Rng& rng, std::size_t i) {
      const Sphere s{to_f(uniform_in_cube(rng, 1)), static_cast<float>(radius)};
      const V3 c = to_d(s.center), u = unit_vector(rng);
      const Vec3f o = to_f(c + u * uniform(rng, 1, 10));
      const double h = i % 3 == 0 ? 1 + uniform(rng, -1e-3, 1e-3) : uniform(rng, 0, 1.2);
      return std::pair{aimed(o, c + perpendicular_unit(rng, u) * (h * s.radius)), s};
    }));
  }
  add_common_sets<Sphere>(sets, scene, n, seed, random_sphere);
  return sets;
}

std::vector<PrimRaySet<Triangle>> triangle_raysets(std::size_t n, std::uint64_t seed) {
  const std::string scene = "prim:triangle";
  std::vector<PrimRaySet<Triangle>> sets;
  // G05 tiny-triangles: legs of 1e-3, 1e-5, 1e-7 (angle between them 30-150
  // degrees) at the origin and at offset (1e3, 1e3, 1e3), seen from 1000
  // legs away (|n.d| >= 0.3), aimed at an interior point with barycentric
  // margin 0.1. At offset 1e3 the float spacing is 6.1e-5: legs of 1e-5 and
  // 1e-7 round to (nearly) degenerate triangles, and the exact truth says so.
  for (const int leg_exp : {-3, -5, -7})
    for (const double offset : {0.0, 1e3}) {
      const double leg = std::pow(10.0, leg_exp);
      const std::string name = "tiny-triangles:leg=" + power_of_ten(leg_exp) + (offset > 0 ? ",offset=1e3" : "");
      sets.push_back(make_set<Triangle>(scene, name, n, seed, [leg, offset](Rng& rng, std::size_t) {
        V3 e1, e2;
        do {
          e1 = unit_vector(rng);
          e2 = unit_vector(rng);
        } while (std::fabs(dot(e1, e2)) > std::cos(std::numbers::pi / 6));
        const V3 v0 = V3{offset, offset, offset} + uniform_in_cube(rng, 0.5 * leg);
        const Triangle t{to_f(v0), to_f(v0 + e1 * leg), to_f(v0 + e2 * leg)};
        const V3 target = interior_point(rng, t, 0.1);
        const V3 n = normalized(cross(e1, e2));
        V3 u;
        do u = unit_vector(rng);
        while (std::fabs(dot(u, n)) < 0.3);
        return std::pair{aimed(to_f(target + u * (1000 * leg)), target), t};
      }));
    }
  // G07 grazing: at angle alpha to the plane of a well-shaped triangle,
  // aimed at an interior point (margin 0.1) from 0.5-2 away.
  for (int e = -2; e >= -6; --e) {
    const double alpha = std::pow(10.0, e);
    sets.push_back(make_set<Triangle>(scene, "grazing:a=" + power_of_ten(e), n, seed, [alpha](Rng& rng, std::size_t) {
      const Triangle t = random_triangle(rng);
      const V3 target = interior_point(rng, t, 0.1), n = normal_of(t);
      const V3 along = perpendicular_unit(rng, n);
      const V3 dir = along * std::cos(alpha) + n * ((coin(rng) ? 1 : -1) * std::sin(alpha));
      return std::pair{aimed(to_f(target - dir * uniform(rng, 0.5, 2)), target), t};
    }));
  }
  // G08 degenerate-triangles (EXTREMES.md): (a) the exact-integer collinear
  // triangle (0,0,0), (3000,5000,7000), (5331,8885,12439) in a random vertex
  // order; (b) a random triangle with one vertex repeated; both aimed at a
  // point of a segment of theirs (or the repeated vertex) from 1e3-1e4 away
  // (a) or 1-3 away (b): never a hit. (c) needles: length 0.5-2, width 1e-7
  // of that (aspect 1e7), aimed at an interior point: judged exactly.
  sets.push_back(make_set<Triangle>(scene, "degenerate-triangles:collinear", n, seed, [](Rng& rng, std::size_t) {
    const Vec3f p[3] = {{0, 0, 0}, {3000, 5000, 7000}, {5331, 8885, 12439}};
    const int r = uniform_int(rng, 3);
    const Triangle t{p[r], p[(r + 1) % 3], p[(r + 2) % 3]};
    const V3 a = to_d(p[uniform_int(rng, 3)]), b = to_d(p[uniform_int(rng, 3)]);
    const V3 target = a + (b - a) * rng.next_double();
    return std::pair{aimed(to_f(target + unit_vector(rng) * uniform(rng, 1e3, 1e4)), target), t};
  }));
  sets.push_back(make_set<Triangle>(scene, "degenerate-triangles:repeated", n, seed, [](Rng& rng, std::size_t) {
    Triangle t = random_triangle(rng);
    Vec3f* v[3] = {&t.v0, &t.v1, &t.v2};
    const int keep = uniform_int(rng, 3), copy = (keep + 1 + uniform_int(rng, 2)) % 3, other = 3 - keep - copy;
    *v[copy] = *v[keep];
    // Aim at the repeated vertex or at a point of the one remaining segment.
    const V3 a = to_d(*v[keep]), b = to_d(*v[other]);
    const V3 target = coin(rng) ? a : a + (b - a) * rng.next_double();
    return std::pair{aimed(to_f(target + unit_vector(rng) * uniform(rng, 1, 3)), target), t};
  }));
  sets.push_back(make_set<Triangle>(scene, "degenerate-triangles:needle", n, seed, [](Rng& rng, std::size_t) {
    const V3 v0 = uniform_in_cube(rng, 1), e = unit_vector(rng);
    const double len = uniform(rng, 0.5, 2);
    const V3 w = perpendicular_unit(rng, e);
    const Triangle t{to_f(v0), to_f(v0 + e * len), to_f(v0 + e * (0.5 * len) + w * (1e-7 * len))};
    const V3 target = interior_point(rng, t, 0.1);
    return std::pair{aimed(to_f(target + unit_vector(rng) * uniform(rng, 1, 3)), target), t};
  }));
  // G14 behind-origin: the ray leaves an interior point of the triangle and
  // starts 0.5-3 beyond it (|n.d| >= 0.3): the triangle lies at t < 0.
  sets.push_back(make_set<Triangle>(scene, "behind-origin", n, seed, [](Rng& rng, std::size_t) {
    const Triangle t = random_triangle(rng);
    const V3 target = interior_point(rng, t, 0.1), n = normal_of(t);
    V3 u;
    do u = unit_vector(rng);
    while (std::fabs(dot(u, n)) < 0.3);
    const Vec3f o = to_f(target + u * uniform(rng, 0.5, 3));
    return std::pair{make_ray(o, to_f(normalized(to_d(o) - target))), t};
  }));
  // G19 coplanar: a triangle in the plane x_k = c (c a multiple of 1/8, so
  // the plane is exact) and a ray in that plane (direction component k = +0
  // or -0) crossing the triangle's interior; odd rays start one float step
  // above or below the plane instead, parallel to it. Never a hit.
  sets.push_back(make_set<Triangle>(scene, "coplanar", n, seed, [](Rng& rng, std::size_t i) {
    const int k = uniform_int(rng, 3);
    const float c = static_cast<float>((uniform_int(rng, 17) - 8) / 8.0);
    Triangle t = random_triangle(rng);
    t.v0[k] = t.v1[k] = t.v2[k] = c;
    const V3 target = interior_point(rng, t, 0.1);  // its k coordinate is c exactly
    V3 along = unit_vector(rng);
    along[k] = 0;
    along = normalized(along);
    Vec3f o = to_f(target - along * uniform(rng, 2, 4));
    o[k] = c;
    Ray r = aimed(o, target);
    r.dir[k] = coin(rng) ? -0.0f : 0.0f;
    if (i % 2 == 1) r.org[k] = std::nextafter(c, coin(rng) ? kInf : -kInf);
    return std::pair{r, t};
  }));
  add_common_sets<Triangle>(sets, scene, n, seed, random_triangle_sample);
  return sets;
}

}  // namespace raybench
