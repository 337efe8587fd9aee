// The ambiguity band of analytic primitives (referee/analytic_band.h), in
// double: the box and the OBB share one slab formulation, the OBB's in its
// frame (the given axes, as the exact referee reads them).
#include "referee/analytic_band.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace raybench {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct V3 {
  double x, y, z;
  double operator[](int i) const { return i == 0 ? x : i == 1 ? y : z; }
};
V3 d3(Vec3f v) { return {v.x, v.y, v.z}; }
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// A box in some frame: along axis i the ray's coordinate is e[i] + t f[i],
// and the box spans [lower[i], upper[i]].
struct FrameBox {
  double e[3], f[3], lower[3], upper[3];
};

FrameBox frame(const Ray& ray, const BBox& box) {
  FrameBox b;
  for (int i = 0; i < 3; ++i) {
    b.e[i] = ray.org[i];
    b.f[i] = ray.dir[i];
    b.lower[i] = box.lower[i];
    b.upper[i] = box.upper[i];
  }
  return b;
}

FrameBox frame(const Ray& ray, const OrientedBox& box) {
  FrameBox b;
  const V3 offset = sub(d3(ray.org), d3(box.center)), dir = d3(ray.dir);
  for (int i = 0; i < 3; ++i) {
    const V3 axis = d3(box.axis[i]);
    b.e[i] = dot(offset, axis);
    b.f[i] = dot(dir, axis);
    b.lower[i] = -static_cast<double>(box.half_extent[i]);
    b.upper[i] = box.half_extent[i];
  }
  return b;
}

bool near_boundary(const FrameBox& b, double t, double band) {
  int near_planes = 0;
  for (int i = 0; i < 3; ++i) {
    // Relative to the plane, without forming the large coordinate first.
    const double to_lower = (b.e[i] - b.lower[i]) + t * b.f[i];
    const double to_upper = (b.upper[i] - b.e[i]) - t * b.f[i];
    const double width = band * (b.upper[i] - b.lower[i]);
    near_planes += std::min(std::fabs(to_lower), std::fabs(to_upper)) <= width;
  }
  return near_planes >= 2;
}

double near_miss_t(const FrameBox& b, double lo, double hi, double band) {
  double entry = lo, exit = hi;
  for (int i = 0; i < 3; ++i) {
    const double grow = band * (b.upper[i] - b.lower[i]);
    const double lower = b.lower[i] - grow, upper = b.upper[i] + grow;
    if (b.f[i] == 0.0) {
      if (!(lower <= b.e[i] && b.e[i] <= upper)) return kInf;
      continue;
    }
    double t0 = (lower - b.e[i]) / b.f[i], t1 = (upper - b.e[i]) / b.f[i];
    if (t0 > t1) std::swap(t0, t1);
    entry = std::max(entry, t0);
    exit = std::min(exit, t1);
  }
  if (!(entry <= exit) || !(exit > lo)) return kInf;
  return std::max(entry, std::nextafter(lo, kInf));
}

// (r^2 - h^2) / r^2 for the ray's line and the sphere, h its distance from
// the centre: |f x d|^2 / |d|^2 has no cancellation, unlike b^2 - a C.
double tangency(const Ray& ray, const Sphere& s) {
  const V3 f = sub(d3(ray.org), d3(s.center)), d = d3(ray.dir);
  const V3 c = cross(f, d);
  const double r2 = static_cast<double>(s.radius) * s.radius;
  const double h2 = dot(c, c) / dot(d, d);
  return r2 > 0.0 ? (r2 - h2) / r2 : (h2 > 0.0 ? -kInf : 0.0);
}

}  // namespace

bool near_boundary(const Ray& ray, const Sphere& sphere, double, double band) {
  return std::fabs(tangency(ray, sphere)) <= 2.0 * band;
}

bool near_boundary(const Ray& ray, const BBox& box, double t, double band) { return near_boundary(frame(ray, box), t, band); }

bool near_boundary(const Ray& ray, const OrientedBox& box, double t, double band) {
  return near_boundary(frame(ray, box), t, band);
}

double near_miss_t(const Ray& ray, const Sphere& sphere, double lo, double hi, double band) {
  if (!(std::fabs(tangency(ray, sphere)) <= 2.0 * band)) return kInf;
  const V3 f = sub(d3(ray.org), d3(sphere.center)), d = d3(ray.dir);
  const double closest = -dot(f, d) / dot(d, d);  // the t of the closest approach to the centre
  return closest > lo && closest <= hi ? closest : kInf;
}

double near_miss_t(const Ray& ray, const BBox& box, double lo, double hi, double band) {
  return near_miss_t(frame(ray, box), lo, hi, band);
}

double near_miss_t(const Ray& ray, const OrientedBox& box, double lo, double hi, double band) {
  return near_miss_t(frame(ray, box), lo, hi, band);
}

}  // namespace raybench
