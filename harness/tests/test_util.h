// Helpers shared by the harness tests: temporary files and test meshes.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "io/error.h"

#include <gtest/gtest.h>
#include <unistd.h>

namespace raybench::testing {

// A fresh directory under the system temp folder, removed at scope end.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("raybench_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& contents) const {
    std::ofstream(file(name), std::ios::binary) << contents;
    return file(name);
  }

 private:
  static int& counter() {
    static int c = 0;
    return c;
  }
  std::filesystem::path path_;
};

// The message of the InputError that f() throws, or "" when it throws none.
template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

inline std::string shared_mesh(const std::string& name) { return std::string(RAYBENCH_SHARED_MESHES) + "/" + name; }
inline std::string assimp_model(const std::string& name) { return std::string(RAYBENCH_ASSIMP_MODELS) + "/" + name; }
inline bool exists(const std::string& path) { return std::filesystem::exists(path); }

}  // namespace raybench::testing
