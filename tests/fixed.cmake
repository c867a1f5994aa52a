# SPDX-License-Identifier: MIT
# The integer-only build (issue 16, docs/FIXED_POINT.md):
# - fixed_point_build: the library configures and builds with -DLIDET_FIXED_POINT=ON (host compiler);
# - nofloat_<target>: tools/firmware/check_nofloat.py compiles the integer-only sources (LIDET_FIXED_SOURCES) for
#   Cortex-M0+ and RV32IMAC (no FPU: any float becomes a soft-float call, which nm finds) and for Cortex-M4F and
#   RV32IMAFC (with FPU: any float becomes an FPU instruction, which objdump finds), and fails on any finding;
# - nofloat_<target>_planted: the same with tests/fixed/plant_float.c added must find it (the check bites).
# A target whose cross compiler is missing is reported as skipped (tools/scripts/install_deps.sh installs them).
find_package(Python3 COMPONENTS Interpreter)
if(NOT LIDET_FIXED_POINT)
  add_test(NAME fixed_point_build
           COMMAND ${CMAKE_COMMAND} -DSRC=${PROJECT_SOURCE_DIR} -DBIN=${CMAKE_CURRENT_BINARY_DIR}/fixed_point_probe
                   -P ${CMAKE_CURRENT_SOURCE_DIR}/fixed/build_fixed.cmake)
endif()
if(NOT Python3_Interpreter_FOUND)
  message(WARNING "python3 not found: the no-float checks of the integer-only build are not registered")
  return()
endif()
set(nofloat_args -I ${PROJECT_SOURCE_DIR}/lib/include -I ${PROJECT_SOURCE_DIR}/lib/src -D LIDET_FIXED_POINT=1)
foreach(entry "cortex-m0plus|arm-none-eabi-gcc" "cortex-m4f|arm-none-eabi-gcc" "rv32imac|riscv64-unknown-elf-gcc"
              "rv32imafc|riscv64-unknown-elf-gcc")
  string(REPLACE "|" ";" f "${entry}")
  list(GET f 0 target)
  list(GET f 1 cc)
  find_program(nofloat_cc_${target} ${cc})
  if(nofloat_cc_${target})
    add_test(NAME nofloat_${target}
             COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/check_nofloat.py --target ${target}
                     --sources "${LIDET_FIXED_SOURCES}" ${nofloat_args})
    add_test(NAME nofloat_${target}_planted
             COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/check_nofloat.py --target ${target}
                     --sources "${LIDET_FIXED_SOURCES};${CMAKE_CURRENT_SOURCE_DIR}/fixed/plant_float.c"
                     --expect-float ${nofloat_args})
  else()
    add_test(NAME nofloat_${target} COMMAND ${CMAKE_COMMAND} -E echo "SKIPPED: ${cc} not installed")
    set_tests_properties(nofloat_${target} PROPERTIES SKIP_REGULAR_EXPRESSION "SKIPPED")
  endif()
endforeach()
