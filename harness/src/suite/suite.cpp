#include "suite/suite.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "backends/backend.h"
#include "io/error.h"
#include "io/input_file.h"
#include "scene/analytic_files.h"
#include "scene/procedural.h"
#include "suite/settings_rules.h"

namespace raybench {
namespace {

class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw InputError(path_, fmt::format("'{}': {}", key, problem));
  }

  void check_keys(const toml::table& table, const std::string& where, std::set<std::string> allowed) const {
    for (const auto& [key, value] : table) {
      if (!allowed.count(std::string(key.str())))
        fail(where.empty() ? std::string(key.str()) : where + "." + std::string(key.str()), "unknown key");
    }
  }

  template <typename T>
  T get(const toml::table& table, const std::string& where, const char* key, T fallback) const {
    const toml::node* node = table.get(key);
    if (!node) return fallback;
    if constexpr (std::is_same_v<T, std::string>) {
      if (auto v = node->value<std::string>()) return *v;
      fail(where + key, "expected a string");
    } else if constexpr (std::is_same_v<T, bool>) {
      if (auto v = node->value<bool>()) return *v;
      fail(where + key, "expected true or false");
    } else {
      // Integers go through settings_rules.h (setting()), never a bare cast.
      static_assert(std::is_floating_point_v<T>, "an integer setting needs its rule");
      if (auto v = node->value<double>()) return static_cast<T>(*v);
      fail(where + key, "expected a number");
    }
  }

  // A numeric setting for a rule of settings_rules.h, named by file and key.
  GivenValue given(const toml::node& node, const std::string& key) const {
    std::ostringstream text;
    node.visit([&](const auto& n) { text << n; });
    std::optional<std::int64_t> integer;
    std::optional<double> number;
    if (const auto* i = node.as_integer()) {
      integer = i->get();
      number = static_cast<double>(*integer);
    } else if (const auto* f = node.as_floating_point()) {
      number = f->get();
    }
    return GivenValue::from_manifest(path_, key, text.str(), integer, number);
  }

  // Applies `rule` to table[key] when present; otherwise keeps `value`.
  template <typename T, typename Rule>
  void setting(const toml::table& table, const std::string& where, const char* key, Rule rule, T& value) const {
    if (const toml::node* node = table.get(key)) value = rule(given(*node, where + key));
  }

  std::vector<std::string> strings(const toml::table& table, const std::string& where, const char* key,
                                   std::vector<std::string> fallback) const {
    const toml::node* node = table.get(key);
    if (!node) return fallback;
    const toml::array* array = node->as_array();
    if (!array) fail(where + key, "expected an array of strings");
    std::vector<std::string> out;
    for (const toml::node& e : *array) {
      auto v = e.value<std::string>();
      if (!v) fail(where + key, "expected an array of strings");
      out.push_back(*v);
    }
    return out;
  }

  // `tessellate = ["8x4", "32x16"]` (scene/tessellate.h) when the table has
  // it; `where` is "defaults." or "scene[i].".
  std::optional<std::vector<Tessellation>> tessellations(const toml::table& table, const std::string& where) const {
    if (!table.get("tessellate")) return std::nullopt;
    return parse_tessellations(strings(table, where, "tessellate", {}), fmt::format("{}: '{}tessellate'", path_, where));
  }

  // A point (camera position and target, light, ball centre): finite, and
  // within the coordinates every backend can trace (kLargestTraceableCoordinate,
  // Embree's range); rays from or towards a point beyond it are all misses.
  Vec3f point(const toml::node& node, const std::string& key) const {
    const Vec3f v = vec3(node, key);
    check_point(v, key, "");
    return v;
  }

  void check_point(const Vec3f& v, const std::string& key, const char* context) const {
    for (int i = 0; i < 3; ++i)
      if (!(std::fabs(v[i]) <= kLargestTraceableCoordinate))
        fail(key, fmt::format("{}expected [x, y, z] finite coordinates within +-{:g}, got [{}, {}, {}]", context,
                              kLargestTraceableCoordinate, v.x, v.y, v.z));
  }

  // [x, y, z]: numbers that are finite as float.
  Vec3f vec3(const toml::node& node, const std::string& key) const {
    const toml::array* array = node.as_array();
    if (!array || array->size() != 3) fail(key, "expected [x, y, z]");
    Vec3f v;
    for (int i = 0; i < 3; ++i) {
      auto c = (*array)[static_cast<std::size_t>(i)].value<double>();
      if (!c) fail(key, "expected [x, y, z] numbers");
      v[i] = static_cast<float>(*c);
      if (!std::isfinite(v[i])) fail(key, fmt::format("expected [x, y, z] finite numbers, got {}", *c));
    }
    return v;
  }

  std::array<double, 3> vec3d(const toml::node& node, const std::string& key) const {
    const toml::array* array = node.as_array();
    if (!array || array->size() != 3) fail(key, "expected [x, y, z]");
    std::array<double, 3> v{};
    for (std::size_t i = 0; i < 3; ++i) {
      auto c = (*array)[i].value<double>();
      if (!c || !std::isfinite(*c)) fail(key, "expected [x, y, z] finite numbers");
      v[i] = *c;
    }
    return v;
  }

  Camera camera(const toml::node& node, const std::string& key) const {
    const toml::table* t = node.as_table();
    if (!t) fail(key, "expected a table { position = [..], look_at = [..], up = [..], fov = deg }");
    check_keys(*t, key, {"position", "look_at", "up", "fov"});
    Camera c;
    if (!t->get("position") || !t->get("look_at")) fail(key, "needs position and look_at");
    c.position = point(*t->get("position"), key + ".position");
    c.look_at = point(*t->get("look_at"), key + ".look_at");
    if (t->get("up")) c.up = vec3(*t->get("up"), key + ".up");
    c.fov_degrees = get<float>(*t, key + ".", "fov", c.fov_degrees);
    if (!(c.fov_degrees > 0.0f && c.fov_degrees < 180.0f)) fail(key + ".fov", "must be in (0, 180) degrees");
    check_view(c, key, "");
    return c;
  }

  // A camera defines a view only when it looks somewhere (look_at is not its
  // position) and `up` is not along the view direction: otherwise the basis
  // of camera_ray (rayset.cpp, in double) has a zero vector and every ray is NaN.
  void check_view(const Camera& c, const std::string& key, const char* context) const {
    const double f[3] = {double(c.look_at.x) - c.position.x, double(c.look_at.y) - c.position.y,
                         double(c.look_at.z) - c.position.z};
    const double u[3] = {c.up.x, c.up.y, c.up.z};
    const double f_len = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    const double u_len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (f_len == 0.0)
      fail(key + ".look_at", fmt::format("{}is the camera's position [{}, {}, {}]: the camera looks nowhere", context,
                                         c.position.x, c.position.y, c.position.z));
    if (u_len == 0.0) fail(key + ".up", "must not be [0, 0, 0]");
    const double cross[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2], f[0] * u[1] - f[1] * u[0]};
    const double sine = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]) / (f_len * u_len);
    // sin 1e-6: up within a microradian of the view direction.
    if (!(sine > 1e-6))
      fail(key + ".up", fmt::format("{}[{}, {}, {}] is parallel to the view direction (look_at - position): "
                                    "up must point across it", context, c.up.x, c.up.y, c.up.z));
  }

  // What scale and offset made of the camera, light and ball: still a view,
  // still within range (a large scale can push them out; float rounding at a
  // large offset can merge a camera with its target).
  void check_moved(const SuiteScene& scene, const std::string& key) const {
    if (!scene.transformed()) return;
    const std::string context = fmt::format("at scale {:g} and offset [{:g}, {:g}, {:g}] (scene '{}'): ", scene.scale,
                                            scene.offset[0], scene.offset[1], scene.offset[2], scene.name);
    if (scene.camera) {
      check_point(scene.camera->position, key + ".camera.position", context.c_str());
      check_point(scene.camera->look_at, key + ".camera.look_at", context.c_str());
      check_view(*scene.camera, key + ".camera", context.c_str());
    }
    if (scene.light) check_point(*scene.light, key + ".light", context.c_str());
    if (scene.inside) {
      check_point(scene.inside->center, key + ".inside.center", context.c_str());
      if (!(scene.inside->radius > 0.0f && std::isfinite(scene.inside->radius)))
        fail(key + ".inside.radius", context + "must be a finite number > 0");
    }
  }

 private:
  std::string path_;
};

}  // namespace

namespace {

Vec3f moved(Vec3f v, double scale, const std::array<double, 3>& offset) {
  return {static_cast<float>(scale * v.x + offset[0]), static_cast<float>(scale * v.y + offset[1]),
          static_cast<float>(scale * v.z + offset[2])};
}

// Applies the transform to what the manifest gave for the untransformed scene.
void move_entry(SuiteScene& scene) {
  if (scene.camera) {
    scene.camera->position = moved(scene.camera->position, scene.scale, scene.offset);
    scene.camera->look_at = moved(scene.camera->look_at, scene.scale, scene.offset);
  }
  if (scene.light) scene.light = moved(*scene.light, scene.scale, scene.offset);
  if (scene.inside) {
    scene.inside->center = moved(scene.inside->center, scene.scale, scene.offset);
    scene.inside->radius = static_cast<float>(scene.inside->radius * scene.scale);
  }
}

}  // namespace

Scene load_suite_scene(const SuiteScene& entry) {
  Scene scene;
  if (!entry.path.empty()) scene = load_scene(entry.path);
  if (!entry.spheres.empty()) scene.spheres = read_sphere_file(entry.spheres);
  if (!entry.boxes.empty()) scene.boxes = read_box_file(entry.boxes);
  if (!entry.obbs.empty()) scene.obbs = read_obb_file(entry.obbs);
  scene.name = entry.name;
  scene.source = entry.sources();
  // A mesh without triangles is refused by load_scene; files of 0 rows are
  // valid arrays, but a scene of nothing has nothing to trace.
  if (scene.primitive_count() == 0)
    throw InputError("scene '" + entry.name + "' (" + entry.sources() + ")",
                     "holds no primitives (its files have 0 rows): nothing to trace");
  if (entry.transformed()) {
    for (Triangle& t : scene.triangles) {
      t.v0 = moved(t.v0, entry.scale, entry.offset);
      t.v1 = moved(t.v1, entry.scale, entry.offset);
      t.v2 = moved(t.v2, entry.scale, entry.offset);
    }
    const double s = entry.scale;
    for (Sphere& b : scene.spheres) {
      b.center = moved(b.center, s, entry.offset);
      b.radius = static_cast<float>(s * b.radius);
    }
    // scale > 0 and rounding is monotonic: lower <= upper stays true.
    for (BBox& b : scene.boxes) {
      b.lower = moved(b.lower, s, entry.offset);
      b.upper = moved(b.upper, s, entry.offset);
    }
    for (OrientedBox& o : scene.obbs) {
      o.center = moved(o.center, s, entry.offset);
      o.half_extent = {static_cast<float>(s * o.half_extent.x), static_cast<float>(s * o.half_extent.y),
                       static_cast<float>(s * o.half_extent.z)};
    }
    check_scene_coordinates(scene, "scene '" + entry.name + "' (" + entry.sources() +
                                       " with the manifest's scale and offset)");
  }
  return scene;
}

std::string SuiteScene::missing() const {
  for (const std::string* file : {&path, &spheres, &boxes, &obbs}) {
    if (file->empty() || file->rfind(kProceduralPrefix, 0) == 0) continue;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(*file, ec)) return *file;
  }
  return "";
}

bool SuiteScene::available() const { return missing().empty(); }

std::string SuiteScene::sources() const {
  std::string out = path;
  for (const auto& [key, file] : {std::pair{"spheres", &spheres}, {"boxes", &boxes}, {"obbs", &obbs}})
    if (!file->empty()) out += fmt::format("{}{} {}", out.empty() ? "" : " + ", key, *file);
  return out;
}

const SuiteScene* Suite::find(const std::string& name) const {
  for (const SuiteScene& s : scenes)
    if (s.name == name) return &s;
  return nullptr;
}

Suite load_suite(const std::string& path) {
  namespace fs = std::filesystem;
  check_input_file(path, "suite manifest");
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw InputError(path, fmt::format("line {}: {}", e.source().begin.line, e.description()));
  }
  const Reader r(path);
  r.check_keys(root, "", {"defaults", "scene"});
  Suite suite;
  suite.path = path;
  SuiteSettings& s = suite.settings;
  if (const toml::node* d = root.get("defaults")) {
    const toml::table* t = d->as_table();
    if (!t) r.fail("defaults", "expected a table");
    r.check_keys(*t, "defaults", {"rays", "raysets", "backends", "threads", "repetitions", "build_repetitions", "seed",
                                  "min_time", "warmup", "reference", "tessellate", "huge_pages"});
    r.setting(*t, "defaults.", "rays", rays_setting, s.rays);
    s.raysets = r.strings(*t, "defaults.", "raysets", s.raysets);
    for (const std::string& k : s.raysets) {
      try {
        parse_rayset_kind(k);
      } catch (const InputError& e) {
        r.fail("defaults.raysets", e.what());
      }
    }
    s.backends = r.strings(*t, "defaults.", "backends", s.backends);
    try {
      s.backends = expand_backend_patterns(s.backends);  // "bvh2:*": every triangle test (backend.h)
    } catch (const InputError& e) {
      r.fail("defaults.backends", e.what());
    }
    if (const toml::node* th = t->get("threads")) {
      const toml::array* a = th->as_array();
      if (!a || a->empty()) r.fail("defaults.threads", "expected an array of thread counts, e.g. [1, 2]");
      s.threads.clear();
      for (const toml::node& e : *a) s.threads.push_back(threads_setting(r.given(e, "defaults.threads")));
    }
    r.setting(*t, "defaults.", "repetitions", repetitions_setting, s.repetitions);
    r.setting(*t, "defaults.", "build_repetitions", build_repetitions_setting, s.build_repetitions);
    r.setting(*t, "defaults.", "seed", seed_setting, s.seed);
    r.setting(*t, "defaults.", "min_time", min_time_setting, s.min_time);
    r.setting(*t, "defaults.", "warmup", warmup_setting, s.warmup);
    if (t->get("reference")) {
      const GivenValue given = GivenValue::from_manifest(
          path, "defaults.reference", r.get<std::string>(*t, "defaults.", "reference", ""), std::nullopt, std::nullopt);
      s.reference = reference_setting(given);
      s.reference_given = given.where;
    }
    s.tessellate = r.tessellations(*t, "defaults.").value_or(s.tessellate);
    if (const toml::node* h = t->get("huge_pages")) {
      if (!h->is_string()) r.fail("defaults.huge_pages", "must be \"on\" or \"off\"");
      s.huge_pages = huge_pages_setting(
          GivenValue::from_manifest(path, "defaults.huge_pages", *h->value<std::string>(), std::nullopt, std::nullopt));
    }
  }
  const fs::path base = fs::path(path).parent_path();
  if (const toml::node* scenes = root.get("scene")) {
    const toml::array* a = scenes->as_array();
    if (!a) r.fail("scene", "expected [[scene]] tables");
    std::size_t index = 0;
    for (const toml::node& e : *a) {
      const std::string key = fmt::format("scene[{}]", index++);
      const toml::table* t = e.as_table();
      if (!t) r.fail(key, "expected a table");
      r.check_keys(*t, key, {"name", "path", "spheres", "boxes", "obbs", "optional", "camera", "light", "inside",
                             "raysets", "note", "scale", "offset", "sweep",
                             "tessellate"});
      SuiteScene scene;
      scene.name = r.get<std::string>(*t, key + ".", "name", "");
      scene.path = r.get<std::string>(*t, key + ".", "path", "");
      scene.spheres = r.get<std::string>(*t, key + ".", "spheres", "");
      scene.boxes = r.get<std::string>(*t, key + ".", "boxes", "");
      scene.obbs = r.get<std::string>(*t, key + ".", "obbs", "");
      for (const char* k : {"path", "spheres", "boxes", "obbs"})
        if (t->get(k) && r.get<std::string>(*t, key + ".", k, "").empty()) r.fail(key + "." + k, "is empty");
      if (scene.name.empty() || (scene.path.empty() && scene.spheres.empty() && scene.boxes.empty() && scene.obbs.empty()))
        r.fail(key, "needs a name and a path (a mesh or proc:<name>), or analytic primitives (spheres, boxes, obbs "
                    "= \"FILE.npy\"), or both");
      if (const std::string problem = scene_name_problem(scene.name); !problem.empty()) r.fail(key + ".name", problem);
      if (suite.find(scene.name) && !t->get("sweep")) r.fail(key + ".name", "duplicate scene name '" + scene.name + "'");
      if (!scene.path.empty() && scene.path.rfind(kProceduralPrefix, 0) != 0 && fs::path(scene.path).is_relative())
        scene.path = (base / scene.path).lexically_normal().string();
      for (const auto& [k, file] : {std::pair{"spheres", &scene.spheres}, {"boxes", &scene.boxes}, {"obbs", &scene.obbs}}) {
        if (file->rfind(kProceduralPrefix, 0) == 0)
          r.fail(key + "." + k, fmt::format("'{}' is a procedural scene's name; {} names a .npy file (a procedural "
                                            "scene goes in path)", *file, k));
        if (!file->empty() && fs::path(*file).is_relative()) *file = (base / *file).lexically_normal().string();
      }
      scene.optional = r.get<bool>(*t, key + ".", "optional", false);
      if (const toml::node* c = t->get("camera")) scene.camera = r.camera(*c, key + ".camera");
      if (const toml::node* l = t->get("light")) scene.light = r.point(*l, key + ".light");
      if (const toml::node* in = t->get("inside")) {
        const toml::table* b = in->as_table();
        if (!b || !b->get("center")) r.fail(key + ".inside", "expected { center = [x, y, z], radius = r }");
        r.check_keys(*b, key + ".inside", {"center", "radius"});
        scene.inside = InsideBall{r.point(*b->get("center"), key + ".inside.center"),
                                  r.get<float>(*b, key + ".inside.", "radius", 0.0f)};
        if (!(scene.inside->radius > 0.0f && std::isfinite(scene.inside->radius)))
          r.fail(key + ".inside.radius", "must be a finite number > 0");
      }
      scene.raysets = r.strings(*t, key + ".", "raysets", {});
      for (const std::string& k : scene.raysets) {
        try {
          parse_rayset_kind(k);
        } catch (const InputError& e) {
          r.fail(key + ".raysets", e.what());
        }
      }
      scene.tessellate = r.tessellations(*t, key + ".");
      scene.scale = r.get<double>(*t, key + ".", "scale", 1.0);
      if (!(scene.scale > 0.0 && std::isfinite(scene.scale))) r.fail(key + ".scale", "must be a positive number");
      if (const toml::node* o = t->get("offset")) scene.offset = r.vec3d(*o, key + ".offset");
      const toml::node* sweep = t->get("sweep");
      if (!sweep) {
        move_entry(scene);
        r.check_moved(scene, key);
        suite.scenes.push_back(std::move(scene));
        continue;
      }
      // The stability sweep: one scene per (scale, offset), skipping those
      // where float spacing at the offset exceeds max_quantisation * scale
      // (the mesh would no longer be the same shape, nor the ball inside it).
      const toml::table* w = sweep->as_table();
      if (!w) r.fail(key + ".sweep", "expected { scales = [..], offsets = [[x, y, z], ..] }");
      r.check_keys(*w, key + ".sweep", {"scales", "offsets", "max_quantisation"});
      const toml::array* scales = w->get("scales") ? w->get("scales")->as_array() : nullptr;
      if (!scales || scales->empty()) r.fail(key + ".sweep.scales", "expected a non-empty array of numbers");
      std::vector<std::array<double, 3>> offsets{{0.0, 0.0, 0.0}};
      if (const toml::node* os = w->get("offsets")) {
        const toml::array* oa = os->as_array();
        if (!oa || oa->empty()) r.fail(key + ".sweep.offsets", "expected an array of [x, y, z]");
        offsets.clear();
        for (const toml::node& o : *oa) offsets.push_back(r.vec3d(o, key + ".sweep.offsets"));
      }
      const double max_quantisation = r.get<double>(*w, key + ".sweep.", "max_quantisation", 1e-3);
      if (!(max_quantisation > 0.0 && std::isfinite(max_quantisation)))
        r.fail(key + ".sweep.max_quantisation", "must be a finite number > 0");
      for (const toml::node& sn : *scales) {
        const auto sv = sn.value<double>();
        if (!sv || !(*sv > 0.0 && std::isfinite(*sv))) r.fail(key + ".sweep.scales", "expected finite positive numbers");
        for (const auto& o : offsets) {
          const double far = std::max({std::fabs(o[0]), std::fabs(o[1]), std::fabs(o[2])});
          const float f = static_cast<float>(far);
          if (std::nextafter(f, std::numeric_limits<float>::infinity()) - f > max_quantisation * *sv) continue;
          SuiteScene copy = scene;
          copy.scale = *sv;
          copy.offset = o;
          copy.name = fmt::format("{}@s{:g}", scene.name, *sv);
          if (far > 0.0) copy.name += fmt::format("@o{:g}_{:g}_{:g}", o[0], o[1], o[2]);
          if (suite.find(copy.name)) r.fail(key + ".name", "duplicate scene name '" + copy.name + "'");
          move_entry(copy);
          r.check_moved(copy, key);
          suite.scenes.push_back(std::move(copy));
        }
      }
    }
  }
  if (suite.scenes.empty()) throw InputError(path, "the suite names no [[scene]]");
  return suite;
}

}  // namespace raybench
