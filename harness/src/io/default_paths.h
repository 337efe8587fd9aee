// Where raybench's default files are. A binary running from the build tree it
// was built in (and whose source tree still exists) keeps the source tree's
// files: meshes/default.toml, results/latest.csv, results/rays,
// results/gate.toml. Any other binary, in particular one installed with
// `cmake --install build --prefix P`, depends on no path of the machine it
// was built on: it writes to the current directory, stores rays in the
// user's cache and reads its suite and gate config from P/share/raybench,
// found relative to the executable (P/bin/raybench). docs/install.md.
#pragma once

#include <string>

namespace raybench {

struct DefaultPaths {
  bool build_tree = false;      // running from the build tree (the rest follow from it)
  std::string suite;            // --suite of run, rays, trace, scenes
  std::string out_csv;          // run --out
  std::string rays_dir;         // --rays-dir of run and accuracy-kernels
  std::string kernels_csv;      // kernels --out
  std::string kernels_json;     // kernels --json
  std::string accuracy_kernels_csv;  // accuracy-kernels --out
  std::string gate_config;      // gate --config
};

// The inputs of the decision, apart so that tests can state it for any case.
struct DefaultPathsInputs {
  std::string executable;   // this process's executable, absolute ("" when unknown)
  std::string source_dir;   // the source tree it was configured from
  std::string binary_dir;   // the build tree it was built in
  std::string xdg_cache_home;  // $XDG_CACHE_HOME ("" when unset)
  std::string home;            // $HOME ("" when unset)
};

// Build tree: `executable` lies inside `binary_dir`, `source_dir` still holds
// a CMakeLists.txt, and there is no <executable's folder>/../share/raybench
// (an install into a folder of the build tree is still an install).
// Otherwise installed: suite and gate config from
// <executable's folder>/../share/raybench (suites/procedural.toml, gate.toml),
// out ./raybench-results.csv (kernels: ./raybench-kernels.csv and .json,
// accuracy-kernels: ./raybench-accuracy-kernels.csv), rays in
// $XDG_CACHE_HOME/raybench/rays, else $HOME/.cache/raybench/rays, else
// ./raybench-rays.
DefaultPaths default_paths_for(const DefaultPathsInputs& in);

// This process's defaults, worked out once from /proc/self/exe, the paths
// CMake recorded (build_info.h) and the environment.
const DefaultPaths& default_paths();

}  // namespace raybench
