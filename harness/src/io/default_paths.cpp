#include "io/default_paths.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "build_info.h"

namespace raybench {
namespace fs = std::filesystem;
namespace {

// `path` lies inside `dir` (both made absolute and normal, symlinks resolved
// where they exist).
bool is_inside(const fs::path& path, const fs::path& dir) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(path, ec);
  if (ec) return false;
  const fs::path d = fs::weakly_canonical(dir, ec);
  if (ec || d.empty()) return false;
  auto pi = p.begin();
  for (auto di = d.begin(); di != d.end(); ++di, ++pi) {
    if (di->empty()) continue;  // a trailing separator
    if (pi == p.end() || *pi != *di) return false;
  }
  return true;
}

std::string env_or_empty(const char* name) {
  const char* value = std::getenv(name);
  return value ? value : "";
}

}  // namespace

DefaultPaths default_paths_for(const DefaultPathsInputs& in) {
  DefaultPaths d;
  std::error_code ec;
  const fs::path exe_dir = in.executable.empty() ? fs::path(".") : fs::path(in.executable).parent_path();
  const std::string share = (exe_dir.parent_path() / "share" / "raybench").lexically_normal().string();
  const bool beside_share = fs::is_directory(share, ec);  // installed, even into a folder of the build tree
  d.build_tree = !beside_share && !in.executable.empty() && !in.binary_dir.empty() &&
                 is_inside(in.executable, in.binary_dir) && fs::exists(fs::path(in.source_dir) / "CMakeLists.txt", ec);
  if (d.build_tree) {
    const std::string src = in.source_dir;
    d.suite = src + "/meshes/default.toml";
    d.out_csv = src + "/results/latest.csv";
    d.rays_dir = src + "/results/rays";
    d.kernels_csv = src + "/results/kernels.csv";
    d.kernels_json = src + "/results/kernels.json";
    d.accuracy_kernels_csv = src + "/results/accuracy-kernels.csv";
    d.gate_config = src + "/results/gate.toml";
    return d;
  }
  // Installed: P/bin/raybench reads P/share/raybench.
  d.suite = share + "/suites/procedural.toml";
  d.gate_config = share + "/gate.toml";
  d.out_csv = "raybench-results.csv";
  d.kernels_csv = "raybench-kernels.csv";
  d.kernels_json = "raybench-kernels.json";
  d.accuracy_kernels_csv = "raybench-accuracy-kernels.csv";
  if (!in.xdg_cache_home.empty() && fs::path(in.xdg_cache_home).is_absolute())  // the XDG rule: relative is ignored
    d.rays_dir = in.xdg_cache_home + "/raybench/rays";
  else if (!in.home.empty())
    d.rays_dir = in.home + "/.cache/raybench/rays";
  else
    d.rays_dir = "raybench-rays";
  return d;
}

const DefaultPaths& default_paths() {
  static const DefaultPaths paths = [] {
    DefaultPathsInputs in;
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) in.executable = exe.string();
    in.source_dir = RAYBENCH_SOURCE_DIR;
    in.binary_dir = RAYBENCH_BINARY_DIR;
    in.xdg_cache_home = env_or_empty("XDG_CACHE_HOME");
    in.home = env_or_empty("HOME");
    return default_paths_for(in);
  }();
  return paths;
}

}  // namespace raybench
