// Fuzz target: the CSV reader (read_csv_rows, harness/src/io/csv.h) on any
// bytes, as any CSV and as a results CSV (read_results_csv, which requires
// the schema's columns). InputError is the reader's answer to bad input;
// anything else (a crash, a sanitizer report, another exception, a hang) is
// a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_file.h"
#include "io/csv.h"
#include "io/error.h"
#include "results/results_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static raybench::fuzz::FuzzFile file("results.csv");
  const std::string& path = file.write(data, size);
  try {
    raybench::read_csv_rows(path, {"scene"});
  } catch (const raybench::InputError&) {
  }
  try {
    raybench::read_results_csv(path);
  } catch (const raybench::InputError&) {
  }
  return 0;
}
