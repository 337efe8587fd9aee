#include "suite/scene_selection.h"

#include <filesystem>

#include <fmt/format.h>

#include "io/error.h"
#include "scene/procedural.h"
#include "scene/scene.h"
#include "suite/settings_rules.h"

namespace raybench {

SceneChoice choose_scene(const std::string& arg, const Suite& suite) {
  SceneChoice c;
  c.arg = arg;
  if ((c.entry = suite.find(arg))) {
    c.name = c.entry->name;
    return c;
  }
  std::error_code ec;
  const std::size_t eq = arg.find('=');
  if (eq != std::string::npos && eq > 0 && !std::filesystem::exists(arg, ec)) {
    c.name = arg.substr(0, eq);
    c.path = arg.substr(eq + 1);
    if (const std::string problem = scene_name_problem(c.name); !problem.empty())
      throw InputError("--scene", fmt::format("{} is read as NAME=PATH (no file has that name), but the name '{}' is "
                                              "refused: {}", printable(arg), printable(c.name), problem));
    if (c.path.empty()) throw InputError("--scene", fmt::format("{}: NAME=PATH names no path", printable(arg)));
    return c;
  }
  c.path = arg;
  if (arg.rfind(kProceduralPrefix, 0) == 0) {
    c.name = arg.substr(kProceduralPrefix.size());
    return c;
  }
  // A path's scene is named after its file's stem (scene.h). Refused, not
  // rewritten: a rewritten name could collide with another scene's.
  c.name = std::filesystem::path(arg).stem().string();
  if (const std::string problem = scene_name_problem(c.name); !problem.empty())
    throw InputError("--scene", fmt::format("{}: its file name gives the scene name '{}', but {}; name the scene in a "
                                            "suite manifest ([[scene]] name = \"...\", path = \"...\") and run it with "
                                            "--suite, or on the command line: --scene NAME=PATH",
                                            printable(arg), printable(c.name), problem));
  return c;
}

std::vector<SceneChoice> choose_scenes(const std::vector<std::string>& args, const Suite& suite) {
  std::vector<SceneChoice> chosen;
  for (const std::string& arg : args) {
    SceneChoice c = choose_scene(arg, suite);
    for (const SceneChoice& earlier : chosen) {
      if (earlier.name != c.name) continue;
      const std::string& path = !c.path.empty() ? c.path : earlier.path;
      throw InputError("--scene", fmt::format("{} and {} both name the scene '{}' (their rows and ray files would "
                                              "collide){}",
                                              printable(earlier.arg), printable(arg), printable(c.name),
                                              path.empty() ? ": give each scene once"
                                                           : fmt::format(": name one of them, e.g. --scene {}_2={}",
                                                                         printable(c.name), printable(path))));
    }
    chosen.push_back(std::move(c));
  }
  return chosen;
}

Scene load_chosen_scene(const SceneChoice& choice) {
  if (choice.entry) return load_suite_scene(*choice.entry);
  Scene scene = load_scene(choice.path);
  scene.name = choice.name;
  return scene;
}

}  // namespace raybench
