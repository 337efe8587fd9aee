// A scene as every backend receives it: one flat array of triangles and,
// when its manifest names them (issue 31), analytic spheres, boxes and
// oriented boxes.
//
// Order (documented in docs/scenes.md): the file's node hierarchy is
// walked depth first, parent before children, children in file order; at each
// node its meshes in the node's order; in each mesh its faces in file order,
// polygons fan-triangulated by assimp. Node transforms are applied. Degenerate
// triangles are kept. A triangle's index in this array is its `prim` id.
// Analytic primitives follow the triangles in the one numbering of
// raybench/prim/primitives.h: triangles, spheres, boxes, oriented boxes,
// each in file order (PrimitiveSpans::kind and ::local map an id back).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "raybench/math/bbox.h"
#include "raybench/prim/primitives.h"
#include "raybench/prim/triangle.h"

namespace raybench {

struct Scene {
  std::string name;    // short name used in results (file stem, or the manifest's name)
  std::string source;  // the path or procedural spec it was made from
  std::vector<Triangle> triangles;
  std::vector<Sphere> spheres;      // analytic, after the triangles in prim ids
  std::vector<BBox> boxes;          // analytic axis-aligned boxes, after the spheres
  std::vector<OrientedBox> obbs;    // analytic oriented boxes, last
  std::size_t skipped_points = 0;  // point primitives in the file, not traced
  std::size_t skipped_lines = 0;   // line primitives in the file, not traced

  PrimitiveSpans primitives() const { return {triangles, spheres, boxes, obbs}; }
  std::size_t primitive_count() const { return primitives().size(); }
  bool has_analytic() const { return primitives().has_analytic(); }

  BBox bounds() const;  // of every primitive
  // A hash of all primitive data: stored ray sets are keyed by it, so a changed
  // mesh never reuses rays made for its old version.
  std::uint64_t content_hash() const;
};

// "7808 triangles", or with analytic primitives "2 triangles, 120 spheres,
// 3 boxes, 1 oriented box" (the types it has, in prim-id order): what
// progress lines and `raybench scenes` say a scene holds.
std::string describe_primitives(const Scene& scene);

// Loads a mesh file with assimp, or builds a procedural scene when `spec`
// starts with "proc:" (see procedural.h). Throws InputError naming the file
// on a missing, unreadable or malformed file, one without triangles, or one
// that check_scene_coordinates refuses. assimp runs in a child process with
// a deadline (RAYBENCH_LOAD_TIMEOUT, see scene_assimp.cpp): a crash or hang
// of it is such an error too.
Scene load_scene(const std::string& spec);

// The largest coordinate magnitude a scene's vertices may have. Box surface
// areas, which every BVH builder and the collapse compute in float, must stay
// finite: a box within +-B has extents up to 2B and surface area up to
// 2 * 3 * (2B)^2 = 24 B^2, finite while B <= sqrt(FLT_MAX / 24) = 3.7e18.
// 1e18 keeps the scene box's area (2.4e37) a factor 14 below FLT_MAX.
// Coordinates of +-1e19 overflowed the wide BVH's collapse (issue 28).
inline constexpr float kMaxSceneCoordinate = 1e18f;

// Throws InputError(where, ...) when a vertex of `scene` is not finite or
// has a coordinate beyond +-kMaxSceneCoordinate, or an analytic primitive's
// box (raybench/prim/primitives.h) does; `where` names the file or
// the manifest's scene. load_scene runs it on what the file holds, and
// load_suite_scene (suite.h) again after the manifest's scale and offset,
// on the vertices as they will be traced.
void check_scene_coordinates(const Scene& scene, const std::string& where);

}  // namespace raybench
