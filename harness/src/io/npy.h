// NumPy .npy files (format versions 1.0-3.0, C order, little-endian), the
// exchange format for ray sets and hit records, so users can inspect or
// supply them with numpy.load / numpy.save.
//
// Ray files: float32, shape (N, 8), columns ox oy oz tnear dx dy dz tfar.
// Hit files: float64, shape (N, 4), columns t prim u v (t = inf, prim = -1 on a miss).
// Occlusion files: float64, shape (N, 1), 1 when occluded, 0 when not.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "raybench/math/ray.h"

namespace raybench {

// Reads a ray file; throws InputError naming the file for a wrong magic,
// header, dtype, shape, order, or a body shorter or longer than the header says.
std::vector<Ray> read_ray_file(const std::string& path);
void write_ray_file(const std::string& path, std::span<const Ray> rays);

// Writes float64 data of shape (rows, columns), row-major.
void write_npy_f64(const std::string& path, std::span<const double> data, std::size_t rows, std::size_t columns);

// Reads float64 data of shape (rows, columns); used by tests and tools.
std::vector<double> read_npy_f64(const std::string& path, std::size_t& rows, std::size_t& columns);

// Reads a float32 or float64 array of shape (N, columns) as doubles (float32
// values widen exactly), row-major; sets `rows` to N. `what` says what the
// file holds, for the messages, e.g. "spheres: cx cy cz r". Throws InputError
// naming the file for any other dtype, a shape other than (N, columns), and
// everything read_ray_file refuses.
std::vector<double> read_npy_real(const std::string& path, std::size_t columns, const std::string& what,
                                  std::size_t& rows);

}  // namespace raybench
