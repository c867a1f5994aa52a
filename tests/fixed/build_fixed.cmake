# SPDX-License-Identifier: MIT
# ctest fixed_point_build: configure and build the integer-only library (-DLIDET_FIXED_POINT=ON) from scratch
# in BIN with the host compiler, with its own checks. Run: cmake -DSRC=<repo> -DBIN=<dir> -P build_fixed.cmake
file(REMOVE_RECURSE ${BIN})
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SRC} -B ${BIN} -DCMAKE_BUILD_TYPE=Release -DLIDET_FIXED_POINT=ON
                        -DLIDET_BUILD_TESTS=OFF RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the integer-only build failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BIN} -j 2 RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the integer-only build failed")
endif()
file(GLOB lib ${BIN}/liblidet.a)
if(NOT lib)
  message(FATAL_ERROR "the integer-only build made no liblidet.a")
endif()
message(STATUS "integer-only build OK: ${lib}")
