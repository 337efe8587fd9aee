// raybench_bvh8_plugin: the built-in `bvh8` (its default build: binned-SAH
// BVH2 collapsed to 8 wide, Möller–Trumbore leaves, the plain box test)
// as a plugin, written only against raybench/plugin.h and the kernels.
// What it is for: it shows what the plugin boundary costs. It calls exactly
// the functions the built-in backend calls (raybench/bvh/wide_bvh_batch.h,
// the same template arguments as wide_bvh_backend.cpp's default), so it
// builds the same tree and traces bit-identical hits; the only extra work
// is one indirect call per batch of rays. Rays, hits and triangles are
// raybench's own types, so nothing is copied or converted.
// Options: none.
#include <cstdio>
#include <exception>
#include <new>
#include <span>

#include "raybench/bvh/wide_bvh_batch.h"
#include "raybench/plugin.h"

namespace {

using raybench::Hit;
using raybench::Ray;
using raybench::Triangle;
// bvh8 with no options (make_wide_backend<8>): mt leaves, plain boxes.
using Leaf = raybench::WideMollerTrumbore;
using BoxTest = raybench::SlabFma;
using Bvh = raybench::WideBvh<8>;

// raybench passes its own arrays (backends/plugin_backend.cpp asserts the
// same layouts on its side).
static_assert(sizeof(Ray) == sizeof(raybench_ray) && sizeof(Hit) == sizeof(raybench_hit));
static_assert(sizeof(Triangle) == 9 * sizeof(float));

int check_options(const char* options, char* error, size_t error_size) {
  if (options[0] == '\0') return 0;
  std::snprintf(error, error_size, "raybench_bvh8_plugin takes no options (got '%s')", options);
  return 1;
}

void* build(const raybench_build_input* input, char* error, size_t error_size) {
  try {
    const std::span<const Triangle> triangles(reinterpret_cast<const Triangle*>(input->triangles),
                                              input->triangle_count);
    return new Bvh(raybench::build_wide_bvh<8, Leaf>(triangles, raybench::Bvh2Builder::kBinnedSah,
                                                     raybench::Bvh2Reinsertion::kLight));
  } catch (const std::bad_alloc&) {
    std::snprintf(error, error_size, "out of memory");
  } catch (const std::exception& e) {
    std::snprintf(error, error_size, "%s", e.what());
  }
  return nullptr;
}

size_t memory_bytes(const void* accel) { return static_cast<const Bvh*>(accel)->memory_bytes(); }

int intersect(const void* accel, const raybench_ray* rays, size_t count, raybench_hit* hits) {
  raybench::intersect_wide_batch<Leaf, BoxTest>(*static_cast<const Bvh*>(accel),
                                                std::span<const Ray>(reinterpret_cast<const Ray*>(rays), count),
                                                std::span<Hit>(reinterpret_cast<Hit*>(hits), count));
  return 0;
}

int occluded(const void* accel, const raybench_ray* rays, size_t count, uint8_t* occluded) {
  raybench::occluded_wide_batch<Leaf, BoxTest>(*static_cast<const Bvh*>(accel),
                                               std::span<const Ray>(reinterpret_cast<const Ray*>(rays), count),
                                               std::span<std::uint8_t>(occluded, count));
  return 0;
}

void destroy(void* accel) { delete static_cast<Bvh*>(accel); }

const raybench_plugin_table kTable = {
    RAYBENCH_PLUGIN_ABI_VERSION,
    "bvh8_plugin",
    "the built-in bvh8 (binned SAH, 8-wide AVX2 nodes, Moller-Trumbore leaves) behind the plugin interface",
    "fast",  // backend_accuracy_class("bvh8")
    check_options,
    build,
    memory_bytes,
    intersect,
    occluded,
    destroy,
};

}  // namespace

extern "C" RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin(void) { return &kTable; }
