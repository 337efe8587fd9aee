// Analytic primitives from NumPy .npy files, as a suite manifest names them
// (issue 31; keys spheres, boxes, obbs in docs/manifest.md, formats in
// docs/scenes.md). Each file is float32 or float64 of shape (N, k), one
// primitive per row, in the row order that their prim ids follow:
//
//   spheres  (N, 4)   cx cy cz r
//   boxes    (N, 6)   min_x min_y min_z max_x max_y max_z
//   obbs     (N, 15)  cx cy cz, axis 0 xyz, axis 1 xyz, axis 2 xyz, hx hy hz
//
// Values are rounded to float (what every backend traces) and checked after
// rounding. Every malformed row is one InputError line naming the file and
// the row (0-based, as numpy indexes it): a value that is NaN or infinite, a
// negative radius or half extent, min > max on an axis, OBB axes not of unit
// length or not orthogonal beyond kObbAxisTolerance, a primitive reaching
// beyond +-kMaxSceneCoordinate (scene.h). A radius or half extent of 0 (a
// point, a flat box) is kept, as degenerate triangles are.
#pragma once

#include <string>
#include <vector>

#include "raybench/math/bbox.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/sphere.h"

namespace raybench {

// 1e-5: | |axis| - 1 | and |axis_i . axis_j| (in double, of the float axes)
// may be this large. A float32 rotation matrix normalised by the user is off
// by a few 1e-7; 1e-5 keeps the OBB tests' projections (prim/obb.h, which
// assume orthonormal axes and do not check) within 1e-5 of the box's true
// extent, while a matrix with a scale or a shear in it is refused.
inline constexpr double kObbAxisTolerance = 1e-5;

std::vector<Sphere> read_sphere_file(const std::string& path);
std::vector<BBox> read_box_file(const std::string& path);
std::vector<OrientedBox> read_obb_file(const std::string& path);

}  // namespace raybench
