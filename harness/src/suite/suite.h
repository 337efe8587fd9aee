// A suite manifest (TOML, e.g. meshes/default.toml): which scenes, ray sets,
// backends and settings a run uses. See docs/manifest.md.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rays/rayset.h"
#include "scene/tessellate.h"

namespace raybench {

struct SuiteScene {
  std::string name;  // used in results and on the command line
  std::string path;  // resolved against the manifest's folder; or "proc:<name>"; or empty
  // Analytic primitives (issue 31, scene/analytic_files.h): .npy files
  // resolved as `path` is, empty when not given. A scene has a path, some of
  // these, or both; their primitives follow the path's triangles in prim ids.
  std::string spheres;
  std::string boxes;
  std::string obbs;
  bool optional = false;  // skipped with a note when the file is absent
  std::optional<Camera> camera;
  std::optional<Vec3f> light;
  std::optional<InsideBall> inside;  // a closed mesh's inner ball: enables the must-hit ray sets
  std::vector<std::string> raysets;  // this scene's ray sets; empty: the suite's defaults
  // This scene's tessellation study (scene/tessellate.h): the resolutions of
  // its triangle stand-ins; unset: the suite's defaults; empty: none.
  std::optional<std::vector<Tessellation>> tessellate;
  // Every vertex v becomes float(scale * v + offset) after loading, as do
  // sphere and box centres and box corners; radii and half extents become
  // float(scale * r); OBB axes are kept. Camera, light and inside ball
  // (given for the untransformed scene) move with it.
  double scale = 1.0;
  std::array<double, 3> offset{0.0, 0.0, 0.0};

  bool available() const;  // every file it names exists (a proc: path always does)
  std::string missing() const;  // the first file it names that is absent, or ""
  // What it is made of, for listings and messages: the path and each
  // primitive file, e.g. "m.obj + spheres b.npy".
  std::string sources() const;
  bool transformed() const { return scale != 1.0 || offset != std::array<double, 3>{0.0, 0.0, 0.0}; }
};

// Loads the scene an entry names (its mesh or procedural scene, then its
// primitive files), transformed and named as the entry says. Throws
// InputError naming the file at fault (analytic_files.h), or the scene when
// it holds no primitive at all or the transform takes one beyond
// kMaxSceneCoordinate.
Scene load_suite_scene(const SuiteScene& entry);

struct SuiteSettings {
  std::size_t rays = 262144;
  std::vector<std::string> raysets{"primary", "diffuse", "shadow", "uniform"};
  std::vector<std::string> backends{"embree", "bvh2"};
  std::vector<int> threads{1};
  int repetitions = 5;
  int build_repetitions = 3;
  std::uint64_t seed = 1;
  double min_time = 0.05;  // seconds per repetition (Google Benchmark's min time)
  double warmup = 0.05;    // seconds of untimed warm-up per case
  // The timing reference (--reference, [defaults] reference): a backend of
  // the run that ratio_to_reference is relative to; "" for the default
  // (timing_reference in suite_run.h). reference_given says where it was
  // given, for messages ("--reference", or "FILE: 'defaults.reference'").
  std::string reference;
  std::string reference_given;
  // The resolutions every scene with analytic primitives is also traced at
  // as a triangle stand-in ([defaults] tessellate, --tessellate); empty: none.
  std::vector<Tessellation> tessellate;
  // The memory policy of every backend's acceleration structure ([defaults]
  // huge_pages = "on" | "off", --huge-pages): BackendConfig::huge_pages.
  bool huge_pages = true;
};

struct Suite {
  std::string path;
  SuiteSettings settings;
  std::vector<SuiteScene> scenes;

  // The scene called `name`, or nullptr.
  const SuiteScene* find(const std::string& name) const;
};

// Throws InputError naming the file and key on syntax errors, unknown keys,
// wrong types or duplicate scene names. A [[scene]] with a `sweep` table
// (scales, offsets) becomes one scene per combination: the stability sweep.
Suite load_suite(const std::string& path);

}  // namespace raybench
