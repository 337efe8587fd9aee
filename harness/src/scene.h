// A scene as every backend receives it: one flat array of triangles.
//
// Order (documented in README.md, "Scenes"): the file's node hierarchy is
// walked depth first, parent before children, children in file order; at each
// node its meshes in the node's order; in each mesh its faces in file order,
// polygons fan-triangulated by assimp. Node transforms are applied. Degenerate
// triangles are kept. A triangle's index in this array is its `prim` id.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "raybench/math/bbox.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct Scene {
  std::string name;    // short name used in results (file stem, or the manifest's name)
  std::string source;  // the path or procedural spec it was made from
  std::vector<Triangle> triangles;
  std::size_t skipped_points = 0;  // point primitives in the file, not traced
  std::size_t skipped_lines = 0;   // line primitives in the file, not traced

  BBox bounds() const;
  // A hash of the triangle data: stored ray sets are keyed by it, so a changed
  // mesh never reuses rays made for its old version.
  std::uint64_t content_hash() const;
};

// Loads a mesh file with assimp, or builds a procedural scene when `spec`
// starts with "proc:" (see procedural.h). Throws InputError naming the file
// on a missing, unreadable or malformed file, or one without triangles.
Scene load_scene(const std::string& spec);

}  // namespace raybench
