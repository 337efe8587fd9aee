// RAYBENCH_INLINE: force inlining of the per-box and per-triangle tests in
// traversal loops. GCC's size heuristics otherwise inline them in some
// instantiations and not in others, which was measured to move one backend's
// throughput by ~18 % with no change to its arithmetic.
#pragma once

#if defined(__GNUC__)
#define RAYBENCH_INLINE inline __attribute__((always_inline))
#else
#define RAYBENCH_INLINE inline
#endif
