// Fuzz target: the .npy reader (harness/src/io/npy.h) on any bytes, read as a
// ray file, as a float64 matrix, and as a scene's sphere, box and oriented box
// file (scene/analytic_files.h). InputError is the reader's answer to bad
// input; anything else (a crash, a sanitizer report, another exception, a
// hang) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_file.h"
#include "io/error.h"
#include "io/npy.h"
#include "scene/analytic_files.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static raybench::fuzz::FuzzFile file("input.npy");
  const std::string& path = file.write(data, size);
  try {
    raybench::read_ray_file(path);
  } catch (const raybench::InputError&) {
  }
  try {
    std::size_t rows = 0, columns = 0;
    raybench::read_npy_f64(path, rows, columns);
  } catch (const raybench::InputError&) {
  }
  try {
    raybench::read_sphere_file(path);
  } catch (const raybench::InputError&) {
  }
  try {
    raybench::read_box_file(path);
  } catch (const raybench::InputError&) {
  }
  try {
    raybench::read_obb_file(path);
  } catch (const raybench::InputError&) {
  }
  return 0;
}
