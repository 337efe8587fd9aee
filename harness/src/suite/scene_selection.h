// Which scenes a run traces, and the name each goes by. A `--scene` argument
// is a suite scene's name, a mesh path or proc:<name> (named after its file
// stem or procedural name), or NAME=PATH: a mesh path (or proc:) named on the
// command line. A scene's name keys its result rows and its stored ray files,
// so the scenes of one run never share one: two arguments giving the same
// name are refused, both named, before anything is loaded.
#pragma once

#include <string>
#include <vector>

#include "suite/suite.h"

namespace raybench {

struct SceneChoice {
  std::string arg;                    // as given: "spider", "/m/spider.fbx", "big=/m/spider.fbx"
  std::string name;                   // the scene's name in results and ray files
  const SuiteScene* entry = nullptr;  // the suite's scene; null for a path or proc:
  std::string path;                   // mesh path or proc:<name> (empty for a suite scene)
};

// Reads one argument: a suite scene's name first, then an existing file's
// path (a file name may hold '='), then NAME=PATH, then a path or proc:.
// Throws InputError("--scene", ...) when the name breaks scene_name_problem.
SceneChoice choose_scene(const std::string& arg, const Suite& suite);

// Every argument, in order; throws InputError naming both arguments when two
// give the same scene name.
std::vector<SceneChoice> choose_scenes(const std::vector<std::string>& args, const Suite& suite);

// Loads the chosen scene under its chosen name.
Scene load_chosen_scene(const SceneChoice& choice);

}  // namespace raybench
