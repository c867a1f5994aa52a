# SPDX-License-Identifier: MIT
# The library's sources, folder by folder (lib/src/README.md): one folder per pipeline stage, a float file
# lidet_<stage>[_<part>].c beside its integer twin, the same name + _q. Included by CMakeLists.txt,
# ports/firmware/CMakeLists.txt and tools/bench/fw_proj_q/CMakeLists.txt. A new source file goes into its
# folder's list here.
#
# Per folder, absolute paths:
#   LIDET_SRC_<FOLDER>_FLOAT  float code (the default build only)
#   LIDET_SRC_<FOLDER>_INT    integer code, no float (every build; the whole of the integer-only build)
# and the union:
#   LIDET_FLOAT_SOURCES       every _FLOAT list
#   LIDET_FIXED_SOURCES       every _INT list: the integer-only library (-DLIDET_FIXED_POINT=ON)
#   LIDET_ALL_SOURCES         both: the default library
# lib/src/decode (the packet decoders) is listed in LIDET_SRC_DECODE_FLOAT / _INT like the others; the firmware
# images leave it out.
get_filename_component(LIDET_SRC_DIR "${CMAKE_CURRENT_LIST_DIR}/../lib/src" ABSOLUTE)

set(LIDET_SRC_FOLDERS PROJ GROUND CLUSTER POINTNET DETECTOR TRACK NN QMATH COMMON DECODE)

# projection and the sensor presets
set(LIDET_SRC_PROJ_FLOAT proj/lidet_proj.c proj/lidet_sensor.c)
set(LIDET_SRC_PROJ_INT proj/lidet_proj_q.c proj/lidet_sensor_q.c)
# ground: sample filter, gathering and labels; RANSAC planes
set(LIDET_SRC_GROUND_FLOAT ground/lidet_ground_filter.c ground/lidet_ground_ransac.c)
set(LIDET_SRC_GROUND_INT ground/lidet_ground_filter_q.c ground/lidet_ground_ransac_q.c)
# clustering: run and records, growth, fragment rescue, refinement, proposals, the detectors' group split
set(LIDET_SRC_CLUSTER_FLOAT cluster/lidet_cluster.c cluster/lidet_cluster_grow.c cluster/lidet_cluster_rescue.c
    cluster/lidet_refine.c cluster/lidet_proposal.c cluster/lidet_group.c)
set(LIDET_SRC_CLUSTER_INT cluster/lidet_cluster_q.c cluster/lidet_cluster_grow_q.c cluster/lidet_cluster_rescue_q.c
    cluster/lidet_refine_q.c cluster/lidet_proposal_q.c cluster/lidet_group_q.c)
# PointNets (the integer energy tables are generated: python -m lidet_codegen pnqtables)
set(LIDET_SRC_POINTNET_FLOAT pointnet/lidet_pointnet.c)
set(LIDET_SRC_POINTNET_INT pointnet/lidet_pointnet_q.c pointnet/lidet_pointnet_q_tables.c)
# the detectors: the float workspace and detector; the integer detector and its post-processing (size check, NMS)
set(LIDET_SRC_DETECTOR_FLOAT detector/lidet_detector.c detector/lidet_workspace.c)
set(LIDET_SRC_DETECTOR_INT detector/lidet_detector_q.c detector/lidet_post_q.c)
# the tracker after the detector (docs/TRACKING.md)
set(LIDET_SRC_TRACK_FLOAT track/lidet_track.c)
set(LIDET_SRC_TRACK_INT track/lidet_track_q.c)
# PointNet kernels: float (portable, x86 clones and FMA, aarch64 NEON, Cortex-M4F/M7, RISC-V F) and int8
set(LIDET_SRC_NN_FLOAT nn/lidet_nn_f32.c nn/lidet_nn_f32_x86.c nn/lidet_nn_f32_neon.c nn/lidet_nn_f32_cm.c
                       nn/lidet_nn_f32_rv.c)
set(LIDET_SRC_NN_INT nn/lidet_nn_s8.c)
# integer math and its generated tables (python -m lidet_codegen qtables)
set(LIDET_SRC_QMATH_FLOAT)
set(LIDET_SRC_QMATH_INT qmath/lidet_qmath.c qmath/lidet_qmath_tables.c)
# status strings, sort
set(LIDET_SRC_COMMON_FLOAT)
set(LIDET_SRC_COMMON_INT common/lidet_status.c common/lidet_sort.c)
# packet decoding: the Velodyne returns' x, y, z (float); the Velodyne and Ouster decoders (integer)
set(LIDET_SRC_DECODE_FLOAT decode/lidet_velodyne_xyz.c)
set(LIDET_SRC_DECODE_INT decode/lidet_velodyne.c decode/lidet_ouster.c)

set(LIDET_FLOAT_SOURCES)
set(LIDET_FIXED_SOURCES)
foreach(folder IN LISTS LIDET_SRC_FOLDERS)
  list(TRANSFORM LIDET_SRC_${folder}_FLOAT PREPEND ${LIDET_SRC_DIR}/)
  list(TRANSFORM LIDET_SRC_${folder}_INT PREPEND ${LIDET_SRC_DIR}/)
  list(APPEND LIDET_FLOAT_SOURCES ${LIDET_SRC_${folder}_FLOAT})
  list(APPEND LIDET_FIXED_SOURCES ${LIDET_SRC_${folder}_INT})
endforeach()
set(LIDET_ALL_SOURCES ${LIDET_FIXED_SOURCES} ${LIDET_FLOAT_SOURCES})

# every .c under lib/src must be in exactly one list above (a file added without a list entry fails here)
if(CMAKE_SCRIPT_MODE_FILE)
  file(GLOB lidet_src_found ${LIDET_SRC_DIR}/*.c ${LIDET_SRC_DIR}/*/*.c)
else()
  file(GLOB lidet_src_found CONFIGURE_DEPENDS ${LIDET_SRC_DIR}/*.c ${LIDET_SRC_DIR}/*/*.c)
endif()
set(lidet_src_unlisted ${lidet_src_found})
list(REMOVE_ITEM lidet_src_unlisted ${LIDET_ALL_SOURCES})
set(lidet_src_missing ${LIDET_ALL_SOURCES})
list(REMOVE_ITEM lidet_src_missing ${lidet_src_found})
if(lidet_src_unlisted OR lidet_src_missing)
  message(FATAL_ERROR "cmake/lidet_sources.cmake: not listed: ${lidet_src_unlisted}; listed but missing: "
                      "${lidet_src_missing}")
endif()
