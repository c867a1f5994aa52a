# SPDX-License-Identifier: MIT
# The compile-time options of lib/include/lidet/lidet_opt.h as CMake cache variables of the same names (STRING,
# empty = the header's default), read by the main CMakeLists.txt and by ports/firmware/CMakeLists.txt.
# docs/OPTIONS.md ("Every compile-time option") lists them with their defaults and ranges; lidet_opt.h checks each
# value (#error), so a bad one fails the first compile. Four options are CMake options (ON/OFF) instead, because
# they also choose sources or per-source flags: LIDET_FIXED_POINT, LIDET_NN_CLONES, LIDET_NN_FMA, LIDET_NN_NEON.
# tests/python/test_opt_knobs.py holds this list, lidet_opt.h and the docs to each other.
#
#   cmake -S . -B build -DLIDET_MAX_POINTS=30000 -DLIDET_NN_S8_KERNEL=LIDET_NN_S8_KERNEL_COLS

# capacities: sizes of the state structs
set(LIDET_CAPACITY_OPTIONS
    LIDET_MAX_ROWS LIDET_MAX_COLS LIDET_MAX_POINTS LIDET_MAX_CLUSTERS LIDET_REFINE_MAX_CELLS LIDET_REFINE_MAX_POINTS
    LIDET_REFINE_MAX_PARTS LIDET_PROPOSAL_POINTS LIDET_CLUSTER_MAX_STEPS LIDET_MAX_DETECTIONS LIDET_TRACK_MAX_TRACKS LIDET_TRACK_MAX_DETS LIDET_DETECTOR_PN_SCRATCH
    LIDET_DETECTOR_Q_PN_SCRATCH LIDET_PROJ_ROW_LUT LIDET_PROJ_BLOCK LIDET_PN_BLOCK LIDET_GROUND_MAX_SECTORS
    LIDET_GROUND_MAX_SAMPLES LIDET_GROUND_EVAL_MAX)
# memory layout and build variants (0 or 1)
set(LIDET_LAYOUT_OPTIONS LIDET_Q_PIXEL_XYZ LIDET_WORKSPACE_KEEP_R LIDET_DEBUG LIDET_ENABLE_STATUS_STRINGS)
# per target: kernel forms and instruction-set choices (the same results with every value, but LIDET_NN_CM_FMA and
# LIDET_NN_RV_FMA: the Cortex-M and RISC-V float dense kernels' fused arithmetic, that of the x86-64 FMA and aarch64
# NEON kernels)
set(LIDET_TARGET_OPTIONS
    LIDET_HOST_SIMD LIDET_GROUND_Q_SQRT_LANES LIDET_NN_SIMD LIDET_Q_HAVE_DIV LIDET_Q_HAVE_MUL64 LIDET_GROUND_Q_BAND32
    LIDET_NN_S8_KERNEL
    LIDET_PNQ_WEIGHTS_PK LIDET_PNQ_LIST_BIAS LIDET_NN_PK_ASM LIDET_NN_CM_FMA LIDET_NN_RV_FMA)
set(LIDET_OPT_OPTIONS ${LIDET_CAPACITY_OPTIONS} ${LIDET_LAYOUT_OPTIONS} ${LIDET_TARGET_OPTIONS})

foreach(opt IN LISTS LIDET_OPT_OPTIONS)
  set(${opt} "" CACHE STRING "Override ${opt} of lidet_opt.h (empty: its default; docs/OPTIONS.md)")
endforeach()
set_property(CACHE LIDET_NN_S8_KERNEL PROPERTY STRINGS "" LIDET_NN_S8_KERNEL_ROWS4 LIDET_NN_S8_KERNEL_COLS
             LIDET_NN_S8_KERNEL_DSP LIDET_NN_S8_KERNEL_R2O2 LIDET_NN_S8_KERNEL_R4O2
             LIDET_NN_S8_KERNEL_LIST)

# lidet_opt_definitions(<target> <PUBLIC|PRIVATE|INTERFACE>): -D<option>=<value> for every option set in the cache
function(lidet_opt_definitions target scope)
  foreach(opt IN LISTS LIDET_OPT_OPTIONS)
    if(NOT "${${opt}}" STREQUAL "")
      target_compile_definitions(${target} ${scope} ${opt}=${${opt}})
    endif()
  endforeach()
endfunction()
