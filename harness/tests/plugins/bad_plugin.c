/* The bad test plugins: one library per way a plugin can be wrong, all
 * from this file, chosen by BAD_<MODE> at compile time (CMakeLists.txt):
 *   BAD_NO_ENTRY        exports no raybench_plugin
 *   BAD_WRONG_ABI       reports ABI version RAYBENCH_PLUGIN_ABI_VERSION + 1
 *   BAD_NULL_NAME       a table without a name
 *   BAD_NO_INTERSECT    a table without intersect
 *   BAD_CLASS           an accuracy class raybench does not know
 *   BAD_BUILD_FAILS     build returns NULL with a message
 *   BAD_PRIMS           hits with prim = triangle count + 5
 *   BAD_NAN_T           hits at t = NaN
 *   BAD_INF_HIT         hits at t = +inf
 *   BAD_TRACE_ERROR     intersect and occluded return 7
 *   BAD_SEGFAULT        intersect and occluded write to an unmapped address
 * Otherwise they are the good brute force. Option "after=N": they misbehave
 * only on scenes of more than N triangles (brute_force.h). */
#include "brute_force.h"

typedef struct bad_accel {
  brute_accel* inner;
  int misbehave;
} bad_accel;

static void* bad_build(const raybench_build_input* input, char* error, size_t error_size) {
  const int misbehave = input->triangle_count > brute_after(input->options);
#ifdef BAD_BUILD_FAILS
  if (misbehave) {
    snprintf(error, error_size, "cannot build %zu triangles (a test plugin that fails)", input->triangle_count);
    return NULL;
  }
#endif
  bad_accel* a = (bad_accel*)malloc(sizeof(bad_accel));
  if (!a) return NULL;
  a->inner = (brute_accel*)brute_build(input, error, error_size);
  a->misbehave = misbehave;
  if (!a->inner) {
    free(a);
    return NULL;
  }
  return a;
}

static size_t bad_memory_bytes(const void* accel) { return brute_memory_bytes(((const bad_accel*)accel)->inner); }

static void bad_destroy(void* accel) {
  brute_destroy(((bad_accel*)accel)->inner);
  free(accel);
}

__attribute__((unused)) static int bad_intersect(const void* accel, const raybench_ray* rays, size_t count, raybench_hit* hits) {
  const bad_accel* a = (const bad_accel*)accel;
  brute_intersect(a->inner, rays, count, hits);
  if (!a->misbehave) return 0;
#ifdef BAD_TRACE_ERROR
  return 7;
#endif
#ifdef BAD_SEGFAULT
  *(volatile int*)(hits[0].prim < -1000 ? (uintptr_t)hits : (uintptr_t)16) = 1; /* an unmapped page */
#endif
  for (size_t i = 0; i < count; ++i) {
    if (hits[i].prim == RAYBENCH_NO_HIT) continue;
#ifdef BAD_PRIMS
    hits[i].prim = (int32_t)a->inner->count + 5;
#endif
#ifdef BAD_NAN_T
    hits[i].t = NAN;
#endif
#ifdef BAD_INF_HIT
    hits[i].t = INFINITY;
#endif
  }
  return 0;
}

static int bad_occluded(const void* accel, const raybench_ray* rays, size_t count, uint8_t* occluded) {
  const bad_accel* a = (const bad_accel*)accel;
  brute_occluded(a->inner, rays, count, occluded);
  if (!a->misbehave) return 0;
#ifdef BAD_TRACE_ERROR
  return 7;
#endif
#ifdef BAD_SEGFAULT
  *(volatile int*)(occluded[0] > 200 ? (uintptr_t)occluded : (uintptr_t)16) = 1;
#endif
  return 0;
}

static const raybench_plugin_table table = {
#ifdef BAD_WRONG_ABI
    RAYBENCH_PLUGIN_ABI_VERSION + 1,
#else
    RAYBENCH_PLUGIN_ABI_VERSION,
#endif
#ifdef BAD_NULL_NAME
    NULL,
#else
    "bad_plugin",
#endif
    "a test plugin that misbehaves",
#ifdef BAD_CLASS
    "approximate",
#else
    "fast",
#endif
    NULL,
    bad_build,
    bad_memory_bytes,
#ifdef BAD_NO_INTERSECT
    NULL,
#else
    bad_intersect,
#endif
    bad_occluded,
    bad_destroy,
};

#ifdef BAD_NO_ENTRY
RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin_v2(void) { return &table; }
#else
RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin(void) { return &table; }
#endif
