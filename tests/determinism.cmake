# SPDX-License-Identifier: MIT
# Determinism across builds (issue 19): two CLIs (e.g. this build's and the -O0 one, or the Release and the
# sanitizer build's) must write byte-identical results on the shipped simulated scans: per-point outputs of
# project / ground / cluster (--out) and every detector result (detect --dump: per-point labels, clusters,
# proposals, detections).
# Usage: cmake -DA=cli_a -DB=cli_b -DSRC=<repo> -DWORK=<dir> -P determinism.cmake
file(MAKE_DIRECTORY ${WORK})
set(n_compared 0)
foreach(sensor hdl64 vlp16)
  set(scan ${SRC}/tests/data/sim_${sensor}/velodyne/000000.bin)
  foreach(cmd detect cluster ground project)
    if(cmd STREQUAL "detect")
      set(opt --dump)
    else()
      set(opt --out)
    endif()
    foreach(side A B)
      execute_process(COMMAND ${${side}} ${cmd} ${scan} --sensor ${sensor} ${opt} ${WORK}/${sensor}_${cmd}_${side}.bin
                      RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "${${side}} ${cmd} ${scan} failed (${rc}): ${err}")
      endif()
    endforeach()
    execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/${sensor}_${cmd}_A.bin ${WORK}/${sensor}_${cmd}_B.bin
                    RESULT_VARIABLE same)
    if(NOT same EQUAL 0)
      message(FATAL_ERROR "${sensor} ${cmd}: ${A} and ${B} write different bytes (${WORK}/${sensor}_${cmd}_[AB].bin)")
    endif()
    math(EXPR n_compared "${n_compared} + 1")
  endforeach()
endforeach()
message(STATUS "determinism: ${n_compared} outputs byte-identical between ${A} and ${B}")
