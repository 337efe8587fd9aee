#include "scene/tessellate.h"

#include <array>
#include <charconv>

#include <fmt/format.h>

#include "io/error.h"
#include "raybench/geometry/uv_sphere.h"

namespace raybench {
namespace {

// A decimal number of digits only (no sign, no space), or -1.
int digits_value(std::string_view text) {
  if (text.empty() || text.size() > 9) return -1;
  for (const char c : text)
    if (c < '0' || c > '9') return -1;
  int value = 0;
  std::from_chars(text.data(), text.data() + text.size(), value);
  return value;
}

// The six faces of a box as corner quads, corner index = x | y << 1 | z << 2
// (bit set: the upper side along that axis), each quad counter-clockwise seen
// from outside, so (b - a) x (c - a) points out when the axes are right-handed.
constexpr std::array<std::array<int, 4>, 6> kBoxFaces{{
    {0, 4, 6, 2},  // -x
    {1, 3, 7, 5},  // +x
    {0, 1, 5, 4},  // -y
    {2, 6, 7, 3},  // +y
    {0, 2, 3, 1},  // -z
    {4, 5, 7, 6},  // +z
}};

// 12 triangles over 8 corners, each corner one float shared by every
// triangle that touches it.
void append_box(std::vector<Triangle>& out, const std::array<Vec3f, 8>& corner) {
  for (const auto& f : kBoxFaces) {
    out.push_back({corner[f[0]], corner[f[1]], corner[f[2]]});
    out.push_back({corner[f[0]], corner[f[2]], corner[f[3]]});
  }
}

std::array<Vec3f, 8> box_corners(const BBox& b) {
  std::array<Vec3f, 8> c;
  for (int i = 0; i < 8; ++i)
    c[i] = {(i & 1) ? b.upper.x : b.lower.x, (i & 2) ? b.upper.y : b.lower.y, (i & 4) ? b.upper.z : b.lower.z};
  return c;
}

// centre +- axis_0 h_0 +- axis_1 h_1 +- axis_2 h_2, summed in double and
// rounded once, so each corner is the float nearest the exact corner (up to
// the double rounding of the sum).
std::array<Vec3f, 8> obb_corners(const OrientedBox& o) {
  std::array<Vec3f, 8> c;
  for (int i = 0; i < 8; ++i) {
    for (int a = 0; a < 3; ++a) {
      double v = o.center[a];
      for (int k = 0; k < 3; ++k)
        v += ((i >> k) & 1 ? 1.0 : -1.0) * static_cast<double>(o.axis[k][a]) * static_cast<double>(o.half_extent[k]);
      c[i][a] = static_cast<float>(v);
    }
  }
  return c;
}

std::size_t sphere_triangles(const Tessellation& t) {
  return static_cast<std::size_t>(t.segments) * static_cast<std::size_t>(2 * t.rings - 2);
}

}  // namespace

std::string Tessellation::name() const { return "uv" + spec(); }

std::string Tessellation::spec() const { return fmt::format("{}x{}", segments, rings); }

Tessellation parse_tessellation(std::string_view text, const std::string& where) {
  const std::string rule = fmt::format(
      "must be SxR: S segments (longitude, {} to {}) by R rings (latitude, {} to {}), e.g. 16x8; got '{}'",
      kMinSegments, kMaxTessellation, kMinRings, kMaxTessellation, text);
  const std::size_t x = text.find('x');
  if (x == std::string_view::npos) throw InputError(where, rule);
  const Tessellation t{digits_value(text.substr(0, x)), digits_value(text.substr(x + 1))};
  if (t.segments < kMinSegments || t.segments > kMaxTessellation || t.rings < kMinRings || t.rings > kMaxTessellation)
    throw InputError(where, rule);
  return t;
}

std::vector<Tessellation> parse_tessellations(const std::vector<std::string>& texts, const std::string& where) {
  std::vector<Tessellation> out;
  for (const std::string& text : texts) {
    const Tessellation t = parse_tessellation(text, where);
    for (const Tessellation& seen : out)
      if (seen == t) throw InputError(where, fmt::format("{} is given twice", text));
    out.push_back(t);
  }
  return out;
}

std::size_t stand_in_triangle_count(const Scene& scene, const Tessellation& t) {
  return scene.triangles.size() + scene.spheres.size() * sphere_triangles(t) +
         12 * (scene.boxes.size() + scene.obbs.size());
}

void check_stand_in_size(const Scene& scene, const Tessellation& t) {
  const std::size_t n = stand_in_triangle_count(scene, t);
  if (n > kMaxStandInTriangles)
    throw InputError(fmt::format("scene '{}'", scene.name),
                     fmt::format("its {} stand-in would have {} triangles, more than prim ids reach ({}): "
                                 "choose a coarser tessellation",
                                 t.name(), n, kMaxStandInTriangles));
}

StandIn tessellate(const Scene& scene, const Tessellation& t) {
  check_stand_in_size(scene, t);
  StandIn s;
  s.tessellation = t;
  s.kept_triangles = scene.triangles.size();
  s.scene.name = scene.name + "@" + t.name();
  s.scene.source = fmt::format("{} tessellated {}", scene.source, t.name());
  s.scene.skipped_points = scene.skipped_points;
  s.scene.skipped_lines = scene.skipped_lines;
  std::vector<Triangle>& out = s.scene.triangles;
  const std::size_t count = stand_in_triangle_count(scene, t);
  out.reserve(count);
  s.prim_of.reserve(count);
  out.insert(out.end(), scene.triangles.begin(), scene.triangles.end());
  for (std::size_t i = 0; i < scene.triangles.size(); ++i) s.prim_of.push_back(static_cast<std::int32_t>(i));
  const PrimitiveSpans prims = scene.primitives();
  // After each primitive's triangles are appended: as many copies of its id.
  const auto stands_for = [&](std::size_t id) { s.prim_of.resize(out.size(), static_cast<std::int32_t>(id)); };
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    append_uv_sphere(out, scene.spheres[i].center, scene.spheres[i].radius, t.rings, t.segments);
    stands_for(prims.first_sphere() + i);
  }
  for (std::size_t i = 0; i < scene.boxes.size(); ++i) {
    append_box(out, box_corners(scene.boxes[i]));
    stands_for(prims.first_box() + i);
  }
  for (std::size_t i = 0; i < scene.obbs.size(); ++i) {
    append_box(out, obb_corners(scene.obbs[i]));
    stands_for(prims.first_obb() + i);
  }
  return s;
}

std::vector<Hit> analytic_hits(std::span<const Hit> hits, const StandIn& stand_in) {
  std::vector<Hit> out(hits.begin(), hits.end());
  for (Hit& h : out) {
    if (!h.hit()) continue;
    const auto i = static_cast<std::size_t>(h.prim);
    h.prim = stand_in.prim_of[i];
    if (i >= stand_in.kept_triangles) h.u = h.v = 0.0f;
  }
  return out;
}

}  // namespace raybench
