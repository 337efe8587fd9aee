// Fuzz target: the suite manifest reader (load_suite, harness/src/suite/suite.h)
// on any bytes as a TOML manifest. It only parses: no scene is loaded.
// InputError is the reader's answer to bad input; anything else (a crash, a
// sanitizer report, another exception, a hang) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_file.h"
#include "io/error.h"
#include "suite/suite.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static raybench::fuzz::FuzzFile file("suite.toml");
  try {
    raybench::load_suite(file.write(data, size));
  } catch (const raybench::InputError&) {
  }
  return 0;
}
