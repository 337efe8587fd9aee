// Reading and writing NumPy .npy files (io/npy.h): the header parsed as
// numpy writes it and nothing else, every mismatch of magic, dtype, shape,
// order or body length an InputError naming the file; files are written
// atomically (io/atomic_file.h).
#include "io/npy.h"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>

#include <fmt/format.h>

#include "io/atomic_file.h"
#include "io/error.h"
#include "io/input_file.h"

namespace raybench {
namespace {

constexpr char kMagic[] = "\x93NUMPY";

struct NpyHeader {
  std::string descr;
  bool fortran_order = false;
  std::vector<std::size_t> shape;
  std::size_t data_offset = 0;
};

// The dimensions inside a shape's parentheses: a Python tuple of
// non-negative integers as numpy writes it ("16, 8", "16,", "16, 8, " or
// ""), nothing else. Anything else -- a sign, a float, an expression, an
// empty element -- is refused rather than half-read (std::stoull read
// "-16" as 16).
std::vector<std::size_t> parse_shape(const std::string& dims, const std::string& path) {
  const auto bad = [&](const std::string& why) {
    return InputError(path, fmt::format("malformed .npy header: 'shape' ({}) is not a tuple of non-negative integers: {}",
                                        dims, why));
  };
  std::vector<std::size_t> shape;
  std::size_t i = 0;
  const auto skip_space = [&] {
    while (i < dims.size() && (dims[i] == ' ' || dims[i] == '\t')) ++i;
  };
  skip_space();
  while (i < dims.size()) {
    const std::size_t start = i;
    while (i < dims.size() && dims[i] >= '0' && dims[i] <= '9') ++i;
    if (i == start) {
      if (dims[i] == '-') throw bad(fmt::format("dimension {} is negative", shape.size()));
      throw bad(fmt::format("dimension {} is not an integer", shape.size()));
    }
    std::uint64_t d = 0;
    if (const auto r = std::from_chars(dims.data() + start, dims.data() + i, d); r.ec != std::errc())
      throw InputError(path, fmt::format(".npy shape dimension {} ({}) is too large", shape.size(),
                                         dims.substr(start, i - start)));
    shape.push_back(d);
    skip_space();
    if (i == dims.size()) {
      if (shape.size() != 1) break;  // (16,) needs its comma: (16) is not a tuple
      throw bad("a 1-element tuple needs a trailing comma");
    }
    if (dims[i] != ',') throw bad(fmt::format("unexpected '{}' after dimension {}", dims[i], shape.size() - 1));
    ++i;
    skip_space();
  }
  return shape;
}

// Parses the header dictionary, e.g.
// {'descr': '<f4', 'fortran_order': False, 'shape': (1024, 8), }
NpyHeader read_header(std::istream& in, const std::string& path) {
  char magic[6];
  if (!in.read(magic, 6) || std::memcmp(magic, kMagic, 6) != 0) throw InputError(path, "not a .npy file (bad magic)");
  unsigned char version[2];
  if (!in.read(reinterpret_cast<char*>(version), 2)) throw InputError(path, "truncated .npy header");
  std::size_t header_len = 0, prefix = 0;
  if (version[0] == 1) {
    unsigned char len[2];
    if (!in.read(reinterpret_cast<char*>(len), 2)) throw InputError(path, "truncated .npy header");
    header_len = len[0] | (len[1] << 8);
    prefix = 10;
  } else if (version[0] == 2 || version[0] == 3) {
    unsigned char len[4];
    if (!in.read(reinterpret_cast<char*>(len), 4)) throw InputError(path, "truncated .npy header");
    header_len = len[0] | (len[1] << 8) | (len[2] << 16) | (static_cast<std::size_t>(len[3]) << 24);
    prefix = 12;
  } else {
    throw InputError(path, fmt::format("unsupported .npy format version {}.{}", version[0], version[1]));
  }
  if (header_len > (1u << 20)) throw InputError(path, "implausible .npy header length");
  std::string dict(header_len, '\0');
  if (!in.read(dict.data(), static_cast<std::streamsize>(header_len))) throw InputError(path, "truncated .npy header");

  NpyHeader h;
  h.data_offset = prefix + header_len;
  std::smatch m;
  static const std::regex descr_re(R"('descr'\s*:\s*'([^']*)')");
  static const std::regex order_re(R"('fortran_order'\s*:\s*(True|False))");
  static const std::regex shape_re(R"('shape'\s*:\s*\(([^)]*)\))");
  if (!std::regex_search(dict, m, descr_re)) throw InputError(path, "malformed .npy header: no 'descr'");
  h.descr = m[1];
  if (!std::regex_search(dict, m, order_re)) throw InputError(path, "malformed .npy header: no 'fortran_order'");
  h.fortran_order = m[1] == "True";
  if (!std::regex_search(dict, m, shape_re)) throw InputError(path, "malformed .npy header: no 'shape'");
  h.shape = parse_shape(m[1], path);
  return h;
}

std::string shape_string(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

// Reads a 2-D array of `columns` columns and element type `descr`.
std::vector<char> read_matrix(const std::string& path, const char* descr, std::size_t element_size,
                              std::size_t columns, const std::string& what, std::size_t& rows) {
  check_input_file(path, ".npy file");
  std::error_code ec;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot be opened for reading");
  const NpyHeader h = read_header(in, path);
  if (h.descr != descr)
    throw InputError(path, fmt::format("dtype is '{}', expected '{}' ({})", h.descr, descr, what));
  if (h.fortran_order) throw InputError(path, "array is in Fortran order; save it C-contiguous (numpy.ascontiguousarray)");
  if (h.shape.size() != 2 || h.shape[1] != columns)
    throw InputError(path, fmt::format("shape is {}, expected (N, {}) ({})", shape_string(h.shape), columns, what));
  rows = h.shape[0];
  const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, "cannot read its size: " + ec.message());
  // The body's size is checked against the file before anything is
  // allocated, without overflow: a header may promise any number of rows.
  const std::uintmax_t row_bytes = columns * element_size;  // columns >= 1: 8 for rays, at most 1024
  if (rows > (std::numeric_limits<std::uintmax_t>::max() - h.data_offset) / row_bytes ||
      h.data_offset + rows * row_bytes > file_size)
    throw InputError(path, fmt::format("truncated: the header promises {} rows of {} bytes, more than the file's {} "
                                       "bytes hold", rows, row_bytes, file_size));
  const std::uintmax_t expected = h.data_offset + rows * row_bytes;
  if (file_size > expected)
    throw InputError(path, fmt::format("{} unexpected bytes after the {} rows the header declares",
                                       file_size - expected, rows));
  std::vector<char> body(rows * columns * element_size);
  if (!in.read(body.data(), static_cast<std::streamsize>(body.size()))) throw InputError(path, "read failed");
  return body;
}

void write_matrix(const std::string& path, const char* descr, const void* data, std::size_t bytes,
                  std::size_t rows, std::size_t columns) {
  std::string dict = fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': ({}, {}), }}", descr, rows, columns);
  // Pad with spaces so that magic + version + length + dict + '\n' is a multiple of 64.
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict.push_back('\n');
  write_file_atomically(
      path,
      [&](std::ostream& out) {
        out.write(kMagic, 6);
        const unsigned char version[2] = {1, 0};
        out.write(reinterpret_cast<const char*>(version), 2);
        const unsigned char len[2] = {static_cast<unsigned char>(dict.size() & 0xff),
                                      static_cast<unsigned char>(dict.size() >> 8)};
        out.write(reinterpret_cast<const char*>(len), 2);
        out.write(dict.data(), static_cast<std::streamsize>(dict.size()));
        out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
      },
      std::ios::out | std::ios::binary);
}

}  // namespace

std::vector<Ray> read_ray_file(const std::string& path) {
  std::size_t rows = 0;
  const std::vector<char> body = read_matrix(path, "<f4", sizeof(float), 8, "float32 rays: ox oy oz tnear dx dy dz tfar", rows);
  std::vector<Ray> rays(rows);
  if (!body.empty()) std::memcpy(rays.data(), body.data(), body.size());  // never memcpy from an empty vector's null data()
  return rays;
}

void write_ray_file(const std::string& path, std::span<const Ray> rays) {
  write_matrix(path, "<f4", rays.data(), rays.size_bytes(), rays.size(), 8);
}

void write_npy_f64(const std::string& path, std::span<const double> data, std::size_t rows, std::size_t columns) {
  write_matrix(path, "<f8", data.data(), data.size_bytes(), rows, columns);
}

std::vector<double> read_npy_f64(const std::string& path, std::size_t& rows, std::size_t& columns) {
  check_input_file(path, ".npy file");
  std::ifstream in(path, std::ios::binary);
  const NpyHeader h = read_header(in, path);
  if (h.shape.size() != 2) throw InputError(path, "expected a 2-D array");
  columns = h.shape[1];
  if (columns == 0 || columns > 1024)
    throw InputError(path, fmt::format("shape is {}: expected 1 to 1024 columns", shape_string(h.shape)));
  const std::vector<char> body = read_matrix(path, "<f8", sizeof(double), columns, "float64", rows);
  std::vector<double> out(rows * columns);
  if (!body.empty()) std::memcpy(out.data(), body.data(), body.size());
  return out;
}

std::vector<double> read_npy_real(const std::string& path, std::size_t columns, const std::string& what,
                                  std::size_t& rows) {
  check_input_file(path, ".npy file");
  std::string descr;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "cannot be opened for reading");
    descr = read_header(in, path).descr;
  }
  if (descr == "<f4") {
    const std::vector<char> body = read_matrix(path, "<f4", sizeof(float), columns, what, rows);
    std::vector<float> values(rows * columns);
    if (!body.empty()) std::memcpy(values.data(), body.data(), body.size());
    return std::vector<double>(values.begin(), values.end());
  }
  if (descr == "<f8") {
    const std::vector<char> body = read_matrix(path, "<f8", sizeof(double), columns, what, rows);
    std::vector<double> out(rows * columns);
    if (!body.empty()) std::memcpy(out.data(), body.data(), body.size());
    return out;
  }
  throw InputError(path, fmt::format("dtype is '{}', expected float32 or float64 ('<f4' or '<f8', little-endian) ({})",
                                     descr, what));
}

}  // namespace raybench
