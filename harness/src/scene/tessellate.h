// Triangle stand-ins for analytic scenes (issue 31's tessellation study): the
// same scene with every sphere a UV sphere of S segments by R rings
// (raybench/geometry/uv_sphere.h) and every box and oriented box 12
// triangles, so that what tessellation costs and gets wrong can be measured
// on the analytic scene's own rays against its own referee.
//
// Order of a stand-in's triangles: the scene's triangles first (their ids
// unchanged), then each sphere's, each box's and each oriented box's, in the
// scene's order: the order of global prim ids (raybench/prim/primitives.h).
// `prim_of` maps each stand-in triangle back to the id it stands for, so a
// hit on the stand-in is judged as a hit on that analytic primitive.
//
// Guarantee: UV spheres are inscribed (every vertex on the sphere, up to
// float rounding), so a stand-in sphere lies inside its sphere: its
// silhouette shrinks and its near side moves away from the ray origin.
// Boxes and oriented boxes are the exact box surface up to the rounding of
// their corners. Shared edges are bit-identical (each corner or grid vertex
// is computed once), so a stand-in is as watertight as its triangle test.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "raybench/math/ray.h"
#include "scene/scene.h"

namespace raybench {

// A UV sphere's resolution: S segments (longitude slices) by R rings
// (latitude bands), written "SxR" (e.g. "16x8"); a stand-in is called
// "uv<S>x<R>" in the representation column of results and accuracy CSVs.
struct Tessellation {
  int segments = 0;
  int rings = 0;

  // "uv16x8": the representation, and the suffix of a stand-in's scene name.
  std::string name() const;
  // "16x8", as parse_tessellation reads it.
  std::string spec() const;
  bool operator==(const Tessellation&) const = default;
};

// Sanity bounds, not capabilities: append_uv_sphere needs segments >= 3 and
// rings >= 2; 4096 (33 million triangles per sphere at 4096x4096) is far past
// any resolution that tells a sphere from its stand-in in float.
inline constexpr int kMinSegments = 3, kMinRings = 2, kMaxTessellation = 4096;

// "SxR" with S in [kMinSegments, kMaxTessellation] and R in [kMinRings,
// kMaxTessellation], decimal digits and a lower-case x only. Throws
// InputError(where, ...) naming the text and what is accepted.
Tessellation parse_tessellation(std::string_view text, const std::string& where);

// Every text of a list (a manifest's `tessellate` array, --tessellate's
// values); a resolution given twice is refused (its stand-ins would share a
// name). An empty list is no stand-in.
std::vector<Tessellation> parse_tessellations(const std::vector<std::string>& texts, const std::string& where);

// The triangles of `scene`'s stand-in at `t`: its triangles, plus
// t.segments * (2 * t.rings - 2) per sphere and 12 per box and oriented box.
std::size_t stand_in_triangle_count(const Scene& scene, const Tessellation& t);

// The largest stand-in: prim ids are int32 (kNoHit = -1 marks a miss).
inline constexpr std::size_t kMaxStandInTriangles = 0x7fffffff;

// Throws InputError naming the scene and the resolution when its stand-in
// would have more than kMaxStandInTriangles triangles; a run checks this
// before its first scene is measured.
void check_stand_in_size(const Scene& scene, const Tessellation& t);

struct StandIn {
  Scene scene;                        // triangles only; named "<scene>@uv<S>x<R>"
  std::vector<std::int32_t> prim_of;  // per triangle of `scene`: the global prim id it stands for
  std::size_t kept_triangles = 0;     // the first ones: the analytic scene's own triangles, same ids
  Tessellation tessellation;
};

// The stand-in of `scene` at `t` (see the order above); check_stand_in_size
// first. A scene without analytic primitives stands for itself.
StandIn tessellate(const Scene& scene, const Tessellation& t);

// Hits on a stand-in as hits on the scene it stands for: each hit's prim
// becomes prim_of[prim]; t is kept; u and v are kept for a triangle of the
// scene and become 0 for an analytic primitive (what analytic hits report,
// raybench/prim/analytic_hit.h). Misses stay misses. Hits must be valid
// (prim within prim_of, measure/answer_check.h).
std::vector<Hit> analytic_hits(std::span<const Hit> hits, const StandIn& stand_in);

}  // namespace raybench
