/* The test plugins' kernel: every ray against every triangle, Möller–Trumbore
 * in float, the interval (max(tnear, 0), tfar]. Plain C99, written only
 * against raybench/plugin.h, as a user's plugin is; small scenes only.
 * Each test plugin includes it and sets its own table (static functions). */
#ifndef RAYBENCH_TEST_BRUTE_FORCE_H
#define RAYBENCH_TEST_BRUTE_FORCE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "raybench/plugin.h"

typedef struct brute_accel {
  float* triangles; /* 9 floats per triangle, copied */
  size_t count;
} brute_accel;

/* "after=N" in the options: the plugin misbehaves only on scenes of more
 * than N triangles (0: always), so a run's earlier, smaller scenes finish. */
static inline size_t brute_after(const char* options) {
  const char* at = strstr(options, "after=");
  return at ? (size_t)strtoull(at + 6, NULL, 10) : 0;
}

static void* brute_build(const raybench_build_input* input, char* error, size_t error_size) {
  brute_accel* a = (brute_accel*)malloc(sizeof(brute_accel));
  if (!a) {
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  a->count = input->triangle_count;
  a->triangles = (float*)malloc(9 * sizeof(float) * a->count);
  if (!a->triangles) {
    free(a);
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  memcpy(a->triangles, input->triangles, 9 * sizeof(float) * a->count);
  return a;
}

static size_t brute_memory_bytes(const void* accel) {
  const brute_accel* a = (const brute_accel*)accel;
  return sizeof(*a) + 9 * sizeof(float) * a->count;
}

static void brute_destroy(void* accel) {
  brute_accel* a = (brute_accel*)accel;
  free(a->triangles);
  free(a);
}

/* Möller–Trumbore: 1 and t, u, v when the ray hits triangle tri in (t0, t1]. */
static int brute_hit(const raybench_ray* r, const float* tri, float t0, float t1, float* t, float* u, float* v) {
  const float e1x = tri[3] - tri[0], e1y = tri[4] - tri[1], e1z = tri[5] - tri[2];
  const float e2x = tri[6] - tri[0], e2y = tri[7] - tri[1], e2z = tri[8] - tri[2];
  const float px = r->dir_y * e2z - r->dir_z * e2y, py = r->dir_z * e2x - r->dir_x * e2z,
              pz = r->dir_x * e2y - r->dir_y * e2x;
  const float det = e1x * px + e1y * py + e1z * pz;
  if (det == 0.0f || isnan(det)) return 0;
  const float inv = 1.0f / det;
  const float sx = r->org_x - tri[0], sy = r->org_y - tri[1], sz = r->org_z - tri[2];
  const float uu = (sx * px + sy * py + sz * pz) * inv;
  if (!(uu >= 0.0f && uu <= 1.0f)) return 0;
  const float qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
  const float vv = (r->dir_x * qx + r->dir_y * qy + r->dir_z * qz) * inv;
  if (!(vv >= 0.0f && uu + vv <= 1.0f)) return 0;
  const float tt = (e2x * qx + e2y * qy + e2z * qz) * inv;
  if (!(tt > t0 && tt <= t1)) return 0;
  *t = tt;
  *u = uu;
  *v = vv;
  return 1;
}

static void brute_closest(const brute_accel* a, const raybench_ray* r, raybench_hit* h) {
  const float t0 = r->tnear > 0.0f ? r->tnear : 0.0f;
  h->t = INFINITY;
  h->prim = RAYBENCH_NO_HIT;
  h->u = h->v = 0.0f;
  for (size_t i = 0; i < a->count; ++i) {
    float t, u, v;
    if (brute_hit(r, a->triangles + 9 * i, t0, h->prim == RAYBENCH_NO_HIT ? r->tfar : h->t, &t, &u, &v) &&
        (h->prim == RAYBENCH_NO_HIT || t < h->t)) {
      h->t = t;
      h->prim = (int32_t)i;
      h->u = u;
      h->v = v;
    }
  }
}

static int brute_intersect(const void* accel, const raybench_ray* rays, size_t count, raybench_hit* hits) {
  for (size_t i = 0; i < count; ++i) brute_closest((const brute_accel*)accel, rays + i, hits + i);
  return 0;
}

static int brute_occluded(const void* accel, const raybench_ray* rays, size_t count, uint8_t* occluded) {
  const brute_accel* a = (const brute_accel*)accel;
  for (size_t i = 0; i < count; ++i) {
    const float t0 = rays[i].tnear > 0.0f ? rays[i].tnear : 0.0f;
    occluded[i] = 0;
    for (size_t k = 0; k < a->count && !occluded[i]; ++k) {
      float t, u, v;
      occluded[i] = (uint8_t)brute_hit(rays + i, a->triangles + 9 * k, t0, rays[i].tfar, &t, &u, &v);
    }
  }
  return 0;
}

#endif
