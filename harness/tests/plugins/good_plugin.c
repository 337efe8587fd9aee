/* The good test plugin: brute force (brute_force.h), in C. Options: "" or
 * "reject" (check_options refuses "reject", and any other word, with a
 * message naming it). */
#include "brute_force.h"

static int good_check_options(const char* options, char* error, size_t error_size) {
  if (options[0] == '\0') return 0;
  snprintf(error, error_size, "good_plugin takes no options, not '%s'", options);
  return 1;
}

static const raybench_plugin_table table = {
    RAYBENCH_PLUGIN_ABI_VERSION,
    "good_brute_force",
    "every ray against every triangle, Moller-Trumbore in float (a test plugin)",
    "fast",
    good_check_options,
    brute_build,
    brute_memory_bytes,
    brute_intersect,
    brute_occluded,
    brute_destroy,
};

RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin(void) { return &table; }
