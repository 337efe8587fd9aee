// Bad input is reported at the boundary as one line naming the file and the
// problem; main() prints it and exits 2. Kernels never throw.
#pragma once

#include <stdexcept>
#include <string>

namespace raybench {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& where, const std::string& problem)
      : std::runtime_error(where.empty() ? problem : where + ": " + problem) {}
};

}  // namespace raybench
