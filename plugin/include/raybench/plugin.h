/* raybench/plugin.h: the interface between raybench and a kernel that lives
 * in its user's own repository. A plugin is a shared library that exports one
 * C function, raybench_plugin(), returning a table of functions: raybench
 * loads it with `--backend plugin:PATH.so[:options]` and gives it the same
 * scenes, stored rays, timing, agreement, referee, compare and gate as its
 * built-in backends. Plain C (C99 and C++), so a kernel written in C, C++,
 * Rust or ISPC can implement it. Reference: docs/plugins.md.
 *
 * Guarantees raybench gives a plugin:
 * - Triangles: `build` receives the scene as a triangle soup, 9 floats per
 *   triangle (v0 x y z, v1 x y z, v2 x y z); triangle i is primitive id i.
 *   Degenerate triangles (zero area) are kept, as every backend sees them.
 * - Rays: the .npy row layout, 8 floats (ox oy oz tnear dx dy dz tfar). A
 *   ray covers the open-closed interval (tnear, tfar]. raybench screens the
 *   rays once per ray set, outside the timing: a plugin never receives NaN
 *   or infinite components, coordinates beyond 1.844e18, or a negative
 *   tnear (raised to 0). A ray raybench screened out arrives as an empty
 *   interval (origin 0, direction (1, 0, 0), tnear 1, tfar 0) and counts as
 *   a miss whatever the plugin answers. Directions are not normalised and
 *   may be zero; tnear may exceed tfar.
 * - Threads: `build` runs on one thread of raybench's and may use up to
 *   `threads` threads (a TBB parallel_for inside it uses raybench's arena).
 *   `intersect` and `occluded` are called concurrently from up to `threads`
 *   threads on disjoint batches of the same accel: they must not modify it.
 * - Batches: one call traces `count` rays (1 to a few thousand; 1024 today).
 *   raybench never calls per ray, so the boundary costs one indirect call per
 *   batch.
 * - Ownership: raybench owns the triangle, option, ray and output arrays;
 *   they are valid only during the call. The accel belongs to the plugin
 *   from `build` until raybench passes it to `destroy`. Strings in the table
 *   (name, description, accuracy_class) must stay valid while the library is
 *   loaded.
 * - Errors: a plugin never aborts the process. `build` and `check_options`
 *   report failure by returning NULL / non-zero with a message in `error`;
 *   `intersect` and `occluded` return non-zero. raybench then stops with one
 *   line naming the plugin, and keeps every result row it had finished.
 *   Exceptions must not leave a C++ plugin (unwinding through a C interface
 *   is undefined behaviour); raybench catches what escapes anyway, as a
 *   failure of the call. raybench also checks the answers, outside the
 *   timing: a hit with a primitive id outside [0, triangle_count), a NaN t,
 *   a hit at infinite t, or an occlusion flag other than 0 or 1 is an error
 *   naming how many rays had it.
 *
 * Versioning: RAYBENCH_PLUGIN_ABI_VERSION changes whenever this file changes
 * incompatibly; raybench refuses a plugin built for another version, naming
 * both. */
#ifndef RAYBENCH_PLUGIN_H
#define RAYBENCH_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RAYBENCH_PLUGIN_ABI_VERSION 1

/* The symbol raybench looks up in the library. */
#define RAYBENCH_PLUGIN_ENTRY_POINT "raybench_plugin"

/* One ray: a row of a ray file. */
typedef struct raybench_ray {
  float org_x, org_y, org_z;
  float tnear;
  float dir_x, dir_y, dir_z;
  float tfar;
} raybench_ray;

/* The closest hit: t in (tnear, tfar]; prim the triangle's index; u, v the
 * barycentric coordinates of the hit point p = (1-u-v) v0 + u v1 + v v2.
 * A miss is t = +infinity, prim = -1 (u, v ignored). The plugin writes
 * every entry, misses included (raybench does not clear the array). */
typedef struct raybench_hit {
  float t;
  int32_t prim;
  float u, v;
} raybench_hit;

#define RAYBENCH_NO_HIT (-1)

typedef struct raybench_build_input {
  const float* triangles;  /* 9 * triangle_count floats, see above */
  size_t triangle_count;   /* at least 1 */
  const char* options;     /* the text after "plugin:PATH:", "" when none */
  int threads;             /* threads build may use; also the tracing threads */
} raybench_build_input;

/* Space for a message from build or check_options: one line, UTF-8, NUL
 * terminated, truncated to the buffer. */
#define RAYBENCH_PLUGIN_ERROR_SIZE 512

/* Every field is required except `description` (NULL reads as "") and
 * `check_options` (NULL accepts every options string). */
typedef struct raybench_plugin_table {
  /* RAYBENCH_PLUGIN_ABI_VERSION as the plugin was compiled. */
  uint32_t abi_version;
  /* Shown in results and tables: a short name ("my_bvh"), what it is, and
   * the accuracy class of its triangle test, one of "fast" (a float test
   * that may let rays through shared edges), "epsilon" (a float test with
   * tolerances), "watertight" (no ray passes between adjacent triangles),
   * "exact". */
  const char* name;
  const char* description;
  const char* accuracy_class;

  /* Optional (NULL: every options string is accepted): checks an options
   * string before any scene is loaded, so that a typo fails at once. Returns
   * 0 when the options are valid, otherwise non-zero with a message. */
  int (*check_options)(const char* options, char* error, size_t error_size);

  /* Builds the acceleration structure; returns NULL with a message on
   * failure. Timed by raybench (repeated builds each get their own accel). */
  void* (*build)(const raybench_build_input* input, char* error, size_t error_size);
  /* Bytes the accel holds (tree, triangles it copied): the memory column. */
  size_t (*memory_bytes)(const void* accel);
  /* Closest hit of each of `count` rays into hits[0 .. count). Returns 0. */
  int (*intersect)(const void* accel, const raybench_ray* rays, size_t count, raybench_hit* hits);
  /* Any hit within each ray's interval: occluded[i] = 1 if so, 0 if not,
   * for every i. Returns 0. */
  int (*occluded)(const void* accel, const raybench_ray* rays, size_t count, uint8_t* occluded);
  void (*destroy)(void* accel);
} raybench_plugin_table;

/* What a plugin library exports (with C linkage and default visibility):
 *   RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin(void);
 * It returns the same table on every call. */
#if defined(_WIN32)
#define RAYBENCH_PLUGIN_EXPORT __declspec(dllexport)
#else
#define RAYBENCH_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

typedef const raybench_plugin_table* (*raybench_plugin_entry)(void);

#ifdef __cplusplus
}
#endif

#endif /* RAYBENCH_PLUGIN_H */
