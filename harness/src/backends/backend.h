// One interface for Embree and for our BVHs. Virtual per batch of rays, never
// per ray: inside a backend the loops are templates with the kernel inlined.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "raybench/math/ray.h"
#include "scene/scene.h"

namespace raybench {

// What a backend can model natively: the primitive types of a scene
// (raybench/prim/primitives.h) it traces as they are. A run skips a backend
// for a scene with a type it lacks (with a note: suite/suite_run.h), never
// tessellating silently; plugins model triangles only.
struct Capabilities {
  bool triangles = true;
  bool spheres = false;
  bool boxes = false;
  bool oriented_boxes = false;
  bool intersect = true;  // false for occlusion-only backends
};

// The primitive types `scene` has and `capabilities` lacks, in prim-id order
// ("spheres and oriented boxes"); "" when the backend can model the scene.
std::string missing_primitive_types(const Capabilities& capabilities, const Scene& scene);

struct BackendConfig {
  int threads = 1;  // threads a backend may use to build
  // The run's memory policy, the same for every backend: acceleration
  // structures in transparent huge pages (our BVHs: raybench/bvh/huge_pages.h;
  // Embree: backends/embree_memory.h), or all of them in ordinary pages.
  bool huge_pages = true;
};

std::string backend_accuracy_class(const std::string& name);

class Backend {
 public:
  virtual ~Backend() = default;
  // The full name it was made from, options included (e.g. "embree:high").
  virtual const std::string& name() const = 0;
  virtual Capabilities capabilities() const { return {}; }
  // The accuracy class of its triangle test: what the registry lists for its
  // name (backend_accuracy_class), or what a plugin reports for itself.
  virtual std::string accuracy_class() const { return backend_accuracy_class(name()); }
  // The name a plugin reports for itself (the results' `plugin` column);
  // empty for built-in backends.
  virtual std::string plugin_name() const { return {}; }
  // What its results depend on beyond its name, as metadata key/value pairs
  // (a plugin: its file's absolute path and content hash, its description;
  // Embree: the ISA, BVH and intersector it selected). A "summary" pair is
  // also printed as the run's progress line for the backend.
  virtual std::vector<std::pair<std::string, std::string>> provenance() const { return {}; }
  // Builds the acceleration structure; timed by the caller apart from tracing.
  virtual void build(const Scene& scene) = 0;
  // Bytes of the acceleration structure, triangle data it copied included.
  virtual std::size_t memory_bytes() const = 0;
  // Surface-area-heuristic cost of the tree it built, relative to its root's
  // area, for comparing builders (each backend says which cost model); NaN
  // where it does not apply or is not known (Embree, the reference).
  virtual double sah_cost() const { return std::numeric_limits<double>::quiet_NaN(); }

  // The rays both take are screened (rays/screening.h, screen_rays), once per
  // ray set and outside every timing, by every caller that may reach Embree or
  // a plugin (a run's timed traces and agreement, `raybench trace`):
  // - origin and direction finite, every |coordinate| <= kLargestTraceableCoordinate;
  // - 0 <= tnear (a negative tnear was raised to 0), tnear and tfar not NaN;
  // - the interval (tnear, tfar] may be empty (tfar < tnear, -inf included;
  //   kEmptyRay stands for a ray screened out): such a ray is a miss and not
  //   occluded.
  // Every backend relies on it: Embree (Debian's, built with assertions,
  // aborts on NaN, Inf or a negative tnear), plugins (docs/plugins.md), and
  // our own, whose timed loops trace each ray as given, so that every
  // backend does the same per-ray work inside the timing (issue 33). An
  // unscreened ray's answer is undefined (still no crash for our own).

  // Closest hit for every ray (t, prim, u, v; a miss is the default Hit).
  // Called concurrently on disjoint chunks, so implementations are const
  // and thread-safe.
  virtual void intersect(std::span<const Ray> rays, std::span<Hit> hits) const = 0;
  // Any hit within each ray's interval: 1 when occluded, 0 otherwise.
  virtual void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const = 0;
};

struct BackendInfo {
  std::string name;         // as given on the command line
  std::string description;
  std::string accuracy = "fast";  // the accuracy class of its triangle test; "epsilon" for seed-faithful ones
  // One of its family's kernel variants (bvh2: one per entry of TriangleTests
  // in raybench/variants.h): the pattern "<family>:*" names all of them
  // (expand_backend_patterns).
  bool variant = false;
  // A form to fill in, not a name make_backend accepts as it stands
  // ("plugin:PATH.so[:options]"): listed for people, skipped by code that
  // makes every listed backend.
  bool placeholder = false;
};

// A backend family: every name "family[:option...]" is made by `make`
// (given the full name and the options after the family), and `names` lists
// its canonical names for `raybench backends`.
using BackendFactory = std::unique_ptr<Backend> (*)(const std::string& name, const std::vector<std::string>& options,
                                                    const BackendConfig& config);
using BackendNames = std::vector<BackendInfo> (*)();

// Adds a family to the registry; RAYBENCH_BACKEND_FAMILY calls it while the
// program starts, so the registry is complete once main() runs (do not ask
// it from another file's static initialiser; gtest evaluates
// INSTANTIATE_TEST_SUITE_P's ValuesIn from main). `order` places the family
// in list_backends() (ascending; embree 100, bvh2 200, bvh8 300, bvh4 400,
// reference 900, plugin 950). Throws std::logic_error for a family name registered twice.
bool register_backend_family(std::string family, int order, BackendFactory make, BackendNames names);

// Registers a backend family from its own .cpp in harness/src/backends/, at
// namespace scope: RAYBENCH_BACKEND_FAMILY("bvh2", 200, make_bvh2, bvh2_names);
// Nothing else names the family: make_backend, list_backends and
// backend_accuracy_class find it by name. The harness is an OBJECT library
// (harness/CMakeLists.txt) so that the linker keeps this file although
// nothing refers to it.
#define RAYBENCH_BACKEND_FAMILY(family, order, make, names)                                    \
  [[maybe_unused]] static const bool RAYBENCH_BACKEND_CAT_(raybench_backend_family_, __LINE__) = \
      ::raybench::register_backend_family(family, order, make, names)
#define RAYBENCH_BACKEND_CAT_(a, b) RAYBENCH_BACKEND_PASTE_(a, b)
#define RAYBENCH_BACKEND_PASTE_(a, b) a##b

// Makes a backend from "family[:option[:option...]]", e.g. "embree:high:robust"
// or "bvh2:mt". Throws InputError naming an unknown family or option.
std::unique_ptr<Backend> make_backend(const std::string& name, const BackendConfig& config = {});

// Why `backend` cannot trace `scene`, as one line, e.g. "backend 'plugin:x.so'
// models triangles only; scene 'mix' has spheres and boxes"; "" when it can
// (missing_primitive_types is empty).
std::string capability_problem(const Backend& backend, const Scene& scene);

// Every name make_backend accepts in its canonical forms, for --help.
std::vector<BackendInfo> list_backends();

// The backend names with each pattern "<family>:*" replaced by every name
// of that family marked as a kernel variant (BackendInfo::variant), in
// list_backends() order: "bvh2:*" is bvh2 with every triangle test of
// raybench/variants.h. Other names pass through unchanged. Throws InputError
// for a pattern whose family is unknown or has no variants.
std::vector<std::string> expand_backend_patterns(const std::vector<std::string>& names);

// The accuracy class of a backend name (as listed; options the list does not
// spell out, such as a trailing ":robust", are looked through): "fast",
// "epsilon", "watertight", "reference", "exact". A plugin's ("plugin:...")
// is the class it reports, which loads the library (InputError if it cannot).
std::string backend_accuracy_class(const std::string& name);

}  // namespace raybench
