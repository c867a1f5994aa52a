/* SPDX-License-Identifier: MIT */
/* Host builds on x86-64 (CMake option LIDET_NN_CLONES, on by default there, set on the sources that use these):
 * GCC/clang also compile the functions marked below for AVX2 (and AVX-512) and pick the variant when the
 * program loads (ifunc), the way onnxruntime dispatches its kernels. Same C source, same results: every
 * marked function is a loop whose lanes are independent (no reduction reordered, no FMA contraction:
 * -ffp-contract=off), so each value is computed by the same IEEE operations at every vector width. Only
 * streaming loops are marked: a loop with indexed loads would become hardware gathers, slower than scalar
 * loads on the hosts measured. Firmware builds leave LIDET_NN_CLONES at its default 0: the macros are empty there. */
#ifndef LIDET_SIMD_H
#define LIDET_SIMD_H

#include "lidet/lidet_opt.h" /* LIDET_NN_CLONES, LIDET_NN_FMA, LIDET_HOST_SIMD */

#if LIDET_NN_CLONES && LIDET__TARGET_X86_64_GNU
#define LIDET_CLONES_AVX2 __attribute__((target_clones("avx2", "default")))
#define LIDET_CLONES_AVX512 __attribute__((target_clones("avx512f", "avx2", "default")))
#define LIDET_HOST_CLONES 1 /* the clones are built: a loop written branch-free for them runs vectorised */
#else
#define LIDET_CLONES_AVX2
#define LIDET_CLONES_AVX512
#define LIDET_HOST_CLONES 0
#endif
/* the one exception to "same results": the float dense kernel's FMA variants (lib/src/nn/lidet_nn_f32_x86.c),
 * where LIDET_NN_FMA is 1 (by default with the clones; CMake LIDET_NN_FMA=OFF passes 0; the -O0 CLI of the
 * determinism test, tests/CMakeLists.txt, passes 1 without the clones, so that it runs the arithmetic of the
 * build it is compared with). LIDET_HOST_SIMD (lidet_opt.h) picks the integer kernels' loop forms. */

#endif
