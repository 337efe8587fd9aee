// Reading analytic primitives from .npy files (scene/analytic_files.h): each
// row rounded to float, then checked, the first problem thrown as one line
// naming the file, the row and the values at fault.
#include "scene/analytic_files.h"

#include <cmath>

#include <fmt/format.h>

#include "io/error.h"
#include "io/npy.h"
#include "raybench/prim/primitives.h"
#include "scene/scene.h"

namespace raybench {
namespace {

// One file's rows, rounded to float; checks shared by the three formats.
class Rows {
 public:
  Rows(std::string path, std::size_t columns, const char* what, const char* const* column_names)
      : path_(std::move(path)), columns_(columns), names_(column_names) {
    const std::vector<double> values = read_npy_real(path_, columns, what, count_);
    values_.resize(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      values_[i] = static_cast<float>(values[i]);
      // Checked as float: 1e39 is a finite double but an infinite float.
      if (!std::isfinite(values_[i]))
        fail(i / columns, fmt::format("column {} ({}) is {:g}{}: every value must be finite", i % columns,
                                      names_[i % columns], values[i],
                                      std::isfinite(values[i]) ? ", beyond float32's range" : ""));
    }
  }

  std::size_t count() const { return count_; }
  float at(std::size_t row, std::size_t column) const { return values_[row * columns_ + column]; }
  Vec3f vec(std::size_t row, std::size_t first) const { return {at(row, first), at(row, first + 1), at(row, first + 2)}; }

  [[noreturn]] void fail(std::size_t row, const std::string& problem) const {
    throw InputError(path_, fmt::format("row {}: {}", row, problem));
  }

  // The primitive's box must lie within +-kMaxSceneCoordinate, as every
  // triangle's vertex must (check_scene_coordinates, scene.h).
  void check_reach(std::size_t row, const char* kind, const BBox& b) const {
    for (int a = 0; a < 3; ++a) {
      for (const float c : {b.lower[a], b.upper[a]}) {
        if (std::fabs(c) <= kMaxSceneCoordinate) continue;
        fail(row, fmt::format("the {} reaches {} = {:g}; coordinates must be finite and within +-{:g} (box areas "
                              "must stay finite in float)",
                              kind, "xyz"[a], static_cast<double>(c), static_cast<double>(kMaxSceneCoordinate)));
      }
    }
  }

 private:
  std::string path_;
  std::size_t columns_;
  const char* const* names_;
  std::size_t count_ = 0;
  std::vector<float> values_;
};

std::string vec_string(Vec3f v) { return fmt::format("({:g}, {:g}, {:g})", v.x, v.y, v.z); }

double dot_double(Vec3f a, Vec3f b) {
  return static_cast<double>(a.x) * b.x + static_cast<double>(a.y) * b.y + static_cast<double>(a.z) * b.z;
}

}  // namespace

std::vector<Sphere> read_sphere_file(const std::string& path) {
  static const char* const names[] = {"cx", "cy", "cz", "r"};
  const Rows rows(path, 4, "spheres: cx cy cz r", names);
  std::vector<Sphere> out(rows.count());
  for (std::size_t i = 0; i < rows.count(); ++i) {
    out[i] = {rows.vec(i, 0), rows.at(i, 3)};
    if (out[i].radius < 0.0f) rows.fail(i, fmt::format("radius is {:g}: it must be >= 0", out[i].radius));
    rows.check_reach(i, "sphere", sphere_bounds(out[i]));
  }
  return out;
}

std::vector<BBox> read_box_file(const std::string& path) {
  static const char* const names[] = {"min_x", "min_y", "min_z", "max_x", "max_y", "max_z"};
  const Rows rows(path, 6, "boxes: min_x min_y min_z max_x max_y max_z", names);
  std::vector<BBox> out(rows.count());
  for (std::size_t i = 0; i < rows.count(); ++i) {
    out[i].lower = rows.vec(i, 0);
    out[i].upper = rows.vec(i, 3);
    for (int a = 0; a < 3; ++a)
      if (out[i].lower[a] > out[i].upper[a])
        rows.fail(i, fmt::format("min_{0} {1:g} > max_{0} {2:g}: a box's min must not exceed its max", "xyz"[a],
                                 out[i].lower[a], out[i].upper[a]));
    rows.check_reach(i, "box", out[i]);
  }
  return out;
}

std::vector<OrientedBox> read_obb_file(const std::string& path) {
  static const char* const names[] = {"cx",  "cy",  "cz",  "a0x", "a0y", "a0z", "a1x", "a1y",
                                      "a1z", "a2x", "a2y", "a2z", "hx",  "hy",  "hz"};
  const Rows rows(path, 15, "obbs: cx cy cz, axis 0 xyz, axis 1 xyz, axis 2 xyz, hx hy hz", names);
  std::vector<OrientedBox> out(rows.count());
  for (std::size_t i = 0; i < rows.count(); ++i) {
    OrientedBox& o = out[i];
    o.center = rows.vec(i, 0);
    for (int k = 0; k < 3; ++k) o.axis[k] = rows.vec(i, 3 + 3 * k);
    o.half_extent = rows.vec(i, 12);
    for (int k = 0; k < 3; ++k) {
      if (o.half_extent[k] < 0.0f)
        rows.fail(i, fmt::format("half extent {} is {:g}: it must be >= 0", k, o.half_extent[k]));
      const double length = std::sqrt(dot_double(o.axis[k], o.axis[k]));
      if (!(std::fabs(length - 1.0) <= kObbAxisTolerance))
        rows.fail(i, fmt::format("axis {} {} has length {:.9g}: the axes must be unit vectors (within {:g})", k,
                                 vec_string(o.axis[k]), length, kObbAxisTolerance));
    }
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      const double d = dot_double(o.axis[std::min(k, l)], o.axis[std::max(k, l)]);
      if (!(std::fabs(d) <= kObbAxisTolerance))
        rows.fail(i, fmt::format("axes {} {} and {} {} are not orthogonal: dot product {:.9g} (tolerance {:g})",
                                 std::min(k, l), vec_string(o.axis[std::min(k, l)]), std::max(k, l),
                                 vec_string(o.axis[std::max(k, l)]), d, kObbAxisTolerance));
    }
    rows.check_reach(i, "oriented box", oriented_box_bounds(o));
  }
  return out;
}

}  // namespace raybench
