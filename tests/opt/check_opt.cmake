# SPDX-License-Identifier: MIT
# The #error checks of lib/include/lidet/lidet_opt.h bite: every public header (tests/opt/opt_probe.c) compiled
# with one option out of range at a time must fail with that option's message; compiled with the defaults and
# with valid values it must succeed, in C and (when CXX is given) in C++; the int8 kernel file compiles with each
# kernel name of LIDET_NN_S8_KERNEL and refuses the old numbers. tests/python/test_opt_knobs.py checks that every
# option of lidet_opt.h has a case here.
#   cmake -DCC=<C compiler> [-DCXX=<C++ compiler>] -DSRC=<repository> -P tests/opt/check_opt.cmake
set(probe ${SRC}/tests/opt/opt_probe.c)
set(kernel ${SRC}/lib/src/nn/lidet_nn_s8.c)
set(failures "")
set(n_cases 0)

# one compile: expect "OK" or a substring of the error it must fail with
function(opt_case expect compiler std file)
  math(EXPR n "${n_cases} + 1")
  set(n_cases ${n} PARENT_SCOPE)
  execute_process(COMMAND ${compiler} ${std} -fsyntax-only -Wall -Wextra -Werror -pedantic -I${SRC}/lib/include
                          -I${SRC}/lib/src ${ARGN} ${file}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REPLACE ";" " " std "${std}")
  if(expect STREQUAL "OK")
    if(NOT rc EQUAL 0)
      set(failures "${failures}\n  ${std} ${ARGN}: should compile, failed:\n${err}" PARENT_SCOPE)
    endif()
  else()
    string(FIND "${err}" "${expect}" at)
    if(rc EQUAL 0)
      set(failures "${failures}\n  ${std} ${ARGN}: should fail with '${expect}', compiled" PARENT_SCOPE)
    elseif(at EQUAL -1)
      set(failures "${failures}\n  ${std} ${ARGN}: should fail with '${expect}', failed with:\n${err}" PARENT_SCOPE)
    endif()
  endif()
endfunction()

set(c_std -x c -std=c99)
# option=bad value | the start of its #error message
set(bad_cases
    "LIDET_MAX_ROWS=0|LIDET_MAX_ROWS must be in"
    "LIDET_MAX_ROWS=257|LIDET_MAX_ROWS must be in"
    "LIDET_MAX_COLS=4|LIDET_MAX_COLS must be in"
    "LIDET_MAX_POINTS=0|LIDET_MAX_POINTS must be in"
    "LIDET_MAX_CLUSTERS=65533|LIDET_MAX_CLUSTERS must be in"
    "LIDET_REFINE_MAX_CELLS=8|LIDET_REFINE_MAX_CELLS must be in"
    "LIDET_REFINE_MAX_POINTS=0|LIDET_REFINE_MAX_POINTS must be in"
    "LIDET_REFINE_MAX_PARTS=1|LIDET_REFINE_MAX_PARTS must be in"
    "LIDET_PROPOSAL_POINTS=4097|LIDET_PROPOSAL_POINTS must be in"
    "LIDET_CLUSTER_MAX_STEPS=65|LIDET_CLUSTER_MAX_STEPS must be in"
    "LIDET_MAX_DETECTIONS=1025|LIDET_MAX_DETECTIONS must be in"
    "LIDET_TRACK_MAX_TRACKS=0|LIDET_TRACK_MAX_TRACKS must be in"
    "LIDET_TRACK_MAX_DETS=1025|LIDET_TRACK_MAX_DETS must be in"
    "LIDET_DETECTOR_PN_SCRATCH=16386|LIDET_DETECTOR_PN_SCRATCH must be a multiple of 4"
    "LIDET_DETECTOR_PN_SCRATCH=32|LIDET_DETECTOR_PN_SCRATCH must be a multiple of 4"
    "LIDET_DETECTOR_Q_PN_SCRATCH=12290|LIDET_DETECTOR_Q_PN_SCRATCH must be a multiple of 4"
    "LIDET_PROJ_ROW_LUT=8|LIDET_PROJ_ROW_LUT must be in"
    "LIDET_PROJ_BLOCK=0|LIDET_PROJ_BLOCK must be in"
    "LIDET_PN_BLOCK=257|LIDET_PN_BLOCK must be in"
    "LIDET_GROUND_MAX_SECTORS=0|LIDET_GROUND_MAX_SECTORS must be in"
    "LIDET_GROUND_MAX_SAMPLES=2|LIDET_GROUND_MAX_SAMPLES must be in"
    "LIDET_GROUND_EVAL_MAX=0|LIDET_GROUND_EVAL_MAX must be in"
    "LIDET_Q_PIXEL_XYZ=2|LIDET_Q_PIXEL_XYZ must be 0 or 1"
    "LIDET_WORKSPACE_KEEP_R=2|LIDET_WORKSPACE_KEEP_R must be 0 or 1"
    "LIDET_FIXED_POINT=2|LIDET_FIXED_POINT must be 0 or 1"
    "LIDET_DEBUG=2|LIDET_DEBUG must be 0 or 1"
    "LIDET_ENABLE_STATUS_STRINGS=-1|LIDET_ENABLE_STATUS_STRINGS must be 0 or 1"
    "LIDET_HOST_SIMD=2|LIDET_HOST_SIMD must be 0 or 1"
    "LIDET_GROUND_Q_SQRT_LANES=2|LIDET_GROUND_Q_SQRT_LANES must be 0 or 1"
    "LIDET_NN_SIMD=2|LIDET_NN_SIMD must be 0 or 1"
    "LIDET_Q_HAVE_DIV=2|LIDET_Q_HAVE_DIV must be 0 or 1"
    "LIDET_Q_HAVE_MUL64=2|LIDET_Q_HAVE_MUL64 must be 0 or 1"
    "LIDET_GROUND_Q_BAND32=2|LIDET_GROUND_Q_BAND32 must be 0 or 1"
    # the kernel variants are names: a number (the values 0, 1, 2, 22, 42 the names replaced included) or an
    # unknown word is refused
    "LIDET_NN_S8_KERNEL=0|LIDET_NN_S8_KERNEL must be one of"
    "LIDET_NN_S8_KERNEL=2|LIDET_NN_S8_KERNEL must be one of"
    "LIDET_NN_S8_KERNEL=42|LIDET_NN_S8_KERNEL must be one of"
    "LIDET_NN_S8_KERNEL=DSP|LIDET_NN_S8_KERNEL must be one of"
    "LIDET_PNQ_WEIGHTS_PK=2|LIDET_PNQ_WEIGHTS_PK must be 0 or 1"
    "LIDET_PNQ_LIST_BIAS=2|LIDET_PNQ_LIST_BIAS must be 0 or 1"
    "LIDET_NN_PK_ASM=2|LIDET_NN_PK_ASM must be 0 or 1"
    "LIDET_NN_CM_FMA=2|LIDET_NN_CM_FMA must be 0 or 1"
    "LIDET_NN_RV_FMA=1|LIDET_NN_RV_FMA must be 0, or 1 on a RISC-V target"
    "LIDET_NN_CLONES=2|LIDET_NN_CLONES must be 0 or 1"
    "LIDET_NN_FMA=2|LIDET_NN_FMA must be 0, or 1"
    "LIDET_NN_NEON=2|LIDET_NN_NEON must be 0, or 1")
foreach(entry IN LISTS bad_cases)
  string(REPLACE "|" ";" f "${entry}")
  list(GET f 0 def)
  list(GET f 1 msg)
  opt_case("${msg}" ${CC} "${c_std}" ${probe} -D${def})
endforeach()

# valid values compile: the defaults, the ends of ranges, the VLP-16 board's capacities, each kernel name
opt_case(OK ${CC} "${c_std}" ${probe})
opt_case(OK ${CC} "${c_std}" ${probe} -DLIDET_MAX_ROWS=16 -DLIDET_MAX_COLS=1800 -DLIDET_MAX_POINTS=30000
         -DLIDET_MAX_CLUSTERS=64 -DLIDET_MAX_DETECTIONS=64 -DLIDET_Q_PIXEL_XYZ=0 -DLIDET_DETECTOR_PN_SCRATCH=64
         -DLIDET_DETECTOR_Q_PN_SCRATCH=268435456 -DLIDET_DEBUG=1 -DLIDET_ENABLE_STATUS_STRINGS=0
         -DLIDET_PNQ_WEIGHTS_PK=1 -DLIDET_NN_PK_ASM=0 -DLIDET_HOST_SIMD=0 -DLIDET_Q_HAVE_DIV=0 -DLIDET_Q_HAVE_MUL64=0)
foreach(k ROWS4 COLS DSP R2O2 R4O2 LIST)
  opt_case(OK ${CC} "${c_std}" ${kernel} -DLIDET_NN_S8_KERNEL=LIDET_NN_S8_KERNEL_${k})
endforeach()
opt_case(OK ${CC} "${c_std}" ${kernel} -DLIDET_NN_SIMD=0 -DLIDET_NN_PK_ASM=0)
# off x86-64 GCC/clang (a freestanding compile with __x86_64__ undefined stands in for another target) the FMA
# kernel cannot be built: LIDET_NN_FMA=1 is refused; LIDET_NN_CLONES=1 has no effect there and compiles
opt_case("LIDET_NN_FMA must be 0, or 1 on an x86-64" ${CC} "${c_std}" ${probe} -ffreestanding -U__x86_64__
         -DLIDET_NN_FMA=1)
opt_case(OK ${CC} "${c_std}" ${SRC}/lib/src/nn/lidet_nn_f32.c -ffreestanding -U__x86_64__ -DLIDET_NN_CLONES=1)
# the NEON kernel exists only on aarch64: LIDET_NN_NEON=1 is refused on any other target (this compiler's, unless it
# targets aarch64 itself), and the kernel's file is an empty unit there
execute_process(COMMAND ${CC} -dumpmachine OUTPUT_VARIABLE cc_target ERROR_QUIET)
if(NOT cc_target MATCHES "^(aarch64|arm64)")
  opt_case("LIDET_NN_NEON must be 0, or 1 on an aarch64" ${CC} "${c_std}" ${probe} -DLIDET_NN_NEON=1)
endif()
opt_case(OK ${CC} "${c_std}" ${SRC}/lib/src/nn/lidet_nn_f32_neon.c)
if(NOT "${CXX}" STREQUAL "")
  opt_case(OK ${CXX} "-x;c++;-std=c++11" ${probe})
  opt_case(OK ${CXX} "-x;c++;-std=c++11" ${probe} -DLIDET_MAX_ROWS=16 -DLIDET_MAX_COLS=1800 -DLIDET_Q_PIXEL_XYZ=0
           -DLIDET_NN_S8_KERNEL=LIDET_NN_S8_KERNEL_COLS)
  opt_case("LIDET_NN_S8_KERNEL must be one of" ${CXX} "-x;c++;-std=c++11" ${probe} -DLIDET_NN_S8_KERNEL=1)
endif()

if(NOT "${failures}" STREQUAL "")
  message(FATAL_ERROR "lidet_opt.h checks:${failures}")
endif()
message(STATUS "lidet_opt.h checks: ${n_cases} compiles as expected")
