// Targets on analytic primitives for the ray generators
// (rays/analytic_targets.h). A box and an oriented box share one
// formulation: a centre, three unit axes and half extents (a box's axes are
// the coordinate axes), all in double.
#include "rays/analytic_targets.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace raybench {
namespace {

Eigen::Vector3d to_eigen(Vec3f v) { return {v.x, v.y, v.z}; }
Vec3f to_vec(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

struct Frame {
  Eigen::Vector3d center;
  std::array<Eigen::Vector3d, 3> axis;  // unit
  Eigen::Vector3d half;

  Eigen::Vector3d at(const Eigen::Vector3d& local) const {
    return center + axis[0] * local[0] + axis[1] * local[1] + axis[2] * local[2];
  }
  Eigen::Vector3d local(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d q = p - center;
    return {q.dot(axis[0]), q.dot(axis[1]), q.dot(axis[2])};
  }
  Eigen::Vector3d corner(int k) const {
    return at({k & 1 ? half[0] : -half[0], k & 2 ? half[1] : -half[1], k & 4 ? half[2] : -half[2]});
  }
};

Frame frame_of(const PrimitiveSpans& prims, std::size_t id) {
  const std::size_t i = prims.local(id);
  Frame f;
  if (prims.kind(id) == PrimitiveKind::kBox) {
    const BBox& b = prims.boxes[i];
    f.center = 0.5 * (to_eigen(b.lower) + to_eigen(b.upper));
    f.half = 0.5 * (to_eigen(b.upper) - to_eigen(b.lower));
    f.axis = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
    return f;
  }
  const OrientedBox& o = prims.obbs[i];
  f.center = to_eigen(o.center);
  f.half = to_eigen(o.half_extent).cwiseAbs();
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d axis = to_eigen(o.axis[a]);
    f.axis[a] = axis.norm() > 0.0 ? Eigen::Vector3d(axis.normalized()) : Eigen::Vector3d::Unit(a);
  }
  return f;
}

Eigen::Vector3d uniform_direction(Rng& rng) {
  const double z = 2.0 * rng.next_double() - 1.0, phi = 2.0 * std::numbers::pi * rng.next_double();
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), z, s * std::sin(phi)};
}

}  // namespace

SurfacePoint nearest_surface_point(const PrimitiveSpans& prims, std::size_t id, const Eigen::Vector3d& p,
                                   const Eigen::Vector3d& org, const Eigen::Vector3d& dir) {
  if (prims.kind(id) == PrimitiveKind::kSphere) {
    const Sphere& s = prims.spheres[prims.local(id)];
    const Eigen::Vector3d c = to_eigen(s.center), q = p - c;
    const Eigen::Vector3d n = q.norm() > 0.0 ? Eigen::Vector3d(q.normalized()) : Eigen::Vector3d::UnitY();
    return {c + std::fabs(static_cast<double>(s.radius)) * n, n};
  }
  const Frame f = frame_of(prims, id);
  Eigen::Vector3d e = f.local(p);
  const Eigen::Vector3d o = f.local(org);
  const bool entering = (o.cwiseAbs() - f.half).maxCoeff() > 0.0;
  // The face whose plane is nearest (|e_a| closest to h_a), preferring,
  // within 1e-6 of the box's size, one the ray can have crossed.
  const double tie = 1e-6 * f.half.norm();
  int face = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double toward = (std::signbit(e[a]) ? -1.0 : 1.0) * f.axis[a].dot(dir);  // outward normal . dir
    const bool crossable = entering ? toward < 0.0 : toward > 0.0;
    const double gap = std::fabs(std::fabs(e[a]) - f.half[a]) + (crossable ? 0.0 : tie);
    if (gap < best) best = gap, face = a;
  }
  const double side = std::signbit(e[face]) ? -1.0 : 1.0;
  for (int a = 0; a < 3; ++a) e[a] = std::clamp(e[a], -f.half[a], f.half[a]);
  e[face] = side * f.half[face];
  return {f.at(e), side * f.axis[face]};
}

SurfacePoint random_surface_point(const PrimitiveSpans& prims, std::size_t id, Rng& rng, double margin) {
  if (prims.kind(id) == PrimitiveKind::kSphere) {
    const Sphere& s = prims.spheres[prims.local(id)];
    const Eigen::Vector3d n = uniform_direction(rng);
    return {to_eigen(s.center) + std::fabs(static_cast<double>(s.radius)) * n, n};
  }
  const Frame f = frame_of(prims, id);
  // Face pair a (normal axis a) has area 4 h_b h_c per face.
  const double area[3] = {f.half[1] * f.half[2], f.half[0] * f.half[2], f.half[0] * f.half[1]};
  const double total = area[0] + area[1] + area[2];
  double pick = rng.next_double() * total;
  int face = total > 0.0 ? 2 : static_cast<int>(rng.next_u64() % 3);
  for (int a = 0; a < 2 && total > 0.0; ++a) {
    if (pick < area[a]) {
      face = a;
      break;
    }
    pick -= area[a];
  }
  const double side = rng.next_u64() % 2 ? 1.0 : -1.0;
  Eigen::Vector3d e;
  for (int a = 0; a < 3; ++a) e[a] = f.half[a] * (2.0 * (margin + (1.0 - 2.0 * margin) * rng.next_double()) - 1.0);
  e[face] = side * f.half[face];
  return {f.at(e), side * f.axis[face]};
}

Vec3f random_corner(const PrimitiveSpans& prims, std::size_t id, Rng& rng) {
  if (prims.kind(id) == PrimitiveKind::kSphere) {
    const Sphere& s = prims.spheres[prims.local(id)];
    const auto k = rng.next_u64() % 6;
    Vec3f p = s.center;
    p[static_cast<int>(k / 2)] += k % 2 ? std::fabs(s.radius) : -std::fabs(s.radius);
    return p;
  }
  if (prims.kind(id) == PrimitiveKind::kBox) {  // the box's own floats, exactly
    const BBox& b = prims.boxes[prims.local(id)];
    const auto k = rng.next_u64() % 8;
    return {(k & 1 ? b.upper : b.lower).x, (k & 2 ? b.upper : b.lower).y, (k & 4 ? b.upper : b.lower).z};
  }
  return to_vec(frame_of(prims, id).corner(static_cast<int>(rng.next_u64() % 8)));
}

Vec3f random_edge_point(const PrimitiveSpans& prims, std::size_t id, Rng& rng) {
  if (prims.kind(id) == PrimitiveKind::kSphere) return to_vec(random_surface_point(prims, id, rng, 0.0).point);
  // Edge: along axis a, at corner k of the other two axes' sides.
  const auto edge = rng.next_u64() % 12;
  const int a = static_cast<int>(edge / 4), k = static_cast<int>(edge % 4);
  const int bit_a = 1 << a, others[2] = {1 << ((a + 1) % 3), 1 << ((a + 2) % 3)};
  const int start = (k & 1 ? others[0] : 0) | (k & 2 ? others[1] : 0);
  Vec3f from, to;
  if (prims.kind(id) == PrimitiveKind::kBox) {
    const BBox& b = prims.boxes[prims.local(id)];
    const auto corner = [&](int c) {
      return Vec3f{(c & 1 ? b.upper : b.lower).x, (c & 2 ? b.upper : b.lower).y, (c & 4 ? b.upper : b.lower).z};
    };
    from = corner(start);
    to = corner(start | bit_a);
  } else {
    const Frame f = frame_of(prims, id);
    from = to_vec(f.corner(start));
    to = to_vec(f.corner(start | bit_a));
  }
  return from + (to - from) * static_cast<float>(rng.next_double());  // the float lerp
}

double primitive_size(const PrimitiveSpans& prims, std::size_t id) {
  if (prims.kind(id) == PrimitiveKind::kSphere) return 2.0 * std::fabs(static_cast<double>(prims.spheres[prims.local(id)].radius));
  return 2.0 * frame_of(prims, id).half.norm();
}

}  // namespace raybench
