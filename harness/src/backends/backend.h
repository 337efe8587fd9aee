// One interface for Embree and for our BVHs. Virtual per batch of rays, never
// per ray: inside a backend the loops are templates with the kernel inlined.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "raybench/math/ray.h"
#include "scene/scene.h"

namespace raybench {

// What a backend can model natively. Only triangles exist today; analytic
// spheres and boxes arrive with scene manifests that name them.
struct Capabilities {
  bool triangles = true;
  bool spheres = false;
  bool boxes = false;
  bool oriented_boxes = false;
  bool intersect = true;  // false for occlusion-only backends
};

struct BackendConfig {
  int threads = 1;  // threads a backend may use to build
};

class Backend {
 public:
  virtual ~Backend() = default;
  // The full name it was made from, options included (e.g. "embree:high").
  virtual const std::string& name() const = 0;
  virtual Capabilities capabilities() const { return {}; }
  // Builds the acceleration structure; timed by the caller apart from tracing.
  virtual void build(const Scene& scene) = 0;
  // Bytes of the acceleration structure, triangle data it copied included.
  virtual std::size_t memory_bytes() const = 0;
  // Surface-area-heuristic cost of the tree it built, relative to its root's
  // area, for comparing builders (each backend says which cost model); NaN
  // where it does not apply or is not known (Embree, the reference).
  virtual double sah_cost() const { return std::numeric_limits<double>::quiet_NaN(); }

  // Closest hit for every ray (t, prim, u, v; a miss leaves the default Hit).
  // Untraceable rays (see is_traceable) are misses. Called concurrently on
  // disjoint chunks, so implementations are const and thread-safe.
  virtual void intersect(std::span<const Ray> rays, std::span<Hit> hits) const = 0;
  // Any hit within each ray's interval: 1 when occluded, 0 otherwise.
  virtual void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const = 0;
};

struct BackendInfo {
  std::string name;         // as given on the command line
  std::string description;
  std::string accuracy = "fast";  // the accuracy class of its triangle test; "epsilon" for seed-faithful ones
};

// Makes a backend from "family[:option[:option...]]", e.g. "embree:high:robust"
// or "bvh2:mt". Throws InputError naming an unknown family or option.
std::unique_ptr<Backend> make_backend(const std::string& name, const BackendConfig& config = {});

// Every name make_backend accepts in its canonical forms, for --help.
std::vector<BackendInfo> list_backends();

// The accuracy class of a backend name (as listed; options the list does not
// spell out, such as a trailing ":robust", are looked through): "fast",
// "epsilon", "watertight", "reference", "exact".
std::string backend_accuracy_class(const std::string& name);

}  // namespace raybench
