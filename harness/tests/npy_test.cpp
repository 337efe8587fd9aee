// Specification of the .npy reader and writer (harness/src/io/npy.h).
#include "io/npy.h"

#include <cstring>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <sys/stat.h>

#include "io/error.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::TempDir;

std::string npy_bytes(const std::string& dict, std::size_t body_bytes, int major = 1) {
  std::string header = dict;
  const std::size_t prefix = major == 1 ? 10 : 12;
  header.append((64 - (prefix + header.size() + 1) % 64) % 64, ' ');
  header += '\n';
  std::string out = "\x93NUMPY";
  out += static_cast<char>(major);
  out += '\0';
  const std::size_t n = header.size();
  out += static_cast<char>(n & 0xff);
  out += static_cast<char>((n >> 8) & 0xff);
  if (major != 1) out += std::string(2, '\0');
  return out + header + std::string(body_bytes, '\0');
}

std::string error_of(const std::string& path) {
  return testing::input_error_of([&] { read_ray_file(path); });
}

TEST(Npy, RayFileRoundTripsBitExactly) {
  TempDir dir;
  std::vector<Ray> rays(3);
  rays[0] = Ray{{1, 2, 3}, 0.5f, {0, 0, -1}, 100.0f};
  rays[1] = Ray{{-0.0f, 1e-30f, 1e30f}, 0.0f, {1, 0, 0}, std::numeric_limits<float>::infinity()};
  rays[2].org.x = std::numeric_limits<float>::quiet_NaN();
  write_ray_file(dir.file("r.npy"), rays);
  const std::vector<Ray> back = read_ray_file(dir.file("r.npy"));
  ASSERT_EQ(back.size(), rays.size());
  EXPECT_EQ(std::memcmp(back.data(), rays.data(), rays.size() * sizeof(Ray)), 0);
}

TEST(Npy, HeaderIsAlignedTo64BytesAsNumpyWritesIt) {
  TempDir dir;
  write_ray_file(dir.file("r.npy"), std::vector<Ray>(2));
  EXPECT_EQ(std::filesystem::file_size(dir.file("r.npy")), 128u + 2 * 32);
}

// 0 rows read as no rays; in the sanitizer build (.ci/run) also without
// passing an empty vector's null data() to memcpy (issue 28).
TEST(Npy, EmptyRayFileRoundTrips) {
  TempDir dir;
  write_ray_file(dir.file("r.npy"), {});
  EXPECT_TRUE(read_ray_file(dir.file("r.npy")).empty());
}

TEST(Npy, ReadsVersion2Headers) {
  TempDir dir;
  const auto path = dir.write("v2.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 8), }", 64, 2));
  EXPECT_EQ(read_ray_file(path).size(), 2u);
}

TEST(Npy, RejectsWhatIsNotARayFileNamingTheFileAndProblem) {
  TempDir dir;
  const struct {
    const char* name;
    std::string bytes;
    const char* problem;
  } cases[] = {
      {"magic.npy", "not numpy at all", "bad magic"},
      {"f8.npy", npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 8), }", 128), "dtype is '<f8'"},
      {"big_endian.npy", npy_bytes("{'descr': '>f4', 'fortran_order': False, 'shape': (2, 8), }", 64), "dtype is '>f4'"},
      {"shape7.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 7), }", 56), "shape is (2, 7)"},
      {"shape1d.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (16,), }", 64), "shape is (16,)"},
      {"fortran.npy", npy_bytes("{'descr': '<f4', 'fortran_order': True, 'shape': (2, 8), }", 64), "Fortran order"},
      {"truncated.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (4, 8), }", 100), "truncated"},
      {"trailing.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (1, 8), }", 40), "unexpected bytes"},
      {"header.npy", std::string("\x93NUMPY\x01\x00\xff\x00", 10) + "{'descr'", "truncated .npy header"},
      {"nodescr.npy", npy_bytes("{'fortran_order': False, 'shape': (1, 8), }", 32), "no 'descr'"},
  };
  for (const auto& c : cases) {
    const std::string path = dir.write(c.name, c.bytes);
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << c.name << ": " << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << c.name << ": " << error;
  }
  EXPECT_NE(error_of(dir.file("absent.npy")).find("no such file"), std::string::npos);
}

// Issue 28: a shape of (-16, 8) was read as (16, 8) (the regex skipped the
// sign); anything but a tuple of non-negative integers is refused.
TEST(Npy, AShapeIsATupleOfNonNegativeIntegersNothingElse) {
  TempDir dir;
  const struct {
    const char* shape;
    const char* problem;
  } cases[] = {
      {"(-16, 8)", "dimension 0 is negative"},
      {"(16, -8)", "dimension 1 is negative"},
      {"(+16, 8)", "dimension 0 is not an integer"},
      {"(16.0, 8)", "unexpected '.' after dimension 0"},
      {"(16, 8 8)", "unexpected '8' after dimension 1"},
      {"(16,, 8)", "dimension 1 is not an integer"},
      {"(0x10, 8)", "unexpected 'x' after dimension 0"},
      {"(16)", "a 1-element tuple needs a trailing comma"},
      {"(2*8, 8)", "unexpected '*' after dimension 0"},
  };
  for (const auto& c : cases) {
    const std::string path = dir.write(
        "shape.npy", npy_bytes(fmt::format("{{'descr': '<f4', 'fortran_order': False, 'shape': {}, }}", c.shape), 512));
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path + ": malformed .npy header: 'shape'"), std::string::npos) << c.shape << ": " << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << c.shape << ": " << error;
  }
  // Spellings numpy writes, or a Python tuple may take, are read.
  for (const char* shape : {"(16, 8)", "(16,8)", "(16, 8,)", "( 16 , 8 )"}) {
    const std::string path = dir.write(
        "ok.npy", npy_bytes(fmt::format("{{'descr': '<f4', 'fortran_order': False, 'shape': {}, }}", shape), 16 * 32));
    EXPECT_EQ(read_ray_file(path).size(), 16u) << shape;
  }
}

// Issue 28: overflowing dimensions said "stoull" or "cannot create
// std::vector larger than max_size()". The size is checked against the file
// before anything is allocated.
TEST(Npy, HugeDimensionsAreRefusedBeforeAllocatingWithAMessageThatSaysWhy) {
  TempDir dir;
  const struct {
    const char* shape;
    const char* problem;
  } cases[] = {
      {"(99999999999999999999999, 8)", "dimension 0 (99999999999999999999999) is too large"},
      {"(18446744073709551615, 8)", "more than the file's"},           // rows x 32 bytes overflows
      {"(576460752303423488, 8)", "more than the file's"},             // 2^59 rows: exactly 2^64 bytes
      {"(4611686018427387904, 8)", "more than the file's"},            // 2^62 rows
      {"(1000000, 8)", "the header promises 1000000 rows of 32 bytes"},  // plausible, but the file is short
  };
  for (const auto& c : cases) {
    const std::string path = dir.write(
        "huge.npy", npy_bytes(fmt::format("{{'descr': '<f4', 'fortran_order': False, 'shape': {}, }}", c.shape), 64));
    const std::string error = error_of(path);
    EXPECT_NE(error.find(path), std::string::npos) << c.shape << ": " << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << c.shape << ": " << error;
  }
  // The float64 reader takes its column count from the header: bounded too.
  const std::string wide = dir.write(
      "wide.npy", npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 4611686018427387904), }", 64));
  std::size_t rows = 0, columns = 0;
  EXPECT_NE(testing::input_error_of([&] { read_npy_f64(wide, rows, columns); }).find("expected 1 to 1024 columns"),
            std::string::npos);
}

// Found by harness/fuzz/npy_fuzz (issue 28), the exact input: a dimension
// beyond 64 bits after a stray parenthesis escaped from std::stoull as
// std::out_of_range and ended the process. Both readers refuse it as bad input.
TEST(Npy, TheFuzzersOverlongDimensionIsBadInputNotACrash) {
  TempDir dir;
  const std::string input = std::string("\x93NUMPY\x01\x00\x76\x00", 10) +
                            "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::string(31, ' ') +
                            "(99999999999999999999, 8) \n" + std::string("\x00\x00\x40\x00\x00\x00\xf0\x3f", 8) +
                            std::string(8, '\0');
  ASSERT_EQ(input.size(), 135u);
  const std::string path = dir.write("fuzzed.npy", input);
  const std::string error = error_of(path);
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("'shape'"), std::string::npos) << error;
  std::size_t rows = 0, columns = 0;
  EXPECT_NE(testing::input_error_of([&] { read_npy_f64(path, rows, columns); }).find("'shape'"), std::string::npos);
}

// Issue 28: a FIFO given as a ray file blocked forever in open().
TEST(Npy, ARayFileThatIsNotARegularFileIsRefusedWithoutOpeningIt) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("fifo.npy").c_str(), 0600), 0);
  EXPECT_NE(error_of(dir.file("fifo.npy")).find("is a FIFO"), std::string::npos);
  std::filesystem::create_directories(dir.file("folder.npy"));
  EXPECT_NE(error_of(dir.file("folder.npy")).find("is a directory"), std::string::npos);
  std::size_t rows = 0, columns = 0;
  EXPECT_NE(testing::input_error_of([&] { read_npy_f64(dir.file("fifo.npy"), rows, columns); }).find("is a FIFO"),
            std::string::npos);
}

TEST(Npy, Float64MatricesRoundTrip) {
  TempDir dir;
  const std::vector<double> data{1, 2, 3, 4, 5, 6, std::numeric_limits<double>::infinity(), -1};
  write_npy_f64(dir.file("h.npy"), data, 2, 4);
  std::size_t rows = 0, columns = 0;
  EXPECT_EQ(read_npy_f64(dir.file("h.npy"), rows, columns), data);
  EXPECT_EQ(rows, 2u);
  EXPECT_EQ(columns, 4u);
}

TEST(Npy, EmptyFloat64MatrixRoundTrips) {
  TempDir dir;
  write_npy_f64(dir.file("h.npy"), {}, 0, 4);
  std::size_t rows = 1, columns = 0;
  EXPECT_TRUE(read_npy_f64(dir.file("h.npy"), rows, columns).empty());
  EXPECT_EQ(rows, 0u);
  EXPECT_EQ(columns, 4u);
}

// Scene primitive files (scene/analytic_files.h) come as float32 or float64.
TEST(Npy, RealMatricesReadAsDoublesFromFloat32AndFloat64) {
  TempDir dir;
  const float f[6] = {1.5f, -2.0f, 0x1.000002p+0f, 3.0f, 1e30f, -0.0f};
  const std::string f4 = dir.write("f4.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", 0) +
                                                 std::string(reinterpret_cast<const char*>(f), sizeof f));
  std::size_t rows = 0;
  const std::vector<double> a = read_npy_real(f4, 3, "test", rows);
  EXPECT_EQ(rows, 2u);
  EXPECT_EQ(a, std::vector<double>(f, f + 6));  // float32 widens exactly
  const std::vector<double> d{1e300, 2, 3, 4, 5, 6};
  write_npy_f64(dir.file("f8.npy"), d, 3, 2);
  EXPECT_EQ(read_npy_real(dir.file("f8.npy"), 2, "test", rows), d);
  EXPECT_EQ(rows, 3u);
  write_npy_f64(dir.file("empty.npy"), {}, 0, 4);
  EXPECT_TRUE(read_npy_real(dir.file("empty.npy"), 4, "test", rows).empty());
  EXPECT_EQ(rows, 0u);
}

TEST(Npy, RealMatricesOfAnotherDtypeOrShapeAreRefusedNamingTheFileAndWhatItShouldHold) {
  TempDir dir;
  const struct {
    const char* dict;
    std::size_t body;
    const char* problem;
  } cases[] = {
      {"{'descr': '<i8', 'fortran_order': False, 'shape': (1, 4), }", 32, "dtype is '<i8', expected float32 or float64"},
      {"{'descr': '>f8', 'fortran_order': False, 'shape': (1, 4), }", 32, "dtype is '>f8'"},
      {"{'descr': '<f2', 'fortran_order': False, 'shape': (1, 4), }", 8, "dtype is '<f2'"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }", 32, "shape is (4,), expected (N, 4) (spheres: cx cy cz r)"},
      {"{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", 24, "shape is (2, 3), expected (N, 4)"},
      {"{'descr': '<f4', 'fortran_order': False, 'shape': (1, 4, 1), }", 16, "shape is (1, 4, 1)"},
      {"{'descr': '<f4', 'fortran_order': True, 'shape': (2, 4), }", 32, "Fortran order"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (2, 4), }", 40, "truncated"},
  };
  for (const auto& c : cases) {
    const std::string path = dir.write("bad.npy", npy_bytes(c.dict, c.body));
    std::size_t rows = 0;
    const std::string error = testing::input_error_of([&] { read_npy_real(path, 4, "spheres: cx cy cz r", rows); });
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find(c.problem), std::string::npos) << c.dict << ": " << error;
  }
}

TEST(Npy, AFailedWriteLeavesNoFileBehind) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("occupied.npy"));  // a directory where the file should go
  EXPECT_THROW(write_ray_file(dir.file("occupied.npy"), std::vector<Ray>(1)), InputError);
  for (const auto& e : std::filesystem::directory_iterator(dir.file("")))
    EXPECT_EQ(e.path().filename(), "occupied.npy") << "left behind: " << e.path();
}

}  // namespace
}  // namespace raybench
