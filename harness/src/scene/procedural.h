// Deterministic scenes made in code, named "proc:<name>" wherever a mesh path
// is accepted. They need no files, so the default suite and the tests always
// have a large scene and a closed mesh to work with.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace raybench {

inline constexpr std::string_view kProceduralPrefix = "proc:";

struct ProceduralSceneInfo {
  std::string name;
  std::string description;
};

// The procedural scenes that exist, for --help and error messages.
std::vector<ProceduralSceneInfo> procedural_scenes();

// Builds "proc:<name>"; throws InputError for an unknown name.
Scene make_procedural_scene(const std::string& spec);

}  // namespace raybench
