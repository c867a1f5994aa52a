/* SPDX-License-Identifier: MIT */
/* Host builds on x86-64 (CMake option LIDET_NN_CLONES, on by default there, set on the sources that use these):
 * GCC/clang also compile the functions marked below for AVX2 (and AVX-512) and pick the variant when the
 * program loads (ifunc), the way onnxruntime dispatches its kernels. Same C source, same results: every
 * marked function is a loop whose lanes are independent (no reduction reordered, no FMA contraction:
 * -ffp-contract=off), so each value is computed by the same IEEE operations at every vector width. Only
 * streaming loops are marked: a loop with indexed loads would become hardware gathers, slower than scalar
 * loads on the hosts measured. Firmware builds never define LIDET_NN_CLONES: the macros are empty there. */
#ifndef LIDET_SIMD_H
#define LIDET_SIMD_H

#if defined(LIDET_NN_CLONES) && LIDET_NN_CLONES && (defined(__GNUC__) || defined(__clang__)) &&              \
    defined(__x86_64__)
#define LIDET_CLONES_AVX2 __attribute__((target_clones("avx2", "default")))
#define LIDET_CLONES_AVX512 __attribute__((target_clones("avx512f", "avx2", "default")))
/* the one exception to "same results": the float dense kernel's FMA variants (lib/src/nn/lidet_nn_f32_x86.c; CMake
 * LIDET_NN_FMA, on by default, passes 0 when off) */
#ifndef LIDET_NN_FMA
#define LIDET_NN_FMA 1
#endif
#elif defined(LIDET_NN_FMA_ONLY) && LIDET_NN_FMA_ONLY && (defined(__GNUC__) || defined(__clang__)) &&        \
    defined(__x86_64__)
/* the FMA kernel without the clones (tests/CMakeLists.txt: the -O0 CLI of the determinism test, so that it runs
 * the arithmetic of the build it is compared with) */
#define LIDET_CLONES_AVX2
#define LIDET_CLONES_AVX512
#undef LIDET_NN_FMA
#define LIDET_NN_FMA 1
#else
#define LIDET_CLONES_AVX2
#define LIDET_CLONES_AVX512
#undef LIDET_NN_FMA
#define LIDET_NN_FMA 0
#endif

/* 1 on hosts with SIMD (SSE2, AVX2, NEON): the integer kernels keep the loop forms a compiler vectorises (the
 * inner loop over a row's columns or a layer's channels); 0 on cores without SIMD (Cortex-M, RV32), where the
 * same kernels keep values in registers or leave early instead (LIDET_GROUND_Q_SQRT_LANES, LIDET_NN_SIMD).
 * Same values either way. */
#ifndef LIDET_HOST_SIMD
#if defined(__SSE2__) || defined(__ARM_NEON) || defined(__ARM_NEON__) || defined(__AVX2__)
#define LIDET_HOST_SIMD 1
#else
#define LIDET_HOST_SIMD 0
#endif
#endif

#endif
