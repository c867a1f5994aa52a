/* SPDX-License-Identifier: MIT */
/* Dense-layer kernels of the PointNet forward pass (lib/src/nn/lidet_nn_f32.c). Stateless, caller
 * buffers only (CMSIS-NN style); a port may replace the file with kernels of the same signatures, and
 * this portable one stays the test oracle. Never installed. */
#ifndef LIDET_NN_H
#define LIDET_NN_H

#include <stdint.h>

#include "internal/lidet_simd.h"

/* Host builds on x86-64 (internal/lidet_simd.h): the kernels marked LIDET_NN_KERNEL get an AVX2 variant,
 * LIDET_NN_KERNEL_F32 (the float dense kernel) also an AVX-512 one: measured on an AMD EPYC (Zen 4) host, the
 * VLP-16 sample's classifier 0.86 -> 0.58 ms and box net 0.36 -> 0.24 ms per scan (lidet detect --cpu-clock).
 * The int8 kernels do not: their AVX-512 variant measured 7-12 % slower there than the AVX2 one. */
#define LIDET_NN_KERNEL LIDET_CLONES_AVX2
#define LIDET_NN_KERNEL_F32 LIDET_CLONES_AVX512

/* out[r * n_out + o] = act(b[o] + sum_i in[r * n_in + i] * w_t[i * n_out + o]), r < n_rows.
 * in and out may not alias. relu: 1 = max(0, .) after the bias. */
void lidet__nn_dense_f32(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t, const float *b,
                         uint32_t n_out, int relu, float *out);

/* Cortex-M4F, M7 (Armv7E-M with a single-precision FPU; GCC or clang): lidet__nn_dense_f32 is
 * lib/src/nn/lidet_nn_f32_cm.c's kernel (VLDM/VSTM tiles of 8 outputs, zero inputs of ReLU layers skipped): the
 * portable kernel's results bit for bit, or with LIDET_NN_CM_FMA (lidet_opt.h) the x86-64 FMA kernel's arithmetic
 * (VFMA); the portable one stays, as lidet__nn_dense_f32_portable. Not an option: it follows the target. */
#if defined(__GNUC__) && defined(__ARM_ARCH_7EM__) && defined(__ARM_FP) && !LIDET_NN_FMA && !LIDET_NN_NEON
#define LIDET_NN_F32_CM ((__ARM_FP & 4) != 0)
#else
#define LIDET_NN_F32_CM 0
#endif
/* RISC-V cores with the F extension (GCC or clang): lidet__nn_dense_f32 is lib/src/nn/lidet_nn_f32_rv.c's fused kernel
 * (fmadd.s, the x86-64 FMA kernel's arithmetic) where lidet_opt.h's LIDET_NN_RV_FMA is 1 (the default there) */
#if defined(__GNUC__) && LIDET__TARGET_RISCV_F && LIDET_NN_RV_FMA
#define LIDET_NN_F32_RV 1
#else
#define LIDET_NN_F32_RV 0
#endif
#if LIDET_NN_FMA || LIDET_NN_NEON || LIDET_NN_F32_CM || LIDET_NN_F32_RV
/* x86-64 hosts with FMA dispatch (internal/lidet_simd.h): lidet__nn_dense_f32 is lib/src/nn/lidet_nn_f32_x86.c's
 * register-tiled FMA kernel, this the portable one (lidet_nn_f32.c), its fallback on CPUs without FMA; aarch64
 * (LIDET_NN_NEON): lidet__nn_dense_f32 is lidet_nn_f32_neon.c's NEON kernel, this the portable one, for the tests;
 * Cortex-M (LIDET_NN_F32_CM): the unfused kernel's fallback for widths not a multiple of 8, and the tests' oracle;
 * RISC-V (LIDET_NN_F32_RV): the tests' oracle */
void lidet__nn_dense_f32_portable(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                  const float *b, uint32_t n_out, int relu, float *out);
#endif
#if LIDET_NN_FMA
/* its two variants, for the tests (call only on a CPU with AVX-512F, resp. AVX2 and FMA) */
void lidet__nn_dense_f32_avx512(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                const float *b, uint32_t n_out, int relu, float *out);
void lidet__nn_dense_f32_avx2fma(const float *in, uint32_t n_rows, uint32_t n_in, const float *w_t,
                                 const float *b, uint32_t n_out, int relu, float *out);
#endif

/* vmax[k] = max(vmax[k], in[r * n + k]) over the rows: the max-pool over points, applied block by block
 * (the caller initialises vmax), so no N x C buffer is needed. */
void lidet__nn_max_rows_f32(const float *in, uint32_t n_rows, uint32_t n, float *vmax);
#if LIDET_NN_F32_CM
/* Cortex-M4F/M7: lidet__nn_max_rows_f32 is lidet_nn_f32_cm.c's (8 columns in registers over the rows), this the
 * portable one (lidet_nn_f32.c), its fallback for widths not a multiple of 8 */
void lidet__nn_max_rows_f32_portable(const float *in, uint32_t n_rows, uint32_t n, float *vmax);
#endif

#endif
