// Where the ray generators aim at analytic primitives (issue 31): points on
// a sphere's, box's or oriented box's surface with their outward normals,
// corners (a sphere's "corners" are its six axis-extreme points, where it
// touches its bounding box), float points on edges, and sizes. The
// counterparts of a triangle's interior points, vertices and edges in
// rays/rayset.cpp. Computed in double; random choices come from the
// caller's counter-based Rng, so a ray set stays a function of its spec.
#pragma once

#include <cstddef>

#include <Eigen/Dense>

#include "raybench/math/vec.h"
#include "raybench/prim/primitives.h"
#include "scene/random.h"

namespace raybench {

struct SurfacePoint {
  Eigen::Vector3d point;
  Eigen::Vector3d normal;  // unit, outward
};

// `id` must name an analytic primitive of `prims` (not a triangle).

// The surface point nearest `p`, the hit of the ray (org, dir) computed as
// org + t dir (off the surface by the rounding of t), and the outward normal
// there: a sphere's radial projection; a box's or OBB's nearest face, the
// point moved onto its plane and clamped into the face. Near an edge, where
// two faces' planes are within 1e-6 of the box's size, the face the ray can
// have crossed wins: one it enters (normal against dir) when org lies
// outside, one it leaves when org lies inside.
SurfacePoint nearest_surface_point(const PrimitiveSpans& prims, std::size_t id, const Eigen::Vector3d& p,
                                   const Eigen::Vector3d& org, const Eigen::Vector3d& dir);

// A random point of the surface: a sphere's uniformly; a box's or OBB's on
// a face chosen by area, each face coordinate at least `margin` (a fraction
// of the face's side) from the face's edges.
SurfacePoint random_surface_point(const PrimitiveSpans& prims, std::size_t id, Rng& rng, double margin);

// A random corner of a box or OBB (one of 8), or a random axis-extreme point of a sphere (one of 6).
Vec3f random_corner(const PrimitiveSpans& prims, std::size_t id, Rng& rng);

// A box's or OBB's random edge at a random fraction s, as the float lerp
// a + (b - a) s of its corners (as G02 aims at a triangle's edges); a
// sphere's random surface point.
Vec3f random_edge_point(const PrimitiveSpans& prims, std::size_t id, Rng& rng);

// The primitive's size: a sphere's diameter, a box's or OBB's diagonal.
double primitive_size(const PrimitiveSpans& prims, std::size_t id);

}  // namespace raybench
