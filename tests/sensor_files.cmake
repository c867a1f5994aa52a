# SPDX-License-Identifier: MIT
# The CLI's sensor files (--sensor-file, --ouster-meta, --print-sensor; ports/host/cli_sensor.c, docs/SENSORS.md),
# without Python: a description repeating a preset's table detects bit for bit as the preset; --print-sensor
# writes a description that reads back to the same print; bad files exit 1 with a message naming the field;
# Ouster's metadata files of ../shared/data/packets load (when that folder is there); a CLI built without cJSON
# says so. Velodyne calibrations (--velodyne-calib, cli_velodyne_calib.c): the hand-made VLP-16 calibrations (XML and
# YAML) detect bit for bit as the vlp16 preset, bad ones are refused, a CLI built without libxml2 / libyaml says so.
# (tests/python/test_sensor_files.py and test_velodyne_calib.py compare the CLI with the Python loaders message for
# message.)
# Usage: cmake -DCLI=lidet [-DNOJSON=lidet_without_cjson_libxml2_libyaml] -DHAVE_CJSON=ON|OFF -DHAVE_LIBXML2=ON|OFF
#        -DHAVE_LIBYAML=ON|OFF -DSRC=<repo> -DWORK=<dir> -P sensor_files.cmake
cmake_policy(SET CMP0054 NEW) # if(x STREQUAL "preset"): a quoted string, never a variable
file(MAKE_DIRECTORY ${WORK})
set(data ${SRC}/tests/data/sensors)

function(expect_error cli option file pattern)
  execute_process(COMMAND ${cli} project ${option} ${file} --print-sensor
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 1 OR NOT out STREQUAL "" OR NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "${cli} project ${option} ${file}: expected exit 1 and '${pattern}', got ${rc}: ${err}")
  endif()
endfunction()

if(NOJSON)
  expect_error(${NOJSON} --sensor-file ${data}/vlp16.json "--sensor-file needs cJSON, and this lidet was built without it")
  expect_error(${NOJSON} --ouster-meta ${data}/ouster_nested.json "--ouster-meta needs cJSON")
  expect_error(${NOJSON} --velodyne-calib ${data}/vlp16_db.xml
               "--velodyne-calib needs libxml2 to read this XML calibration, and this lidet was built without it")
  expect_error(${NOJSON} --velodyne-calib ${data}/vlp16.yaml
               "--velodyne-calib needs libyaml to read this YAML calibration, and this lidet was built without it")
endif()

# ---- Velodyne calibrations (need neither cJSON nor Python) ----
set(n_calib 0)
foreach(calib vlp16_db.xml vlp16.yaml)
  if(calib MATCHES "xml$")
    set(have ${HAVE_LIBXML2})
    set(lib libxml2)
  else()
    set(have ${HAVE_LIBYAML})
    set(lib libyaml)
  endif()
  if(NOT have)
    expect_error(${CLI} --velodyne-calib ${data}/${calib} "needs ${lib} .* built without it")
    message(STATUS "lidet was built without ${lib}: ${calib} refused, saying so")
    continue()
  endif()
  # the hand-made VLP-16 calibration (lasers in firing order, the preset's elevations) at the preset's mount height
  set(scan ${SRC}/tests/data/sim_vlp16/velodyne/000000.bin)
  foreach(side preset calib)
    if(side STREQUAL "preset")
      set(opt --sensor vlp16)
    else()
      set(opt --velodyne-calib ${data}/${calib} --mount-height 0.5)
    endif()
    execute_process(COMMAND ${CLI} detect ${scan} ${opt} --ring ${SRC}/tests/data/sim_vlp16/ring/000000.bin
                            --dump ${WORK}/${calib}_${side}.bin
                    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${CLI} detect ${scan} ${opt} failed (${rc}): ${err}")
    endif()
  endforeach()
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/${calib}_preset.bin ${WORK}/${calib}_calib.bin
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "detect --velodyne-calib ${data}/${calib} differs from --sensor vlp16 "
                        "(${WORK}/${calib}_[preset|calib].bin)")
  endif()
  execute_process(COMMAND ${CLI} project --velodyne-calib ${data}/${calib} --print-sensor
                  RESULT_VARIABLE rc OUTPUT_VARIABLE printed ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT printed MATCHES "\"name\": \"velodyne-16\",\n  \"cols\": 1800,\n  \"beam_elevation_deg\": \\[-1[45]")
    message(FATAL_ERROR "${CLI} project --velodyne-calib ${data}/${calib} --print-sensor (${rc}): ${err}${printed}")
  endif()
  math(EXPR n_calib "${n_calib} + 1")
endforeach()
if(HAVE_LIBXML2)
  file(WRITE ${WORK}/bad_calib.xml "<boost_serialization><DB><points_><item><px><id_>0</id_><rotCorrection_>0"
                                   "</rotCorrection_><vertCorrection_>95</vertCorrection_></px></item></points_></DB>"
                                   "</boost_serialization>")
  expect_error(${CLI} --velodyne-calib ${WORK}/bad_calib.xml
               "bad_calib.xml: \"points_\"\\[0\\].vertCorrection_: 95 deg is outside \\(-90, 90\\)")
  file(WRITE ${WORK}/entity_calib.xml "<!DOCTYPE b [<!ENTITY a \"x\">]><boost_serialization/>")
  expect_error(${CLI} --velodyne-calib ${WORK}/entity_calib.xml "entity declarations are refused")
endif()
if(HAVE_LIBYAML)
  file(WRITE ${WORK}/bad_calib.yaml "num_lasers: 2\nlasers:\n  - {laser_id: 0, rot_correction: 0, vert_correction: 0}\n")
  expect_error(${CLI} --velodyne-calib ${WORK}/bad_calib.yaml "\"num_lasers\": 2 but \"lasers\" has 1 entries")
  file(WRITE ${WORK}/alias_calib.yaml "a: &x 1\nb: *x\n")
  expect_error(${CLI} --velodyne-calib ${WORK}/alias_calib.yaml "YAML aliases are not supported \\(line 2\\)")
endif()
message(STATUS "Velodyne calibrations: ${n_calib} detected bit for bit as the vlp16 preset")
if(NOT HAVE_CJSON)
  expect_error(${CLI} --sensor-file ${data}/vlp16.json "built without it")
  message(STATUS "SKIPPED: lidet was built without cJSON (apt-get install libcjson-dev): its error checked only")
  return()
endif()

# a description repeating a preset's table: the same bytes as the preset in every detector result (--dump)
foreach(preset hdl64 vlp16)
  set(scan ${SRC}/tests/data/sim_${preset}/velodyne/000000.bin)
  foreach(side preset file)
    if(side STREQUAL "preset")
      set(opt --sensor ${preset})
    else()
      set(opt --sensor-file ${data}/${preset}.json)
    endif()
    execute_process(COMMAND ${CLI} detect ${scan} ${opt} --dump ${WORK}/${preset}_${side}.bin
                    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${CLI} detect ${scan} ${opt} failed (${rc}): ${err}")
    endif()
  endforeach()
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/${preset}_preset.bin ${WORK}/${preset}_file.bin
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "detect --sensor-file ${data}/${preset}.json differs from --sensor ${preset} "
                        "(${WORK}/${preset}_[preset|file].bin)")
  endif()
endforeach()

# --print-sensor of every file, then of what it printed: the same text (what the CLI read, written back whole)
set(files --sensor-file ${data}/hdl64.json --sensor-file ${data}/vlp16.json --sensor-file ${data}/uniform32.json
          --ouster-meta ${data}/ouster_nested.json)
file(GLOB shared_meta ${SRC}/../shared/data/packets/ouster/*.json)
list(FILTER shared_meta EXCLUDE REGEX "_digest\\.json$")
foreach(f ${shared_meta})
  list(APPEND files --ouster-meta ${f})
endforeach()
list(LENGTH files n)
math(EXPR last "${n} - 1")
set(n_files 0)
foreach(i RANGE 0 ${last} 2)
  math(EXPR j "${i} + 1")
  list(GET files ${i} option)
  list(GET files ${j} f)
  get_filename_component(stem ${f} NAME_WE)
  execute_process(COMMAND ${CLI} project ${option} ${f} --print-sensor
                  RESULT_VARIABLE rc OUTPUT_VARIABLE first ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT first MATCHES "\"format\": \"lidet-sensor\"")
    message(FATAL_ERROR "${CLI} project ${option} ${f} --print-sensor failed (${rc}): ${err}")
  endif()
  file(WRITE ${WORK}/${stem}_printed.json "${first}")
  execute_process(COMMAND ${CLI} project --sensor-file ${WORK}/${stem}_printed.json --print-sensor
                  RESULT_VARIABLE rc OUTPUT_VARIABLE second ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT first STREQUAL second)
    message(FATAL_ERROR "${WORK}/${stem}_printed.json does not print back the same (${rc}): ${err}\n${second}")
  endif()
  math(EXPR n_files "${n_files} + 1")
endforeach()

# bad files: exit 1, one line naming the file and the field
file(WRITE ${WORK}/bad_cols.json
     "{\"format\": \"lidet-sensor\", \"version\": 1, \"name\": \"x\", \"cols\": 4, \"rows\": 4, \"fov_up_deg\": 2, "
     "\"fov_down_deg\": -2, \"mount_height_m\": 1, \"max_range_m\": 100}")
expect_error(${CLI} --sensor-file ${WORK}/bad_cols.json "bad_cols.json: \"cols\": 4 is outside \\[8, [0-9]+\\] \\(LIDET_MAX_COLS\\)")
file(WRITE ${WORK}/bad_beams.json
     "{\"format\": \"lidet-sensor\", \"version\": 1, \"name\": \"x\", \"cols\": 64, "
     "\"beam_elevation_deg\": [1, 0, 1], \"mount_height_m\": 1, \"max_range_m\": 100}")
expect_error(${CLI} --sensor-file ${WORK}/bad_beams.json
             "\"beam_elevation_deg\"\\[2\\]: the same elevation as \\[0\\] \\(1 deg\\): beams must be distinct")
file(WRITE ${WORK}/bad_version.json "{\"format\": \"lidet-sensor\", \"version\": 2}")
expect_error(${CLI} --sensor-file ${WORK}/bad_version.json "\"version\": 2 is not supported")
file(WRITE ${WORK}/bad_json.json "{\"format\": ")
expect_error(${CLI} --sensor-file ${WORK}/bad_json.json "bad_json.json: not valid JSON")
expect_error(${CLI} --sensor-file ${data}/ouster_nested.json "this looks like Ouster metadata")
expect_error(${CLI} --ouster-meta ${data}/vlp16.json "this is a lidet sensor description")
file(WRITE ${WORK}/bad_mode.json "{\"beam_altitude_angles\": [1, 0], \"lidar_mode\": \"fast\"}")
expect_error(${CLI} --ouster-meta ${WORK}/bad_mode.json "\"lidar_mode\": expected \"<columns>x<rate>\"")

message(STATUS "sensor files: 2 presets detected bit for bit from their descriptions, ${n_files} files printed "
               "back the same, 8 bad files refused")
