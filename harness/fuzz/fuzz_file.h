// What the fuzz targets share: the readers under test take a path (they
// check the file at the boundary, then open it), so each input is written to
// one temporary file, rewritten every iteration, and read from there. The
// file lives in a folder of its own, removed when the fuzzer exits.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace raybench::fuzz {

class FuzzFile {
 public:
  // `name` is the file's name inside the folder (e.g. "suite.toml").
  explicit FuzzFile(const std::string& name) {
    folder_ = std::filesystem::temp_directory_path() / ("raybench_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
    path_ = (folder_ / name).string();
  }
  ~FuzzFile() {
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
  }
  FuzzFile(const FuzzFile&) = delete;
  FuzzFile& operator=(const FuzzFile&) = delete;

  // Replaces the file's contents with the fuzzer's input; returns its path.
  const std::string& write(const std::uint8_t* data, std::size_t size) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path_;
  }

  const std::string& path() const { return path_; }
  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_;
  std::string path_;
};

}  // namespace raybench::fuzz
