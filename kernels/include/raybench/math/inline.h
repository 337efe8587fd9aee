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

// RAYBENCH_BATCH_LOOP: a batch traversal (one call per batch of rays, its
// whole hot loop inside), never inlined and starting on a page boundary, so
// that its code sits at the same offsets within a page wherever the linker
// places it: in the executable or in a plugin (plugin/bvh8), before or after
// an unrelated change elsewhere. The branch predictors and the decoded-uop
// cache index by those address bits: identical machine code placed at other
// offsets ran 3-7 % apart on fast coherent rays, in every process
// (docs/notes/plugin-boundary.md). The cost is padding, under 4 KiB each.
#if defined(__GNUC__)
#define RAYBENCH_BATCH_LOOP __attribute__((noinline, aligned(4096)))
#else
#define RAYBENCH_BATCH_LOOP
#endif
