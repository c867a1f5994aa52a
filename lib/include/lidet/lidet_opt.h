/* SPDX-License-Identifier: MIT */
/**
 * @file lidet_opt.h
 * @brief Compile-time options of lidet (lwIP style): every capacity of the library.
 *
 * Each option is `#ifndef X / #define X default`. Override them either with `-DX=...` on the compiler
 * command line (CMake cache variables of the same name do that), or in a header named
 * `lidet_user_config.h` on the include path, read when `LIDET_USER_CONFIG` is defined.
 * All consistency checks (`#error`) live at the end of this file, in one place.
 *
 * Memory: every buffer of a stage is a fixed-size array inside its state struct, sized from these
 * options, so the linker reports a RAM overflow instead of the library failing at run time. The
 * byte counts are documented in each stage's header and reported by `lidet_*_bytes()` calls.
 *
 * Defaults fit every shipped sensor profile on a host (os1-128: 128 x 2048 pixels, 262,144 points).
 * A VLP-16 robot board would use e.g. LIDET_MAX_ROWS 16, LIDET_MAX_COLS 1800, LIDET_MAX_POINTS 30000.
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

/** Maximum range-image rows (beams) of any sensor used with this build. */
#ifndef LIDET_MAX_ROWS
#define LIDET_MAX_ROWS 128
#endif

/** Maximum range-image columns (azimuth steps per revolution). */
#ifndef LIDET_MAX_COLS
#define LIDET_MAX_COLS 2048
#endif

/** Maximum points per scan; points past it are not processed (status LIDET_TRUNCATED). */
#ifndef LIDET_MAX_POINTS
#define LIDET_MAX_POINTS 262144
#endif

/** Maximum clusters (proposals before filtering) per scan. */
#ifndef LIDET_MAX_CLUSTERS
#define LIDET_MAX_CLUSTERS 1024
#endif

/** Proposal refinement (lidet_refine.c): bird's-eye-view cells of the finer grid one cluster may span
 *  (a cluster needing more is left whole); 2 B per cell, twice (grid and queue). */
#ifndef LIDET_REFINE_MAX_CELLS
#define LIDET_REFINE_MAX_CELLS 4096
#endif

/** Proposal refinement: member pixels of a cluster it examines (more: left whole); 2 B each. */
#ifndef LIDET_REFINE_MAX_POINTS
#define LIDET_REFINE_MAX_POINTS 4096
#endif

/** Proposal refinement: connected parts one cluster may have on that grid (more: left whole). */
#ifndef LIDET_REFINE_MAX_PARTS
#define LIDET_REFINE_MAX_PARTS 32
#endif

/** Points per proposal handed to the PointNets (resampled). */
#ifndef LIDET_PROPOSAL_POINTS
#define LIDET_PROPOSAL_POINTS 128
#endif

/** Hole bridging: the most pixels the clustering searches onward in one direction (cfg max_steps <= this). */
#ifndef LIDET_CLUSTER_MAX_STEPS
#define LIDET_CLUSTER_MAX_STEPS 16
#endif

/** Maximum detections reported per scan. */
#ifndef LIDET_MAX_DETECTIONS
#define LIDET_MAX_DETECTIONS 128
#endif

/** The integer detector's pixel (lidet_detector_q.h, docs/MEMORY.md): 1 (default) stores x, y, z and the range
 *  (int16 / uint16 in 4 mm steps, 8 B a pixel); 0 stores only the range (2 B a pixel) and the integer stages
 *  decode x, y, z from the pixel's row (the beam's elevation), its column's centre azimuth and the range
 *  (lib/src/internal/lidet_qpix.h). 0 is what fits a VLP-16 integer detector in 256 KiB; exact for a sensor
 *  whose returns lie on their beam's elevation. With 1 the range-only path stays available at run time
 *  (lidet_detector_q_cfg_t.range_only). */
#ifndef LIDET_Q_PIXEL_XYZ
#define LIDET_Q_PIXEL_XYZ 1
#endif

/** The detector workspace keeps R (the horizontal range, a float per pixel) in its image: the projection
 *  writes it once (from the 4 mm values) and the ground stage reads it, where it otherwise computes it, a square
 *  root per pixel, in its filter and in its label pass. 4 B a pixel (HDL-64 capacities: 512 KiB) for about 2 % of
 *  a VLP-16 scan's projection + ground + clustering (docs/MEMORY.md). Default: kept on 64-bit targets (hosts and
 *  application processors, whose memory is not the limit) for images of more than 65536 pixels (HDL-64-class
 *  capacities, this project's host builds); not on 32-bit microcontrollers and not at VLP-16 capacities (the
 *  512 KiB budget). The results are the same bits either way. Define it the same for the library and its
 *  callers (it changes lidet_workspace_t). */
#if (defined(__SIZEOF_POINTER__) && __SIZEOF_POINTER__ >= 8) || defined(_WIN64)
#define LIDET__TARGET_64BIT 1
#else
#define LIDET__TARGET_64BIT 0
#endif
#ifndef LIDET_WORKSPACE_KEEP_R
#define LIDET_WORKSPACE_KEEP_R (LIDET__TARGET_64BIT && LIDET_MAX_ROWS * LIDET_MAX_COLS > 65536L)
#endif

/** Entries of the row lookup table of the projection (elevation -> candidate row). */
#ifndef LIDET_PROJ_ROW_LUT
#define LIDET_PROJ_ROW_LUT 1024
#endif

/** Points per block of the projection's first pass (keys of a block, then lookups, then the
 *  closest-point test); lidet_proj_run() keeps one block's keys on the stack, 28 B per point. */
#ifndef LIDET_PROJ_BLOCK
#define LIDET_PROJ_BLOCK 64
#endif

/** Points per block of the PointNet forward pass: every shared layer runs on a block of this many
 *  points at a time (two blocks of activations in the scratch, see lidet_pointnet.h). */
#ifndef LIDET_PN_BLOCK
#define LIDET_PN_BLOCK 8
#endif

/** Maximum azimuth sectors of the ground stage (one plane each). */
#ifndef LIDET_GROUND_MAX_SECTORS
#define LIDET_GROUND_MAX_SECTORS 256
#endif

/** Maximum ground samples (pixels passing the ground filter) kept per scan; the excess is dropped
 *  (status LIDET_TRUNCATED). The default never truncates (one per pixel); a small board may halve it. */
#ifndef LIDET_GROUND_MAX_SAMPLES
#define LIDET_GROUND_MAX_SAMPLES (LIDET_MAX_ROWS * LIDET_MAX_COLS)
#endif

/** Scoring subset a RANSAC cell copies into the workspace (12 B each) so that every hypothesis scores
 *  a contiguous block; cells whose subset (eval_samples) is larger score in place, slower, same result. */
#ifndef LIDET_GROUND_EVAL_MAX
#define LIDET_GROUND_EVAL_MAX 256
#endif

/** 1: asserts (LIDET_ASSERT) are compiled in; the port may override LIDET_ASSERT itself. */
#ifndef LIDET_DEBUG
#define LIDET_DEBUG 0
#endif

/** 1: lidet_status_str() returns descriptive strings; 0: it returns "" (saves flash). */
#ifndef LIDET_ENABLE_STATUS_STRINGS
#define LIDET_ENABLE_STATUS_STRINGS 1
#endif

/* ---- port hooks (defaults; a port header overrides them) ------------------------------------ */
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

/* ---- consistency checks (all in one place) ------------------------------------------------ */
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
#if LIDET_CLUSTER_MAX_STEPS < 1 || LIDET_CLUSTER_MAX_STEPS > 64
#error "LIDET_CLUSTER_MAX_STEPS must be in [1, 64]"
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
#if LIDET_MAX_DETECTIONS < 1 || LIDET_MAX_DETECTIONS > LIDET_MAX_CLUSTERS
#error "LIDET_MAX_DETECTIONS must be in [1, LIDET_MAX_CLUSTERS]"
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
#if ((-1) >> 1) != -1
#error "lidet needs arithmetic right shifts of negative integers (the fixed-point build relies on them)"
#endif
/* LIDET_FIXED_POINT 1: the integer-only build (docs/FIXED_POINT.md): CMake compiles only the integer sources;
 * the float stages' declarations stay visible but are not built. */
#ifndef LIDET_FIXED_POINT
#define LIDET_FIXED_POINT 0
#endif

#endif /* LIDET_OPT_H */
