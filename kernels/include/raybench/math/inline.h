// RAYBENCH_INLINE: force inlining of the per-box and per-triangle tests in
// traversal loops. GCC's size heuristics otherwise inline them in some
// instantiations and not in others, which moved one backend's throughput
// with no change to its arithmetic (measured: docs/notes/kernels-wide-traversal.md).
#pragma once

#if defined(__GNUC__)
#define RAYBENCH_INLINE inline __attribute__((always_inline))
#else
#define RAYBENCH_INLINE inline
#endif
