/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_opt.h
 * @brief Compile-time options of lidet (lwIP style): every capacity, memory layout, build variant and
 *        per-target kernel choice of the library, each with its default, its range and its #error check.
 *
 * Each option is `#ifndef X / #define X default`. Override them either with `-DX=...` on the compiler
 * command line (CMake cache variables of the same name do that: cmake/lidet_options.cmake), or in a header
 * named `lidet_user_config.h` on the include path, read when `LIDET_USER_CONFIG` is defined.
 * All consistency checks (`#error`) live at the end of this file, in one place, in the order of the options.
 * docs/OPTIONS.md ("Every compile-time option") lists them all with their CMake variables.
 *
 * Memory: every buffer of a stage is a fixed-size array inside its state struct, sized from these
 * options, so the linker reports a RAM overflow instead of the library failing at run time. The
 * byte counts are documented in each stage's header and reported by `lidet_*_bytes()` calls.
 *
 * Defaults fit every shipped sensor profile on a host (os1-128: 128 x 2048 pixels, 262,144 points).
 * A VLP-16 robot board would use e.g. LIDET_MAX_ROWS 16, LIDET_MAX_COLS 1800, LIDET_MAX_POINTS 30000.
 * The per-target options (the last group) default to what the compiler says about the target; the results
 * are the same bits with every value of them, only speed and flash differ.
 */
#ifndef LIDET_OPT_H
#define LIDET_OPT_H

#ifdef LIDET_USER_CONFIG
#include "lidet_user_config.h"
#endif

/* Port layer: a target's ports/<target>/lidet_port.h, read when LIDET_PORT is defined (CMake:
 * -DLIDET_PORT_DIR=ports/<target> adds its folder to the include path and defines LIDET_PORT). It may
 * define the hooks below (LIDET_ASSERT, LIDET_ALIGN, LIDET_WORKSPACE_SECTION, LIDET_RODATA); what it
 * leaves undefined takes the defaults at the end of this file. See ports/cortex-m/lidet_port.h. */
#ifdef LIDET_PORT
#include "lidet_port.h"
#endif

/* ==== capacities: sizes of the state structs (CMake: the cache variable of the same name) ============== */

/** Maximum range-image rows (beams) of any sensor used with this build. Range [1, 256] (rows are stored as
 *  uint8 indices in places). Default 128: the largest shipped profile (os1-128). */
#ifndef LIDET_MAX_ROWS
#define LIDET_MAX_ROWS 128
#endif

/** Maximum range-image columns (azimuth steps per revolution). Range [8, 16384]. Default 2048: the largest
 *  shipped profile (os1-128 and hdl64 at 2048 columns). */
#ifndef LIDET_MAX_COLS
#define LIDET_MAX_COLS 2048
#endif

/** Maximum points per scan; points past it are not processed (status LIDET_TRUNCATED). Range [1, 2^24].
 *  Default 262144: one point per pixel of the default image. */
#ifndef LIDET_MAX_POINTS
#define LIDET_MAX_POINTS 262144
#endif

/** Maximum clusters (proposals before filtering) per scan. Range [1, 65532] (cluster ids are uint16; three
 *  values mark pixel states). Default 1024: a street scene has a few hundred. */
#ifndef LIDET_MAX_CLUSTERS
#define LIDET_MAX_CLUSTERS 1024
#endif

/** Proposal refinement (lidet_refine.c): bird's-eye-view cells of the finer grid one cluster may span
 *  (a cluster needing more is left whole); 2 B per cell, twice (grid and queue). Range [16, 65535] (uint16
 *  cell indices). Default 4096: 7.7 x 7.7 m at the grid's 0.12 m cells. */
#ifndef LIDET_REFINE_MAX_CELLS
#define LIDET_REFINE_MAX_CELLS 4096
#endif

/** Proposal refinement: member pixels of a cluster it examines (more: left whole); 2 B each. Range [1, 2^24].
 *  Default 4096. */
#ifndef LIDET_REFINE_MAX_POINTS
#define LIDET_REFINE_MAX_POINTS 4096
#endif

/** Proposal refinement: connected parts one cluster may have on that grid (more: left whole). Range [2, 65535].
 *  Default 32. */
#ifndef LIDET_REFINE_MAX_PARTS
#define LIDET_REFINE_MAX_PARTS 32
#endif

/** Capacity of points per proposal handed to the PointNets (resampled; the proposal cfg's n_points is at most
 *  this). Range [1, 4096]. Default 128: room for every shipped model (64 points; the small VLP-16 pair 32). */
#ifndef LIDET_PROPOSAL_POINTS
#define LIDET_PROPOSAL_POINTS 128
#endif

/** Hole bridging: the most pixels the clustering searches onward in one direction (cfg max_steps <= this).
 *  Range [1, 64]. Default 16. */
#ifndef LIDET_CLUSTER_MAX_STEPS
#define LIDET_CLUSTER_MAX_STEPS 16
#endif

/** Maximum detections reported per scan. Range [1, LIDET_MAX_CLUSTERS]. Default 128. */
#ifndef LIDET_MAX_DETECTIONS
#define LIDET_MAX_DETECTIONS 128
#endif

/** Tracker (docs/TRACKING.md): the most tracks it holds. Range [1, 1024]. Default 64. */
#ifndef LIDET_TRACK_MAX_TRACKS
#define LIDET_TRACK_MAX_TRACKS 64
#endif

/** Tracker: the most detections one update takes (the rest are counted and dropped); with
 *  LIDET_TRACK_MAX_TRACKS it sizes the assignment's cost matrix. Range [1, 1024]. Default 64. */
#ifndef LIDET_TRACK_MAX_DETS
#define LIDET_TRACK_MAX_DETS 64
#endif

/** Bytes of PointNet scratch in the float detector (lidet_detector_t.pn_scratch; the classifier and the box net
 *  share it); init fails with LIDET_ERR_BUFFER when a model needs more (codegen prints <MODEL>_SCRATCH_BYTES).
 *  Range [64, 2^28], a multiple of 4 (an array of floats). Default 16384: lidet's models need 10-13 KiB. */
#ifndef LIDET_DETECTOR_PN_SCRATCH
#define LIDET_DETECTOR_PN_SCRATCH 16384
#endif

/** Bytes of int8 PointNet scratch in the integer detector (lidet_detector_q_t.pn_scratch, shared by both
 *  models). Range [64, 2^28], a multiple of 4 (an array of int32). Default 12288: lidet's int8 models need
 *  9.8 KiB. */
#ifndef LIDET_DETECTOR_Q_PN_SCRATCH
#define LIDET_DETECTOR_Q_PN_SCRATCH 12288
#endif

/** Entries of the row lookup table of the projection (elevation -> candidate row). Range [16, 65536].
 *  Default 1024. */
#ifndef LIDET_PROJ_ROW_LUT
#define LIDET_PROJ_ROW_LUT 1024
#endif

/** Points per block of the projection's first pass (keys of a block, then lookups, then the
 *  closest-point test); lidet_proj_run() keeps one block's keys on the stack, 28 B per point.
 *  Range [1, 4096]. Default 64. */
#ifndef LIDET_PROJ_BLOCK
#define LIDET_PROJ_BLOCK 64
#endif

/** Points per block of the PointNet forward pass: every shared layer runs on a block of this many
 *  points at a time (two blocks of activations in the scratch, see lidet_pointnet.h). Range [1, 256].
 *  Default 8. */
#ifndef LIDET_PN_BLOCK
#define LIDET_PN_BLOCK 8
#endif

/** Maximum azimuth sectors of the ground stage (one plane each). Range [1, 4096]. Default 256. */
#ifndef LIDET_GROUND_MAX_SECTORS
#define LIDET_GROUND_MAX_SECTORS 256
#endif

/** Maximum ground samples (pixels passing the ground filter) kept per scan; the excess is dropped
 *  (status LIDET_TRUNCATED). Range [3, LIDET_MAX_ROWS * LIDET_MAX_COLS]. The default never truncates (one per
 *  pixel); a small board may halve it. */
#ifndef LIDET_GROUND_MAX_SAMPLES
#define LIDET_GROUND_MAX_SAMPLES (LIDET_MAX_ROWS * LIDET_MAX_COLS)
#endif

/** Scoring subset a RANSAC cell copies into the workspace (12 B each) so that every hypothesis scores
 *  a contiguous block; cells whose subset (eval_samples) is larger score in place, slower, same result.
 *  Range [1, 65536]. Default 256. */
#ifndef LIDET_GROUND_EVAL_MAX
#define LIDET_GROUND_EVAL_MAX 256
#endif

/* ==== memory layout (CMake: the cache variable of the same name); define them the same for the library and
 * its callers: they change the state structs ============================================================= */

/** The integer detector's pixel (lidet_detector_q.h, docs/MEMORY.md): 1 (default) stores x, y, z and the range
 *  (int16 / uint16 in 4 mm steps, 8 B a pixel); 0 stores only the range (2 B a pixel) and the integer stages
 *  decode x, y, z from the pixel's row (the beam's elevation), its column's centre azimuth and the range
 *  (lib/src/internal/lidet_qpix.h). 0 is what fits a VLP-16 integer detector in 256 KiB; exact for a sensor
 *  whose returns lie on their beam's elevation. With 1 the range-only path stays available at run time
 *  (lidet_detector_q_cfg_t.range_only). 0 or 1. */
#ifndef LIDET_Q_PIXEL_XYZ
#define LIDET_Q_PIXEL_XYZ 1
#endif

/** The detector workspace keeps R (the horizontal range, a float per pixel) in its image: the projection
 *  writes it once (from the 4 mm values) and the ground stage reads it, where it otherwise computes it, a square
 *  root per pixel, in its filter and in its label pass. 4 B a pixel (HDL-64 capacities: 512 KiB) for about 2 % of
 *  a VLP-16 scan's projection + ground + clustering (docs/journal/memory.md, "Speed against the stage objects, in
 *  time"). Default: kept on 64-bit targets (hosts and
 *  application processors, whose memory is not the limit) for images of more than 65536 pixels (HDL-64-class
 *  capacities, this project's host builds); not on 32-bit microcontrollers and not at VLP-16 capacities (the
 *  512 KiB budget). The results are the same bits either way. 0 or 1. */
#if (defined(__SIZEOF_POINTER__) && __SIZEOF_POINTER__ >= 8) || defined(_WIN64)
#define LIDET__TARGET_64BIT 1
#else
#define LIDET__TARGET_64BIT 0
#endif
#ifndef LIDET_WORKSPACE_KEEP_R
#define LIDET_WORKSPACE_KEEP_R (LIDET__TARGET_64BIT && LIDET_MAX_ROWS * LIDET_MAX_COLS > 65536L)
#endif

/* ==== build variants ================================================================================== */

/** 1: the integer-only build (docs/FIXED_POINT.md): CMake (option LIDET_FIXED_POINT, OFF) compiles only the
 *  integer sources; the float stages' declarations stay visible but are not built. 0 or 1. Default 0. */
#ifndef LIDET_FIXED_POINT
#define LIDET_FIXED_POINT 0
#endif

/** 1: asserts (LIDET_ASSERT) are compiled in; the port may override LIDET_ASSERT itself. 0 or 1. Default 0:
 *  run() trusts what init validated (the tests build the library with 1 as well). */
#ifndef LIDET_DEBUG
#define LIDET_DEBUG 0
#endif

/** 1: lidet_status_str() returns descriptive strings; 0: it returns "" (saves flash). 0 or 1. Default 1. */
#ifndef LIDET_ENABLE_STATUS_STRINGS
#define LIDET_ENABLE_STATUS_STRINGS 1
#endif

/* ==== per target: kernel forms and instruction-set choices (CMake: the cache variable of the same name,
 * except LIDET_NN_CLONES, LIDET_NN_FMA and LIDET_NN_NEON). The results are the same bits with every value (the
 * FMA and NEON dense kernels excepted); the defaults follow what the compiler says about the target. ========= */

/** 1 on hosts with SIMD (SSE2, AVX2, NEON): the integer kernels keep the loop forms a compiler vectorises (the
 *  inner loop over a row's columns or a layer's channels); 0 on cores without SIMD (Cortex-M, RV32), where the
 *  same kernels keep values in registers or leave early instead. The default of LIDET_GROUND_Q_SQRT_LANES and
 *  LIDET_NN_SIMD, and the clustering's loop form. 0 or 1. */
#ifndef LIDET_HOST_SIMD
#if defined(__SSE2__) || defined(__ARM_NEON) || defined(__ARM_NEON__) || defined(__AVX2__)
#define LIDET_HOST_SIMD 1
#else
#define LIDET_HOST_SIMD 0
#endif
#endif

/** The integer ground stage (lib/src/ground/lidet_ground_filter_q.c): R row by row, 1 = column-wise lanes
 *  (each digit step of the square root over the whole row: a compiler vectorises the column loop on SIMD
 *  hosts), 0 = pixel by pixel with root and remainder in registers (cores without SIMD: fewer loads and
 *  stores); its sample test, 1 = branch-free, 0 = leaving at the first failed condition. 0 or 1. Default
 *  LIDET_HOST_SIMD. */
#ifndef LIDET_GROUND_Q_SQRT_LANES
#define LIDET_GROUND_Q_SQRT_LANES LIDET_HOST_SIMD
#endif

/** The int8 PointNets (lib/src/nn/lidet_nn_s8.c): 1 = the requantization and the int16 layer walk rows then
 *  channels (the inner loop over the channels vectorises), 0 = channel by channel, values in registers (cores
 *  without SIMD; tests/unit/test_nn_s8.c runs both forms). 0 or 1. Default LIDET_HOST_SIMD. */
#ifndef LIDET_NN_SIMD
#define LIDET_NN_SIMD LIDET_HOST_SIMD
#endif

/** 1 on cores with a divide instruction (Cortex-M3 and up, RV32 with M, hosts): the integer square roots use
 *  Newton's iteration there, digit by digit elsewhere (ARMv6-M, RV32 without M: a library division would cost
 *  more than the digits). 0 or 1. Default: from the compiler's target macros. */
#ifndef LIDET_Q_HAVE_DIV
#if (defined(__ARM_ARCH) && !defined(__ARM_FEATURE_IDIV)) || (defined(__riscv) && !defined(__riscv_div))
#define LIDET_Q_HAVE_DIV 0
#else
#define LIDET_Q_HAVE_DIV 1
#endif
#endif

/** 1 on cores with a 32 x 32 -> 64 multiply instruction (not ARMv6-M, not RV32 without M): the integer path may
 *  write 64-bit products of 32-bit values directly there; elsewhere it splits them into 32-bit products. 0 or 1.
 *  Default: from the compiler's target macros. */
#ifndef LIDET_Q_HAVE_MUL64
#if (defined(__ARM_ARCH) && defined(__ARM_ARCH_ISA_THUMB) && __ARM_ARCH_ISA_THUMB == 1) ||                   \
    (defined(__riscv) && !defined(__riscv_mul))
#define LIDET_Q_HAVE_MUL64 0
#else
#define LIDET_Q_HAVE_MUL64 1
#endif
#endif

/** The integer ground stage's band tests (its labelling, the RANSAC's inlier counts and refits): 1 = each point's
 *  32-bit hi part of n . p + D decides first, the exact 64-bit height only for the points near the band's edges
 *  (cores where that height is many instructions: ARMv6-M's split products, RV32's MUL + MULH pairs), 0 = the
 *  exact height for every point (cores with a 64-bit multiply-accumulate, hosts). The same outcome either way
 *  (tests/unit/test_ground_q.c). 0 or 1. Default: 1 where LIDET_Q_HAVE_MUL64 is 0 or on RISC-V, else 0. */
#ifndef LIDET_GROUND_Q_BAND32
#if !LIDET_Q_HAVE_MUL64 || defined(__riscv)
#define LIDET_GROUND_Q_BAND32 1
#else
#define LIDET_GROUND_Q_BAND32 0
#endif
#endif

/* The int8 x int8 accumulation kernels of the integer PointNets, the values of LIDET_NN_S8_KERNEL
 * (lib/src/nn/lidet_nn_s8.c describes each; every one gives the same int32 sums, tests/unit/test_nn_s8.c checks
 * that they agree). */
/** four points share each weight row, output-inner: what host compilers vectorise */
#define LIDET_NN_S8_KERNEL_ROWS4 10
/** the plain output-inner loop (ARMv6-M's former default: 8 low registers, no multiply-accumulate) */
#define LIDET_NN_S8_KERNEL_COLS 11
/** 2 x 2 (points x output channels) accumulators in registers, two multiply-adds per SMLAD: Arm DSP extension */
#define LIDET_NN_S8_KERNEL_DSP 12
/** 2 x 2 accumulators in registers (the former default of 32-bit Arm without the DSP extension, Cortex-M3) */
#define LIDET_NN_S8_KERNEL_R2O2 13
/** 4 x 2 accumulators in registers (RV32's former default) */
#define LIDET_NN_S8_KERNEL_R4O2 14
/** one point at a time over a list of its inputs (those off a ReLU's zero point in layers of several rows), a block
 *  of output channels in registers: cores without the Arm DSP extension, RV32 (16 channels), 32-bit Arm (8),
 *  ARMv6-M (4) */
#define LIDET_NN_S8_KERNEL_LIST 15

/** Which of those lidet__nn_acc_s8 runs (layers with packed weights take the packed kernel instead, see
 *  LIDET_PNQ_WEIGHTS_PK). One of the LIDET_NN_S8_KERNEL_* names above. Default: the one with the fewest
 *  instructions per scan on the target (lib/src/nn/lidet_nn_s8.c counts them per multiply-add): DSP with the Arm
 *  DSP extension, LIST on other 32-bit Arm, ARMv6-M and RISC-V (which skips the inputs at a ReLU's zero point in
 *  layers of 4 rows or more, ARMv6-M 3), ROWS4 elsewhere (hosts).
 *  Any kernel runs on any target (off the DSP cores the DSP one runs a C model of its three instructions). */
#ifndef LIDET_NN_S8_KERNEL
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP
#define LIDET_NN_S8_KERNEL LIDET_NN_S8_KERNEL_DSP
#elif defined(__riscv) || defined(__arm__)
#define LIDET_NN_S8_KERNEL LIDET_NN_S8_KERNEL_LIST
#else
#define LIDET_NN_S8_KERNEL LIDET_NN_S8_KERNEL_ROWS4
#endif
#endif

/** 1: the generated int8 models carry their weights a second time, widened to int16 and packed for the DSP
 *  kernel (lidet_pointnet_q_layer_t.w_pk: about 0.9 instead of 1.6 instructions per multiply-add on a
 *  Cortex-M4 / M7, for three times the weights' flash); 0: the [in][out] int8 weights only. 0 or 1. Default: 1
 *  where the compiler targets the Arm DSP extension, else 0. Define it the same for the library and the
 *  generated models. */
#ifndef LIDET_PNQ_WEIGHTS_PK
#if defined(__ARM_FEATURE_DSP) && __ARM_FEATURE_DSP
#define LIDET_PNQ_WEIGHTS_PK 1
#else
#define LIDET_PNQ_WEIGHTS_PK 0
#endif
#endif

/** 1: the generated int8 models carry, for each shared point layer after the first, the list kernel's starting
 *  sums b - 128 sum w (lidet_pointnet_q_layer_t.b_list: n_out int32 of flash a layer), so that the kernel does not
 *  sum the layer's weights again for every block of points; 0: it does. 0 or 1. Default: 1 where
 *  LIDET_NN_S8_KERNEL is LIDET_NN_S8_KERNEL_LIST, else 0. Define it the same for the library and the generated
 *  models. */
#ifndef LIDET_PNQ_LIST_BIAS
#if LIDET_NN_S8_KERNEL == LIDET_NN_S8_KERNEL_LIST
#define LIDET_PNQ_LIST_BIAS 1
#else
#define LIDET_PNQ_LIST_BIAS 0
#endif
#endif

/** GCC on cores with the Arm DSP extension: 1 runs the packed kernel's inner loops as inline assembly (paired
 *  LDRD loads, the four sums kept in registers: 13 instead of 19 instructions per group), 0 as the C loops the
 *  compiler schedules (same sums). Likewise the list kernel's loops on 32-bit Arm without the DSP extension (21
 *  instead of 24 instructions per 8 multiply-adds) and on ARMv6-M (33 per 8 instead of about 44; optimised builds
 *  but -Os). The loops take nearly every register: a build that keeps a frame pointer (-fno-omit-frame-pointer)
 *  needs 0. No effect on other targets. 0 or 1. Default 1. */
#ifndef LIDET_NN_PK_ASM
#define LIDET_NN_PK_ASM 1
#endif

/** Cortex-M4F / M7 float builds (lib/src/nn/lidet_nn_f32_cm.c): 1 makes the float dense kernel fuse its
 *  multiply-adds (VFMA: the x86-64 FMA and aarch64 NEON kernels' arithmetic, so the same bits as those hosts;
 *  1.25 instructions per multiply-add against 2.3-2.6; its last bits differ from the portable kernel's); 0 keeps the
 *  portable kernel's arithmetic bit for bit (VMUL, VADD). Fewer instructions are not fewer cycles everywhere: the
 *  Cortex-M4 issues a VFMA in 3 cycles against 1 each for VMUL and VADD, the Cortex-M7 one a cycle. No effect on
 *  other targets. 0 or 1. Default 0 (the firmware's Cortex-M7 images set 1). */
#ifndef LIDET_NN_CM_FMA
#define LIDET_NN_CM_FMA 0
#endif

#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define LIDET__TARGET_X86_64_GNU 1
#else
#define LIDET__TARGET_X86_64_GNU 0
#endif

/** x86-64 GCC/clang hosts: 1 also compiles the PointNet kernels for AVX2 and AVX-512 and the compact image's
 *  conversion loops for AVX2, the variant picked when the program loads (lib/src/internal/lidet_simd.h); same
 *  results. CMake option LIDET_NN_CLONES (ON) defines it as 1 on the sources that have such kernels when the
 *  target is x86-64 GCC/clang. 0 or 1; no effect on other targets. Default 0 (a plain compile). */
#ifndef LIDET_NN_CLONES
#define LIDET_NN_CLONES 0
#endif

/** x86-64 GCC/clang hosts: 1 makes the float dense kernel the register-tiled one with fused multiply-adds
 *  (lib/src/nn/lidet_nn_f32_x86.c: AVX-512 or AVX2 + FMA picked at load time, the portable kernel on CPUs without
 *  FMA; about 2x the multiply-adds per second; its last bits differ from the portable kernel's). CMake option
 *  LIDET_NN_FMA (ON) leaves the default; OFF defines it as 0. 0 or 1; 1 only on an x86-64 GCC/clang target (the
 *  kernel's intrinsics exist only there). Default: with the clones (LIDET_NN_CLONES) on such a target. */
#ifndef LIDET_NN_FMA
#define LIDET_NN_FMA (LIDET_NN_CLONES && LIDET__TARGET_X86_64_GNU)
#endif

#if defined(__aarch64__) && defined(__ARM_NEON) && defined(__ARM_FEATURE_FMA)
#define LIDET__TARGET_AARCH64_NEON 1
#else
#define LIDET__TARGET_AARCH64_NEON 0
#endif

/** aarch64 targets (Raspberry Pi 4/5, Jetson, any Armv8-A core): 1 makes the float dense kernel the register-tiled
 *  NEON one with fused multiply-adds (lib/src/nn/lidet_nn_f32_neon.c: the x86-64 FMA kernel's arithmetic, so the
 *  same bits as the x86-64 hosts with FMA; its last bits differ from the portable kernel's); 0 keeps the portable
 *  kernel. CMake option LIDET_NN_NEON (ON) leaves the default; OFF defines it as 0. 0 or 1; 1 only on an aarch64
 *  target with NEON and FMA (the kernel's intrinsics exist only there). Default: 1 on such a target, else 0. */
#ifndef LIDET_NN_NEON
#define LIDET_NN_NEON LIDET__TARGET_AARCH64_NEON
#endif

#if defined(__riscv) && defined(__riscv_flen) && (__riscv_flen >= 32)
#define LIDET__TARGET_RISCV_F 1
#else
#define LIDET__TARGET_RISCV_F 0
#endif

/** RISC-V targets with the F extension (single-precision registers): 1 makes the float dense kernel the one with
 *  fused multiply-adds (lib/src/nn/lidet_nn_f32_rv.c: fmadd.s, the x86-64 FMA kernel's arithmetic, so the same bits
 *  as those hosts; its last bits differ from the portable kernel's); 0 keeps the portable kernel. 0 or 1; 1 only on
 *  such a target. Default: 1 on such a target, else 0. */
#ifndef LIDET_NN_RV_FMA
#define LIDET_NN_RV_FMA LIDET__TARGET_RISCV_F
#endif

/* ==== port hooks (defaults; a port header overrides them) ============================================= */
/* LIDET_ASSERT(c): see lib/src/internal/lidet_assert.h (compiled out unless LIDET_DEBUG). */

/** Alignment of a declaration, e.g. `static lidet_workspace_t ws LIDET_ALIGN(32);`. */
#ifndef LIDET_ALIGN
#if defined(__GNUC__) || defined(__clang__)
#define LIDET_ALIGN(n) __attribute__((aligned(n)))
#else
#define LIDET_ALIGN(n)
#endif
#endif

/** Where the firmware places its detector workspace, e.g. `__attribute__((section(".sdram")))`:
 *  `static lidet_workspace_t ws LIDET_WORKSPACE_SECTION;`. Empty by default (ordinary .bss). */
#ifndef LIDET_WORKSPACE_SECTION
#define LIDET_WORKSPACE_SECTION
#endif

/** Placement of generated constant tables (weights), e.g. a flash section. Empty by default. */
#ifndef LIDET_RODATA
#define LIDET_RODATA
#endif

/* ==== consistency checks (all in one place, in the order of the options) =============================== */
#if LIDET_MAX_ROWS < 1 || LIDET_MAX_ROWS > 256
#error "LIDET_MAX_ROWS must be in [1, 256] (rows are stored as uint8 indices in places)"
#endif
#if LIDET_MAX_COLS < 8 || LIDET_MAX_COLS > 16384
#error "LIDET_MAX_COLS must be in [8, 16384]"
#endif
#if LIDET_MAX_POINTS < 1 || LIDET_MAX_POINTS > 16777216
#error "LIDET_MAX_POINTS must be in [1, 2^24]"
#endif
#if (LIDET_MAX_ROWS * LIDET_MAX_COLS) > 2147483647 / 4
#error "range image too large for int32 pixel indices"
#endif
#if LIDET_MAX_CLUSTERS < 1 || LIDET_MAX_CLUSTERS > 65532
#error "LIDET_MAX_CLUSTERS must be in [1, 65532] (cluster ids are uint16; three values mark pixel states)"
#endif
#if LIDET_REFINE_MAX_CELLS < 16 || LIDET_REFINE_MAX_CELLS > 65535
#error "LIDET_REFINE_MAX_CELLS must be in [16, 65535]"
#endif
#if LIDET_REFINE_MAX_POINTS < 1 || LIDET_REFINE_MAX_POINTS > 16777216
#error "LIDET_REFINE_MAX_POINTS must be in [1, 2^24]"
#endif
#if LIDET_REFINE_MAX_PARTS < 2 || LIDET_REFINE_MAX_PARTS > 65535
#error "LIDET_REFINE_MAX_PARTS must be in [2, 65535]"
#endif
#if LIDET_PROPOSAL_POINTS < 1 || LIDET_PROPOSAL_POINTS > 4096
#error "LIDET_PROPOSAL_POINTS must be in [1, 4096]"
#endif
#if LIDET_CLUSTER_MAX_STEPS < 1 || LIDET_CLUSTER_MAX_STEPS > 64
#error "LIDET_CLUSTER_MAX_STEPS must be in [1, 64]"
#endif
#if LIDET_MAX_DETECTIONS < 1 || LIDET_MAX_DETECTIONS > LIDET_MAX_CLUSTERS
#error "LIDET_MAX_DETECTIONS must be in [1, LIDET_MAX_CLUSTERS]"
#endif
#if LIDET_TRACK_MAX_TRACKS < 1 || LIDET_TRACK_MAX_TRACKS > 1024
#error "LIDET_TRACK_MAX_TRACKS must be in [1, 1024]"
#endif
#if LIDET_TRACK_MAX_DETS < 1 || LIDET_TRACK_MAX_DETS > 1024
#error "LIDET_TRACK_MAX_DETS must be in [1, 1024]"
#endif
#if LIDET_DETECTOR_PN_SCRATCH < 64 || LIDET_DETECTOR_PN_SCRATCH > 268435456 ||                               \
    LIDET_DETECTOR_PN_SCRATCH % 4 != 0
#error "LIDET_DETECTOR_PN_SCRATCH must be a multiple of 4 in [64, 2^28] (bytes)"
#endif
#if LIDET_DETECTOR_Q_PN_SCRATCH < 64 || LIDET_DETECTOR_Q_PN_SCRATCH > 268435456 ||                           \
    LIDET_DETECTOR_Q_PN_SCRATCH % 4 != 0
#error "LIDET_DETECTOR_Q_PN_SCRATCH must be a multiple of 4 in [64, 2^28] (bytes)"
#endif
#if LIDET_PROJ_ROW_LUT < 16 || LIDET_PROJ_ROW_LUT > 65536
#error "LIDET_PROJ_ROW_LUT must be in [16, 65536]"
#endif
#if LIDET_PROJ_BLOCK < 1 || LIDET_PROJ_BLOCK > 4096
#error "LIDET_PROJ_BLOCK must be in [1, 4096]"
#endif
#if LIDET_PN_BLOCK < 1 || LIDET_PN_BLOCK > 256
#error "LIDET_PN_BLOCK must be in [1, 256]"
#endif
#if LIDET_GROUND_MAX_SECTORS < 1 || LIDET_GROUND_MAX_SECTORS > 4096
#error "LIDET_GROUND_MAX_SECTORS must be in [1, 4096]"
#endif
#if LIDET_GROUND_MAX_SAMPLES < 3 || LIDET_GROUND_MAX_SAMPLES > (LIDET_MAX_ROWS * LIDET_MAX_COLS)
#error "LIDET_GROUND_MAX_SAMPLES must be in [3, LIDET_MAX_ROWS * LIDET_MAX_COLS]"
#endif
#if LIDET_GROUND_EVAL_MAX < 1 || LIDET_GROUND_EVAL_MAX > 65536
#error "LIDET_GROUND_EVAL_MAX must be in [1, 65536]"
#endif
#if LIDET_Q_PIXEL_XYZ != 0 && LIDET_Q_PIXEL_XYZ != 1
#error "LIDET_Q_PIXEL_XYZ must be 0 or 1"
#endif
#if LIDET_WORKSPACE_KEEP_R != 0 && LIDET_WORKSPACE_KEEP_R != 1
#error "LIDET_WORKSPACE_KEEP_R must be 0 or 1"
#endif
#if LIDET_FIXED_POINT != 0 && LIDET_FIXED_POINT != 1
#error "LIDET_FIXED_POINT must be 0 or 1"
#endif
#if LIDET_DEBUG != 0 && LIDET_DEBUG != 1
#error "LIDET_DEBUG must be 0 or 1"
#endif
#if LIDET_ENABLE_STATUS_STRINGS != 0 && LIDET_ENABLE_STATUS_STRINGS != 1
#error "LIDET_ENABLE_STATUS_STRINGS must be 0 or 1"
#endif
#if LIDET_HOST_SIMD != 0 && LIDET_HOST_SIMD != 1
#error "LIDET_HOST_SIMD must be 0 or 1"
#endif
#if LIDET_GROUND_Q_SQRT_LANES != 0 && LIDET_GROUND_Q_SQRT_LANES != 1
#error "LIDET_GROUND_Q_SQRT_LANES must be 0 or 1"
#endif
#if LIDET_NN_SIMD != 0 && LIDET_NN_SIMD != 1
#error "LIDET_NN_SIMD must be 0 or 1"
#endif
#if LIDET_Q_HAVE_DIV != 0 && LIDET_Q_HAVE_DIV != 1
#error "LIDET_Q_HAVE_DIV must be 0 or 1"
#endif
#if LIDET_Q_HAVE_MUL64 != 0 && LIDET_Q_HAVE_MUL64 != 1
#error "LIDET_Q_HAVE_MUL64 must be 0 or 1"
#endif
#if LIDET_GROUND_Q_BAND32 != 0 && LIDET_GROUND_Q_BAND32 != 1
#error "LIDET_GROUND_Q_BAND32 must be 0 or 1"
#endif
#if LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_ROWS4 && LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_COLS &&       \
    LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_DSP && LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_R2O2 &&         \
    LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_R4O2 && LIDET_NN_S8_KERNEL != LIDET_NN_S8_KERNEL_LIST
#error "LIDET_NN_S8_KERNEL must be one of LIDET_NN_S8_KERNEL_ROWS4, _COLS, _DSP, _R2O2, _R4O2, _LIST"
#endif
#if LIDET_PNQ_LIST_BIAS != 0 && LIDET_PNQ_LIST_BIAS != 1
#error "LIDET_PNQ_LIST_BIAS must be 0 or 1"
#endif
#if LIDET_PNQ_WEIGHTS_PK != 0 && LIDET_PNQ_WEIGHTS_PK != 1
#error "LIDET_PNQ_WEIGHTS_PK must be 0 or 1"
#endif
#if LIDET_NN_PK_ASM != 0 && LIDET_NN_PK_ASM != 1
#error "LIDET_NN_PK_ASM must be 0 or 1"
#endif
#if LIDET_NN_CM_FMA != 0 && LIDET_NN_CM_FMA != 1
#error "LIDET_NN_CM_FMA must be 0 or 1"
#endif
#if LIDET_NN_RV_FMA != 0 && (LIDET_NN_RV_FMA != 1 || !LIDET__TARGET_RISCV_F)
#error "LIDET_NN_RV_FMA must be 0, or 1 on a RISC-V target with the F extension"
#endif
#if LIDET_NN_CLONES != 0 && LIDET_NN_CLONES != 1
#error "LIDET_NN_CLONES must be 0 or 1"
#endif
#if LIDET_NN_FMA != 0 && (LIDET_NN_FMA != 1 || !LIDET__TARGET_X86_64_GNU)
#error "LIDET_NN_FMA must be 0, or 1 on an x86-64 GCC/clang target"
#endif
#if LIDET_NN_NEON != 0 && (LIDET_NN_NEON != 1 || !LIDET__TARGET_AARCH64_NEON)
#error "LIDET_NN_NEON must be 0, or 1 on an aarch64 target with NEON and FMA"
#endif
#if ((-1) >> 1) != -1
#error "lidet needs arithmetic right shifts of negative integers (the fixed-point build relies on them)"
#endif

#endif /* LIDET_OPT_H */
