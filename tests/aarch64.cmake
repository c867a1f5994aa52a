# SPDX-License-Identifier: MIT
# 64-bit Arm Linux (Raspberry Pi, Jetson): the library, the Unity unit tests and the host CLI cross-built and run
# under qemu-aarch64 (docs/FIRMWARE.md, "Linux on ARM (aarch64)").
#
# - aarch64_linux (ExternalProject, part of the normal build when aarch64-linux-gnu-gcc is installed;
#   tools/scripts/install_deps.sh installs it): this repository configured again in <build>/aarch64 with
#   cmake/toolchains/aarch64-linux-gnu.cmake, building only the targets lidet_unit_tests (every
#   tests/unit/test_*.c) and lidet_cli (without libpng and cJSON, absent from the cross sysroot: the CLI degrades
#   as on a host without them). No fuzz harnesses, benchmarks, firmware or bindings.
# - lidet_cli_portable: the host CLI with the portable float dense kernel, where this build's CLI has the x86
#   FMA kernel (LIDET_NN_FMA, whose last bits differ); the float detector is compared with it.
# - ctest aarch64_linux (tests/aarch64/run_aarch64.py): every unit test under qemu-aarch64 (test_nn_f32 checks the
#   NEON float dense kernel, lib/src/nn/lidet_nn_f32_neon.c, against the portable one), then the aarch64 CLI
#   against the host's on the simulated scans: the integer detector byte for byte; the float one (NEON kernel)
#   byte for byte against this build's CLI where it has the x86 FMA kernel and the host CPU has FMA (the same
#   chain of fused multiply-adds; skipped with a note on other CPUs), and within the firmware comparison's
#   tolerances against the portable build (the report says how many values are bit-identical).
# Without the cross compiler or qemu-aarch64 the test reports itself skipped with the reason. Not in the
# sanitizer build (the same cross build as the normal one) nor in a build that is itself cross or aarch64.
include(ExternalProject)
set(a64_default ON)
if(LIDET_SANITIZE OR CMAKE_CROSSCOMPILING OR CMAKE_SYSTEM_PROCESSOR MATCHES "aarch64|arm64|ARM64")
  set(a64_default OFF)
endif()
option(LIDET_BUILD_AARCH64 "Cross-build the library, unit tests and CLI for aarch64 Linux and run them under qemu-aarch64 (when aarch64-linux-gnu-gcc is installed)"
       ${a64_default})
if(NOT LIDET_BUILD_AARCH64 OR NOT LIDET_BUILD_HOST OR NOT TARGET lidet_cli)
  return()
endif()
find_package(Python3 COMPONENTS Interpreter)
if(NOT Python3_Interpreter_FOUND)
  message(WARNING "python3 not found: the aarch64 test is not registered")
  return()
endif()
set(a64_run ${CMAKE_CURRENT_SOURCE_DIR}/aarch64/run_aarch64.py)
set(LIDET_AARCH64_SYSROOT /usr/aarch64-linux-gnu CACHE PATH "aarch64 glibc sysroot (libc6-dev-arm64-cross)")
find_program(LIDET_AARCH64_CC aarch64-linux-gnu-gcc)
find_program(LIDET_AARCH64_QEMU qemu-aarch64)
if(NOT LIDET_AARCH64_CC)
  add_test(NAME aarch64_linux
           COMMAND ${Python3_EXECUTABLE} ${a64_run}
                   --skip "aarch64-linux-gnu-gcc not found (tools/scripts/install_deps.sh installs gcc-aarch64-linux-gnu)")
  set_tests_properties(aarch64_linux PROPERTIES SKIP_RETURN_CODE 77 SKIP_REGULAR_EXPRESSION "SKIPPED")
  return()
endif()

# the unit tests of tests/unit (their names as lidet_add_unity_test registers them)
set(a64_tests "")
foreach(f ${unit_tests})
  get_filename_component(n ${f} NAME_WE)
  string(REGEX REPLACE "^test_" "" n ${n})
  if(NOT n STREQUAL "util")
    list(APPEND a64_tests ${n})
  endif()
endforeach()
string(REPLACE ";" "," a64_tests "${a64_tests}")

set(a64_bdir ${CMAKE_BINARY_DIR}/aarch64)
if(CMAKE_GENERATOR MATCHES "Makefiles")
  # the parent make's jobs (make -j2 builds it with two jobs in all)
  set(a64_build_cmd $(MAKE) lidet_unit_tests lidet_cli)
else()
  set(a64_build_cmd ${CMAKE_COMMAND} --build <BINARY_DIR> --target lidet_unit_tests lidet_cli -j 2)
endif()
ExternalProject_Add(aarch64_linux
  SOURCE_DIR ${PROJECT_SOURCE_DIR}
  BINARY_DIR ${a64_bdir}
  CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/cmake/toolchains/aarch64-linux-gnu.cmake
             -DCMAKE_BUILD_TYPE=Release -DLIDET_BUILD_TESTS=ON -DLIDET_BUILD_CONSUMER_TESTS=OFF
             -DLIDET_BUILD_FIRMWARE=OFF -DLIDET_BUILD_AARCH64=OFF -DUNITY_ROOT=${UNITY_ROOT}
             -DLIDET_CROSS_SYSROOT=${LIDET_AARCH64_SYSROOT} -DLIDET_NN_NEON=${LIDET_NN_NEON}
             -DPython3_EXECUTABLE=${Python3_EXECUTABLE}
  BUILD_COMMAND ${a64_build_cmd}
  BUILD_ALWAYS ON
  INSTALL_COMMAND ""
  BUILD_BYPRODUCTS ${a64_bdir}/ports/host/lidet)

if(NOT LIDET_AARCH64_QEMU)
  add_test(NAME aarch64_linux
           COMMAND ${Python3_EXECUTABLE} ${a64_run}
                   --skip "qemu-aarch64 not found (tools/scripts/install_deps.sh installs qemu-user)")
  set_tests_properties(aarch64_linux PROPERTIES SKIP_RETURN_CODE 77 SKIP_REGULAR_EXPRESSION "SKIPPED")
  return()
endif()

# the host CLI with the portable float dense kernel (this build's, where it has no FMA kernel)
if(LIDET_NN_CLONES AND LIDET_NN_FMA AND CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64"
   AND CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
  lidet_add_cli_copy(lidet_cli_portable)
  # the library's numerics; LIDET_NN_CLONES and LIDET_NN_FMA keep lidet_opt.h's default 0: portable kernels
  target_compile_options(lidet_cli_portable PRIVATE -fno-math-errno -ffp-contract=off)
  set(a64_portable $<TARGET_FILE:lidet_cli_portable>)
  # this build's CLI has the x86 FMA kernel: the aarch64 float dumps (NEON kernel) must equal its own byte for byte
  if(LIDET_NN_NEON)
    set(a64_fma --host-cli-fma $<TARGET_FILE:lidet_cli>)
  else()
    set(a64_fma "")
  endif()
else()
  set(a64_portable $<TARGET_FILE:lidet_cli>)
  set(a64_fma "")
endif()

add_test(NAME aarch64_linux
         COMMAND ${Python3_EXECUTABLE} ${a64_run} --build ${a64_bdir} --tests ${a64_tests} --src ${PROJECT_SOURCE_DIR}
                 --host-cli $<TARGET_FILE:lidet_cli> --host-cli-portable ${a64_portable} ${a64_fma}
                 --qemu ${LIDET_AARCH64_QEMU} --sysroot ${LIDET_AARCH64_SYSROOT})
set_tests_properties(aarch64_linux PROPERTIES SKIP_RETURN_CODE 77 SKIP_REGULAR_EXPRESSION "SKIPPED" TIMEOUT 900
                                              LABELS aarch64)
