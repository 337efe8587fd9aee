// Specification of scene primitive files (harness/src/scene/analytic_files.h):
// spheres, boxes and oriented boxes read from float32 or float64 .npy files
// in row order, and every malformed row refused in one line naming the file
// and the row.
#include "scene/analytic_files.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "io/npy.h"
#include "scene/procedural.h"
#include "scene/scene.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::TempDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A float32 (N, columns) .npy file as numpy.save writes it.
std::string write_f32(const TempDir& dir, const std::string& name, const std::vector<float>& values, std::size_t columns) {
  std::string dict = fmt::format("{{'descr': '<f4', 'fortran_order': False, 'shape': ({}, {}), }}",
                                 values.size() / columns, columns);
  dict.append((64 - (10 + dict.size() + 1) % 64) % 64, ' ');
  dict += '\n';
  std::string bytes = "\x93NUMPY";
  bytes += '\x01';
  bytes += '\0';
  bytes += static_cast<char>(dict.size() & 0xff);
  bytes += static_cast<char>(dict.size() >> 8);
  bytes += dict;
  bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  return dir.write(name, bytes);
}

std::string write_f64(const TempDir& dir, const std::string& name, const std::vector<double>& values, std::size_t columns) {
  write_npy_f64(dir.file(name), values, values.size() / columns, columns);
  return dir.file(name);
}

// The identity's axes, for OBB rows.
const std::vector<double> kAxes{1, 0, 0, 0, 1, 0, 0, 0, 1};

std::vector<double> obb_row(std::vector<double> center, std::vector<double> axes, std::vector<double> half) {
  std::vector<double> row = center;
  row.insert(row.end(), axes.begin(), axes.end());
  row.insert(row.end(), half.begin(), half.end());
  return row;
}

template <typename Read>
void expect_refused(Read read, const std::string& path, const std::string& problem) {
  const std::string error = testing::input_error_of([&] { read(path); });
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << "must start with the file: '" << error << "'";
  EXPECT_NE(error.find(problem), std::string::npos) << "expected '" << problem << "' in '" << error << "'";
  EXPECT_EQ(error.find('\n'), std::string::npos) << "multi-line error: " << error;
}

TEST(AnalyticFiles, SpheresBoxesAndObbsAreReadInRowOrderFromFloat64) {
  TempDir dir;
  const auto spheres = read_sphere_file(write_f64(dir, "s.npy", {1, 2, 3, 0.5, -1, -2, -3, 0.1}, 4));
  ASSERT_EQ(spheres.size(), 2u);
  EXPECT_EQ(spheres[1].center.y, -2.0f);
  EXPECT_EQ(spheres[1].radius, 0.1f);  // rounded to float, the value traced
  const auto boxes = read_box_file(write_f64(dir, "b.npy", {0, 1, 2, 3, 4, 5}, 6));
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_EQ(boxes[0].lower.z, 2.0f);
  EXPECT_EQ(boxes[0].upper.x, 3.0f);
  // A rotation by 30 degrees about z, in float64.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const auto obbs = read_obb_file(write_f64(dir, "o.npy", obb_row({7, 8, 9}, {c, s, 0, -s, c, 0, 0, 0, 1}, {1, 2, 3}), 15));
  ASSERT_EQ(obbs.size(), 1u);
  EXPECT_EQ(obbs[0].center.z, 9.0f);
  EXPECT_EQ(obbs[0].axis[1].x, static_cast<float>(-s));
  EXPECT_EQ(obbs[0].half_extent.y, 2.0f);
}

TEST(AnalyticFiles, Float32FilesReadTheSameAndEmptyFilesAreNoPrimitives) {
  TempDir dir;
  const auto spheres = read_sphere_file(write_f32(dir, "s.npy", {1, 2, 3, 0.5f}, 4));
  ASSERT_EQ(spheres.size(), 1u);
  EXPECT_EQ(spheres[0].radius, 0.5f);
  EXPECT_EQ(read_box_file(write_f32(dir, "b.npy", {0, 0, 0, 1, 1, 1}, 6)).size(), 1u);
  EXPECT_TRUE(read_sphere_file(write_f64(dir, "empty.npy", {}, 4)).empty());
  EXPECT_TRUE(read_obb_file(write_f32(dir, "empty_obbs.npy", {}, 15)).empty());
}

TEST(AnalyticFiles, DegenerateButValidPrimitivesAreKept) {
  TempDir dir;
  // A point sphere, a flat box, an oriented box flat on one axis: kept, as degenerate triangles are.
  EXPECT_EQ(read_sphere_file(write_f64(dir, "s.npy", {0, 0, 0, 0}, 4))[0].radius, 0.0f);
  EXPECT_EQ(read_box_file(write_f64(dir, "b.npy", {0, 1, 0, 1, 1, 1}, 6)).size(), 1u);
  EXPECT_EQ(read_obb_file(write_f64(dir, "o.npy", obb_row({0, 0, 0}, kAxes, {1, 0, 1}), 15)).size(), 1u);
  // Left-handed axes are a box all the same.
  EXPECT_EQ(read_obb_file(write_f64(dir, "l.npy", obb_row({0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, -1}, {1, 1, 1}), 15)).size(), 1u);
}

TEST(AnalyticFiles, MalformedSphereFilesNameTheFileAndTheRow) {
  TempDir dir;
  const auto bad = [&](const std::vector<double>& rows) { return write_f64(dir, "bad.npy", rows, 4); };
  const auto read = [](const std::string& p) { read_sphere_file(p); };
  expect_refused(read, bad({0, 0, 0, 1, 0, 0, kNaN, 1}), "row 1: column 2 (cz) is nan: every value must be finite");
  expect_refused(read, bad({0, 0, 0, kInf}), "row 0: column 3 (r) is inf");
  expect_refused(read, bad({0, 0, 0, 1, 0, 0, 0, 1, 1e39, 0, 0, 1}), "row 2: column 0 (cx) is 1e+39, beyond float32's range");
  expect_refused(read, bad({0, 0, 0, 1, 0, 0, 0, -1}), "row 1: radius is -1: it must be >= 0");
  expect_refused(read, bad({2e18, 0, 0, 1}), "row 0: the sphere reaches x = 2e+18");
  // The centre within range, the surface not.
  expect_refused(read, bad({0, 0, 0, 1, 0, 9e17, 0, 2e17}), "row 1: the sphere reaches y = 1.1e+18");
  expect_refused(read, write_f64(dir, "wide.npy", {0, 0, 0, 1, 1}, 5), "shape is (1, 5), expected (N, 4) (spheres: cx cy cz r)");
  expect_refused(read, dir.file("absent.npy"), "no such file");
}

TEST(AnalyticFiles, MalformedBoxFilesNameTheFileAndTheRow) {
  TempDir dir;
  const auto bad = [&](const std::vector<double>& rows) { return write_f64(dir, "bad.npy", rows, 6); };
  const auto read = [](const std::string& p) { read_box_file(p); };
  expect_refused(read, bad({0, 0, 0, 1, 1, 1, 0, 2, 0, 1, 1, 1}),
                 "row 1: min_y 2 > max_y 1: a box's min must not exceed its max");
  expect_refused(read, bad({0, 0, 0, 1, -kInf, 1}), "row 0: column 4 (max_y) is -inf");
  expect_refused(read, bad({0, 0, -1e19, 1, 1, 1}), "row 0: the box reaches z = -1e+19");
  expect_refused(read, write_f32(dir, "four.npy", {0, 0, 0, 1}, 4), "shape is (1, 4), expected (N, 6)");
}

TEST(AnalyticFiles, MalformedObbFilesNameTheFileAndTheRow) {
  TempDir dir;
  const auto bad = [&](const std::vector<double>& rows) { return write_f64(dir, "bad.npy", rows, 15); };
  const auto read = [](const std::string& p) { read_obb_file(p); };
  std::vector<double> two = obb_row({0, 0, 0}, kAxes, {1, 1, 1});
  const std::vector<double> second = obb_row({0, 0, 0}, kAxes, {1, 1, -0.5});
  two.insert(two.end(), second.begin(), second.end());
  expect_refused(read, bad(two), "row 1: half extent 2 is -0.5: it must be >= 0");
  expect_refused(read, bad(obb_row({0, 0, 0}, {1, 0, 0, 0, 1.01, 0, 0, 0, 1}, {1, 1, 1})),
                 "row 0: axis 1 (0, 1.01, 0) has length 1.00999999: the axes must be unit vectors (within 1e-05)");
  expect_refused(read, bad(obb_row({0, 0, 0}, {1, 0, 0, 0, 1, 0, 0.6, 0, 0.8}, {1, 1, 1})),
                 "row 0: axes 0 (1, 0, 0) and 2 (0.6, 0, 0.8) are not orthogonal: dot product 0.600000024");
  expect_refused(read, bad(obb_row({0, 0, 0}, {1, 0, 0, 1, 0, 0, 0, 0, 1}, {1, 1, 1})), "axes 0 (1, 0, 0) and 1 (1, 0, 0)");
  expect_refused(read, bad(obb_row({0, 0, 0}, {0, 0, 0, 0, 1, 0, 0, 0, 1}, {1, 1, 1})), "axis 0 (0, 0, 0) has length 0");
  expect_refused(read, bad(obb_row({0, 0, kNaN}, kAxes, {1, 1, 1})), "row 0: column 2 (cz) is nan");
  expect_refused(read, bad(obb_row({0, 0, 0}, kAxes, {1, 1, 1e39})), "row 0: column 14 (hz) is 1e+39");
  // Rotated by 45 degrees about z, half extents of 8e17 on axes 0 and 1 reach 1.13e18 in x.
  const double h = std::sqrt(0.5);
  expect_refused(read, bad(obb_row({0, 0, 0}, {h, h, 0, -h, h, 0, 0, 0, 1}, {8e17, 8e17, 1})), "the oriented box reaches x = ");
}

// kObbAxisTolerance is the stated limit: just within it is kept, just beyond refused.
TEST(AnalyticFiles, ObbAxesAreCheckedAgainstTheStatedToleranceAfterRoundingToFloat) {
  TempDir dir;
  const auto file = [&](double stretch, double tilt) {
    return write_f64(dir, "o.npy", obb_row({0, 0, 0}, {1 + stretch, 0, 0, tilt, 1, 0, 0, 0, 1}, {1, 1, 1}), 15);
  };
  EXPECT_EQ(read_obb_file(file(0.5 * kObbAxisTolerance, 0)).size(), 1u);
  EXPECT_EQ(read_obb_file(file(0, 0.5 * kObbAxisTolerance)).size(), 1u);
  expect_refused([](const std::string& p) { read_obb_file(p); }, file(2 * kObbAxisTolerance, 0), "axis 0");
  expect_refused([](const std::string& p) { read_obb_file(p); }, file(0, 2 * kObbAxisTolerance), "axes 0 (1, 0, 0) and 1");
  // A random rotation rounded to float32 is well within the tolerance.
  const double a = 0.3, b = 1.1;  // z then x rotation angles
  const std::vector<float> row{0, 0, 0,
                               float(std::cos(a)), float(std::sin(a)), 0,
                               float(-std::sin(a) * std::cos(b)), float(std::cos(a) * std::cos(b)), float(std::sin(b)),
                               float(std::sin(a) * std::sin(b)), float(-std::cos(a) * std::sin(b)), float(std::cos(b)),
                               1, 2, 3};
  EXPECT_EQ(read_obb_file(write_f32(dir, "rotated.npy", row, 15)).size(), 1u);
}

// What the procedural scenes hold passes the files' checks: saved as .npy
// and read back, every primitive comes back bit for bit.
TEST(AnalyticFiles, TheProceduralAnalyticScenesRoundTripThroughTheirFileFormats) {
  TempDir dir;
  for (const char* name : {"proc:analytic_mix", "proc:sphere_field", "proc:terrain_spheres_analytic_small"}) {
    const Scene scene = load_scene(name);
    std::vector<double> s, b, o;
    for (const Sphere& x : scene.spheres) s.insert(s.end(), {x.center.x, x.center.y, x.center.z, x.radius});
    for (const BBox& x : scene.boxes) b.insert(b.end(), {x.lower.x, x.lower.y, x.lower.z, x.upper.x, x.upper.y, x.upper.z});
    for (const OrientedBox& x : scene.obbs) {
      o.insert(o.end(), {x.center.x, x.center.y, x.center.z});
      for (const Vec3f& a : x.axis) o.insert(o.end(), {a.x, a.y, a.z});
      o.insert(o.end(), {x.half_extent.x, x.half_extent.y, x.half_extent.z});
    }
    const auto spheres = read_sphere_file(write_f64(dir, "s.npy", s, 4));
    const auto boxes = read_box_file(write_f64(dir, "b.npy", b, 6));
    const auto obbs = read_obb_file(write_f64(dir, "o.npy", o, 15));
    ASSERT_EQ(spheres.size(), scene.spheres.size()) << name;
    ASSERT_EQ(boxes.size(), scene.boxes.size()) << name;
    ASSERT_EQ(obbs.size(), scene.obbs.size()) << name;
    // Byte for byte; memcmp is not given the null data() of an empty vector.
    const auto same_bytes = [](const auto& a, const auto& b) {
      return a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
    };
    EXPECT_TRUE(same_bytes(spheres, scene.spheres)) << name;
    EXPECT_TRUE(same_bytes(boxes, scene.boxes)) << name;
    EXPECT_TRUE(same_bytes(obbs, scene.obbs)) << name;
  }
}

}  // namespace
}  // namespace raybench
