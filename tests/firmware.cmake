# SPDX-License-Identifier: MIT
# Firmware images (ports/firmware) under QEMU, compared with the host build (issue 17).
#
# - fw_host_ref (fw_host_ref_hdl64): the firmware application (ports/firmware/fw_detect.c) built for the host
#   against lidet rebuilt with the firmware's capacities (ports/firmware/config/<sensor>/lidet_user_config.h),
#   on the same generated scan.
# - firmware_<board>: one cross build per board (ExternalProject: its own toolchain file), part of the normal
#   build when its cross compiler is installed (tools/scripts/install_deps.sh installs them), and one ctest test
#   per board that runs the image under QEMU and compares it with fw_host_ref (tools/firmware/run_fw.py).
#   Without the compiler or QEMU the test reports itself skipped with the reason.
# - the Ouster packet image (mps2-an386-q-packets-os1-32) and its reference fw_host_ref_pkt_ouster: a simulated OS1-32
#   scan made at build time (lidet-sim, build/firmware/sim_os1-32) as Ouster payloads (tools/firmware/packets_to_c.py
#   --lidar ouster, lidet_tools.ouster's writer); both need the project's venv (numpy): without it they are not
#   built and the image's test reports itself skipped with the reason.
# `make firmware` builds the target `firmware`; `make firmware-run` runs the tests with their figures.
include(ExternalProject)
set(fw_default ON)
if(LIDET_SANITIZE)
  set(fw_default OFF) # the sanitizer build re-runs the host tests; the images are the same as the normal build's
endif()
option(LIDET_BUILD_FIRMWARE "Build the firmware images when their cross compilers are installed" ${fw_default})
if(NOT LIDET_BUILD_FIRMWARE)
  return()
endif()
find_package(Python3 COMPONENTS Interpreter)
if(NOT Python3_Interpreter_FOUND)
  message(WARNING "python3 not found: the firmware tests are not registered")
  return()
endif()

set(fw_src ${PROJECT_SOURCE_DIR}/ports/firmware)

# ---- the host references: one per sensor configuration (ports/firmware/config/<sensor>) ------------
file(GLOB fw_weights_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/weights/*.c)
# the model family of an image and of its host reference (ports/firmware/CMakeLists.txt: LIDET_FW_MODELS'
# default): the small pair vlp16s for the integer VLP-16 build, the sensor's own models otherwise
function(lidet_fw_models out sensor fixed)
  set(m ${sensor})
  if(fixed AND sensor STREQUAL "vlp16")
    set(m vlp16s)
  elseif(sensor STREQUAL "os1-32")
    set(m beams32) # the 32-beam family (ports/firmware/CMakeLists.txt)
  endif()
  set(${out} ${m} PARENT_SCOPE)
endfunction()

# lidet and the models with a sensor configuration's capacities: lidet_fwcap_<sensor> (float), with FIXED
# lidet_fwcap_<sensor>_q (the integer-only build, the int8 models), with FUSED lidet_fwcap_<sensor>_fused (float, the
# dense layers with fused multiply-adds)
function(lidet_fw_cap_lib sensor)
  set(lib lidet_fwcap_${sensor})
  set(srcs ${LIDET_SOURCES} ${fw_weights_sources})
  if("FUSED" IN_LIST ARGN)
    set(lib lidet_fwcap_${sensor}_fused)
  endif()
  if("FIXED" IN_LIST ARGN)
    set(lib lidet_fwcap_${sensor}_q)
    file(GLOB s8_weights CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/weights/*_s8*.c)
    set(srcs ${LIDET_FIXED_SOURCES} ${s8_weights})
  endif()
  add_library(${lib} STATIC ${srcs})
  set_target_properties(${lib} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  target_include_directories(${lib} PUBLIC ${PROJECT_SOURCE_DIR}/lib/include ${PROJECT_SOURCE_DIR}/weights
                                           ${fw_src}/config/${sensor} PRIVATE ${PROJECT_SOURCE_DIR}/lib/src)
  target_compile_definitions(${lib} PUBLIC LIDET_USER_CONFIG)
  # the same numerics as the images: one rounding per operation, no errno, no AVX2 kernel clones
  target_compile_options(${lib} PRIVATE -Wall -Wextra -Wpedantic -Werror -Wdouble-promotion -fno-math-errno
                                        -ffp-contract=off)
  if("FIXED" IN_LIST ARGN)
    target_compile_definitions(${lib} PUBLIC LIDET_FIXED_POINT=1)
  elseif(LIDET_HAVE_LIBM)
    target_link_libraries(${lib} PUBLIC m)
  endif()
  if("FUSED" IN_LIST ARGN)
    # the float dense layers with fused multiply-adds (lidet_nn_f32_x86.c on a CPU with FMA), the arithmetic of the
    # Cortex-M7, RISC-V F and aarch64 images' kernels: every other source compiles to the same numerics with the clones
    target_compile_definitions(${lib} PRIVATE LIDET_NN_CLONES=1)
  endif()
endfunction()

function(lidet_fw_host_ref sensor exe)
  # optional third argument FIXED: the integer-only build (the integer detector, int8 models, the scan in mm);
  # FUSED: the float build with the fused dense kernel (fw_host_ref_fused, for the images whose kernel fuses)
  set(lib lidet_fwcap_${sensor})
  set(mm "")
  if(ARGV2 STREQUAL "FIXED")
    set(lib lidet_fwcap_${sensor}_q)
    set(mm --mm)
  elseif(ARGV2 STREQUAL "FUSED")
    set(lib lidet_fwcap_${sensor}_fused)
  endif()
  lidet_fw_cap_lib(${sensor} ${ARGN})
  set(scan_c ${CMAKE_CURRENT_BINARY_DIR}/fw_host_scan_${exe}.c)
  set(data ${PROJECT_SOURCE_DIR}/tests/data/sim_${sensor})
  add_custom_command(OUTPUT ${scan_c}
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/scan_to_c.py ${data}/velodyne/000000.bin
            --ring ${data}/ring/000000.bin --name tests/data/sim_${sensor}/000000 --out ${scan_c} ${mm}
    DEPENDS ${PROJECT_SOURCE_DIR}/tools/firmware/scan_to_c.py ${data}/velodyne/000000.bin ${data}/ring/000000.bin
    VERBATIM)
  add_executable(${exe} ${fw_src}/fw_detect.c ${fw_src}/fw_out.c ${fw_src}/fw_host_port.c ${scan_c})
  set_target_properties(${exe} PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
  target_include_directories(${exe} PRIVATE ${fw_src})
  set(fixed_ref OFF)
  if(ARGV2 STREQUAL "FIXED")
    set(fixed_ref ON)
  endif()
  lidet_fw_models(models ${sensor} ${fixed_ref}) # those of the images it is compared with
  target_compile_definitions(${exe} PRIVATE FW_SENSOR="${sensor}" FW_SENSOR_ID=${sensor} FW_MODELS="${models}"
                                            FW_MODELS_ID=${models})
  target_compile_options(${exe} PRIVATE -Wall -Wextra -Werror -fno-math-errno -ffp-contract=off)
  target_link_libraries(${exe} PRIVATE ${lib})
  add_test(NAME firmware_${exe} COMMAND ${exe})
  set_tests_properties(firmware_${exe} PROPERTIES PASS_REGULAR_EXPRESSION "lidet-fw: PASS")
endfunction()
lidet_fw_host_ref(vlp16 fw_host_ref)
lidet_fw_host_ref(hdl64 fw_host_ref_hdl64)
lidet_fw_host_ref(vlp16 fw_host_ref_q FIXED)
# the images whose float dense kernel fuses (Cortex-M7: lidet_nn_f32_cm.c; aarch64: NEON; RISC-V F: _rv.c) are
# compared with a reference that fuses as they do, where the host can (x86-64 GCC/clang with the kernel clones; on a
# CPU without FMA it runs the portable kernel and the comparison stays within run_fw.py's tolerances)
set(fw_fused_ref_vlp16 fw_host_ref)
set(fw_fused_ref_hdl64 fw_host_ref_hdl64)
if(LIDET_NN_CLONES AND LIDET_NN_FMA AND CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64" AND NOT CMAKE_CROSSCOMPILING
   AND CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
  lidet_fw_host_ref(vlp16 fw_host_ref_fused FUSED)
  lidet_fw_host_ref(hdl64 fw_host_ref_hdl64_fused FUSED)
  set(fw_fused_ref_vlp16 fw_host_ref_fused)
  set(fw_fused_ref_hdl64 fw_host_ref_hdl64_fused)
endif()

# the packet application's reference (ports/firmware/fw_packets.c with FW_PACKETS_HOST_REF): the same VLP-16
# payloads (tools/firmware/packets_to_c.py) decoded on the host into a buffer of the whole scan, the completed scan
# given to lidet_detector_q_run_returns at once; the images stream them instead (lidet_detector_q_stream_*)
set(fw_pkt_c ${CMAKE_CURRENT_BINARY_DIR}/fw_host_pkt.c)
set(fw_pkt_data ${PROJECT_SOURCE_DIR}/tests/data/sim_vlp16)
add_custom_command(OUTPUT ${fw_pkt_c}
  COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/packets_to_c.py ${fw_pkt_data}/velodyne/000000.bin
          --ring ${fw_pkt_data}/ring/000000.bin --name tests/data/sim_vlp16/000000 --out ${fw_pkt_c}
  DEPENDS ${PROJECT_SOURCE_DIR}/tools/firmware/packets_to_c.py ${fw_pkt_data}/velodyne/000000.bin
          ${fw_pkt_data}/ring/000000.bin
  VERBATIM)
add_executable(fw_host_ref_pkt ${fw_src}/fw_packets.c ${fw_src}/fw_out.c ${fw_src}/fw_host_port.c ${fw_pkt_c})
set_target_properties(fw_host_ref_pkt PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
target_include_directories(fw_host_ref_pkt PRIVATE ${fw_src})
lidet_fw_models(fw_pkt_models vlp16 ON)
target_compile_definitions(fw_host_ref_pkt PRIVATE FW_PACKETS_HOST_REF=1 FW_SENSOR="vlp16" FW_SENSOR_ID=vlp16
                                                   FW_MODELS="${fw_pkt_models}" FW_MODELS_ID=${fw_pkt_models})
target_compile_options(fw_host_ref_pkt PRIVATE -Wall -Wextra -Werror)
target_link_libraries(fw_host_ref_pkt PRIVATE lidet_fwcap_vlp16_q)
add_test(NAME firmware_fw_host_ref_pkt COMMAND fw_host_ref_pkt)
set_tests_properties(firmware_fw_host_ref_pkt PROPERTIES PASS_REGULAR_EXPRESSION "lidet-fw: PASS")

# the Ouster packet application's reference (fw_packets.c with FW_OUSTER and FW_PACKETS_HOST_REF): an OS1-32 scan
# simulated at build time (lidet-sim --sensor os1-32 --seed 0, scan 000000: no Ouster scan is shipped) as Ouster
# RNG19_RFL8_SIG16_NIR16 payloads (packets_to_c.py --lidar ouster: lidet_tools.ouster.write_packet), the capacities of
# ports/firmware/config/os1-32, the beams32 int8 pair. The simulator and the writer need numpy: the project's venv
# (LIDET_FW_SIM_PYTHON, default <repo>/.venv/bin/python, which `make deps` creates); without it neither the scan, nor
# this reference, nor the image is built, and the image's test reports itself skipped.
set(LIDET_FW_SIM_PYTHON "" CACHE FILEPATH
    "Python with numpy for the Ouster packet image's simulated scan and payloads (empty: <repo>/.venv/bin/python)")
set(fw_sim_py "${LIDET_FW_SIM_PYTHON}")
if(fw_sim_py STREQUAL "")
  set(fw_sim_py ${PROJECT_SOURCE_DIR}/.venv/bin/python)
endif()
set(fw_sim_ok OFF)
if(EXISTS ${fw_sim_py})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PROJECT_SOURCE_DIR}/tools ${fw_sim_py} -c
                          "import numpy, lidet_tools.sim.cli, lidet_tools.ouster"
                  RESULT_VARIABLE fw_sim_rc OUTPUT_QUIET ERROR_QUIET)
  if(fw_sim_rc EQUAL 0)
    set(fw_sim_ok ON)
  endif()
endif()
set(fw_os_sim ${CMAKE_BINARY_DIR}/firmware/sim_os1-32)
set(fw_os_scan ${fw_os_sim}/velodyne/000000.bin)
set(fw_os_ring ${fw_os_sim}/ring/000000.bin)
set(fw_os_name sim_os1-32/000000)
if(fw_sim_ok)
  file(GLOB fw_sim_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tools/lidet_tools/sim/*.py)
  add_custom_command(OUTPUT ${fw_os_scan} ${fw_os_ring}
    COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PROJECT_SOURCE_DIR}/tools ${fw_sim_py} -m lidet_tools.sim.cli
            --sensor os1-32 --scenes 1 --seed 0 --out ${fw_os_sim} --no-progress
    DEPENDS ${fw_sim_sources} ${PROJECT_SOURCE_DIR}/tools/lidet_tools/sensors.py
    COMMENT "lidet-sim: the simulated OS1-32 scan of the Ouster packet image (${fw_os_sim})" VERBATIM)
  add_custom_target(fw_sim_os1-32 DEPENDS ${fw_os_scan} ${fw_os_ring})
  set(fw_pkt_os_c ${CMAKE_CURRENT_BINARY_DIR}/fw_host_pkt_ouster.c)
  add_custom_command(OUTPUT ${fw_pkt_os_c}
    COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PROJECT_SOURCE_DIR}/tools ${fw_sim_py}
            ${PROJECT_SOURCE_DIR}/tools/firmware/packets_to_c.py ${fw_os_scan} --ring ${fw_os_ring} --lidar ouster
            --sensor os1-32 --name ${fw_os_name} --out ${fw_pkt_os_c}
    DEPENDS ${PROJECT_SOURCE_DIR}/tools/firmware/packets_to_c.py ${PROJECT_SOURCE_DIR}/tools/lidet_tools/ouster.py
            ${fw_os_scan} ${fw_os_ring}
    VERBATIM)
  lidet_fw_cap_lib(os1-32 FIXED)
  add_executable(fw_host_ref_pkt_ouster ${fw_src}/fw_packets.c ${fw_src}/fw_out.c ${fw_src}/fw_host_port.c
                                        ${fw_pkt_os_c})
  set_target_properties(fw_host_ref_pkt_ouster PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
  target_include_directories(fw_host_ref_pkt_ouster PRIVATE ${fw_src})
  lidet_fw_models(fw_pkt_os_models os1-32 ON)
  target_compile_definitions(fw_host_ref_pkt_ouster PRIVATE FW_PACKETS_HOST_REF=1 FW_OUSTER=1 FW_SENSOR="os1-32"
                                                            FW_MODELS="${fw_pkt_os_models}"
                                                            FW_MODELS_ID=${fw_pkt_os_models})
  target_compile_options(fw_host_ref_pkt_ouster PRIVATE -Wall -Wextra -Werror)
  target_link_libraries(fw_host_ref_pkt_ouster PRIVATE lidet_fwcap_os1-32_q)
  add_test(NAME firmware_fw_host_ref_pkt_ouster COMMAND fw_host_ref_pkt_ouster)
  set_tests_properties(firmware_fw_host_ref_pkt_ouster PROPERTIES PASS_REGULAR_EXPRESSION "lidet-fw: PASS")
endif()

# ---- the bare-metal aarch64 image's own C library functions (ports/aarch64/virt_libc.c: no C library there), built
# for the host under other names and compared with the host's (tests/aarch64/test_virt_libc.c) ----
set(virt_libc_defs "")
foreach(f expf logf sinf cosf sincosf tanf atan2f fmodf memcpy memmove memset memcmp strcmp)
  list(APPEND virt_libc_defs ${f}=port_${f})
endforeach()
add_executable(test_virt_libc ${PROJECT_SOURCE_DIR}/tests/aarch64/test_virt_libc.c
                              ${PROJECT_SOURCE_DIR}/ports/aarch64/virt_libc.c)
set_target_properties(test_virt_libc PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
set_source_files_properties(${PROJECT_SOURCE_DIR}/ports/aarch64/virt_libc.c PROPERTIES
                            COMPILE_DEFINITIONS "${virt_libc_defs}" COMPILE_OPTIONS "-ffreestanding;-fno-builtin")
target_compile_options(test_virt_libc PRIVATE -Wall -Wextra -Werror)
if(LIDET_HAVE_LIBM)
  target_link_libraries(test_virt_libc PRIVATE m)
endif()
add_test(NAME firmware_virt_libc COMMAND test_virt_libc)
set_tests_properties(firmware_virt_libc PROPERTIES PASS_REGULAR_EXPRESSION "virt_libc: PASS")

# ---- the images --------------------------------------------------------------------------------
add_custom_target(firmware DEPENDS fw_host_ref ${fw_fused_ref_vlp16} fw_host_ref_hdl64 ${fw_fused_ref_hdl64}
                                   fw_host_ref_q fw_host_ref_pkt)
if(fw_sim_ok)
  add_dependencies(firmware fw_host_ref_pkt_ouster)
endif()
# image name | board | sensor | toolchain file | compiler | size tool [| fixed [| application [| lidar]]]. The HDL-64
# (KITTI-like) images need ~4.5 MiB of RAM: QEMU virt, and the AN500's Cortex-M7 with the detector placed in its
# 16 MiB PSRAM. The application is fw_detect.c unless an eighth field names another (LIDET_FW_APP); the packet
# application's lidar is velodyne unless a ninth field says ouster (LIDET_FW_LIDAR).
set(fw_images
    "mps2-an385|mps2-an385|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an385-m0plus|mps2-an385-m0plus|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an386|mps2-an386|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an500|mps2-an500|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an500-hdl64|mps2-an500|hdl64|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "virt-rv32imafc|virt-rv32imafc|vlp16|riscv32-unknown-elf|riscv64-unknown-elf-gcc|riscv64-unknown-elf-size"
    "virt-rv32imafc-hdl64|virt-rv32imafc|hdl64|riscv32-unknown-elf|riscv64-unknown-elf-gcc|riscv64-unknown-elf-size"
    # the integer-only build (issue 16): cores without FPU, compared bit for bit with fw_host_ref_q
    "mps2-an385-q|mps2-an385|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed"
    "mps2-an385-m0plus-q|mps2-an385-m0plus|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed"
    # ... and cores with the DSP extension (their FPU unused): the int8 kernel with SMLAD
    "mps2-an386-q|mps2-an386|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed"
    "mps2-an500-q|mps2-an500|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed"
    "virt-rv32imac-q|virt-rv32imac|vlp16|riscv32-unknown-elf|riscv64-unknown-elf-gcc|riscv64-unknown-elf-size|fixed"
    # VLP-16 payloads in flash decoded (lidet_velodyne_packet) and streamed into the integer detector
    # (ports/firmware/fw_packets.c), compared bit for bit with fw_host_ref_pkt (issue 37)
    "mps2-an386-q-packets|mps2-an386|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed|packets"
    "mps2-an385-m0plus-q-packets|mps2-an385-m0plus|vlp16|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed|packets"
    "virt-rv32imac-q-packets|virt-rv32imac|vlp16|riscv32-unknown-elf|riscv64-unknown-elf-gcc|riscv64-unknown-elf-size|fixed|packets"
    # Ouster OS1-32 payloads (a simulated scan, RNG19_RFL8_SIG16_NIR16) decoded (lidet_ouster_packet) and streamed
    # into the integer detector, beams32 pair, compared bit for bit with fw_host_ref_pkt_ouster
    "mps2-an386-q-packets-os1-32|mps2-an386|os1-32|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed|packets|ouster"
    # ... and on the cores without the DSP extension
    "mps2-an385-m0plus-q-packets-os1-32|mps2-an385-m0plus|os1-32|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size|fixed|packets|ouster"
    "virt-rv32imac-q-packets-os1-32|virt-rv32imac|os1-32|riscv32-unknown-elf|riscv64-unknown-elf-gcc|riscv64-unknown-elf-size|fixed|packets|ouster"
    # 64-bit Arm bare metal (QEMU virt, Cortex-A72; ports/aarch64): the float image with the NEON dense kernel, the
    # integer image compared bit for bit
    "virt-aarch64|virt-aarch64|vlp16|aarch64-bare-metal|aarch64-linux-gnu-gcc|aarch64-linux-gnu-size"
    "virt-aarch64-q|virt-aarch64|vlp16|aarch64-bare-metal|aarch64-linux-gnu-gcc|aarch64-linux-gnu-size|fixed")
foreach(entry IN LISTS fw_images)
  string(REPLACE "|" ";" f "${entry}")
  list(GET f 0 image)
  list(GET f 1 board)
  list(GET f 2 sensor)
  list(GET f 3 tc)
  list(GET f 4 cc)
  list(GET f 5 sz)
  list(LENGTH f nf)
  set(fixed OFF)
  if(nf GREATER 6)
    set(fixed ON)
  endif()
  set(app detect)
  if(nf GREATER 7)
    list(GET f 7 app)
  endif()
  set(lidar velodyne)
  if(nf GREATER 8)
    list(GET f 8 lidar)
  endif()
  set(fw_py ${Python3_EXECUTABLE})
  set(extra_args "")
  set(extra_deps "")
  if(lidar STREQUAL "ouster")
    set(ref fw_host_ref_pkt_ouster)
    if(NOT fw_sim_ok)
      add_test(NAME firmware_${image}
               COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/run_fw.py --board ${board}
                       --label ${image}
                       --skip "no Python with numpy for its simulated OS1-32 scan and Ouster payloads (${fw_sim_py}: make deps creates the venv; or -DLIDET_FW_SIM_PYTHON=...)")
      set_tests_properties(firmware_${image} PROPERTIES SKIP_RETURN_CODE 77)
      continue()
    endif()
    # the simulated scan of the main build, the payloads written with the venv's Python (numpy)
    set(fw_py ${fw_sim_py})
    set(extra_args -DLIDET_FW_SCAN=${fw_os_scan} -DLIDET_FW_RING=${fw_os_ring} -DLIDET_FW_SCAN_NAME=${fw_os_name})
    set(extra_deps DEPENDS fw_sim_os1-32)
  elseif(app STREQUAL "packets")
    set(ref fw_host_ref_pkt)
  elseif(fixed)
    set(ref fw_host_ref_q)
  elseif(board MATCHES "^(mps2-an500|virt-aarch64|virt-rv32imafc)$")
    # a fused dense kernel (Cortex-M7: LIDET_NN_CM_FMA, ports/firmware/CMakeLists.txt; aarch64: NEON; RISC-V F:
    # LIDET_NN_RV_FMA)
    set(ref ${fw_fused_ref_${sensor}})
  elseif(sensor STREQUAL "vlp16")
    set(ref fw_host_ref)
  else()
    set(ref fw_host_ref_${sensor})
  endif()
  find_program(LIDET_FW_CC_${tc} ${cc})
  if(NOT LIDET_FW_CC_${tc})
    add_test(NAME firmware_${image}
             COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/run_fw.py --board ${board}
                     --label ${image}
                     --skip "${cc} not found (tools/scripts/install_deps.sh installs the cross toolchains)")
    set_tests_properties(firmware_${image} PROPERTIES SKIP_RETURN_CODE 77)
    continue()
  endif()
  lidet_fw_models(models ${sensor} ${fixed})
  set(bdir ${CMAKE_BINARY_DIR}/firmware/${image})
  ExternalProject_Add(firmware_${image}
    SOURCE_DIR ${fw_src}
    BINARY_DIR ${bdir}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/cmake/toolchains/${tc}.cmake
               -DLIDET_FW_BOARD=${board} -DLIDET_FW_SENSOR=${sensor} -DPython3_EXECUTABLE=${fw_py}
               -DLIDET_FW_FIXED=${fixed} -DLIDET_FW_MODELS=${models} -DLIDET_FW_APP=${app}
               -DLIDET_FW_LIDAR=${lidar} ${extra_args}
    ${extra_deps}
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    BUILD_BYPRODUCTS ${bdir}/lidet_fw.elf)
  add_dependencies(firmware firmware_${image})
  add_test(NAME firmware_${image}
           COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/run_fw.py --board ${board}
                   --label ${image} --elf ${bdir}/lidet_fw.elf --host-ref $<TARGET_FILE:${ref}> --size ${sz}
                   --json ${bdir}/report.json --timeout 600)
  set_tests_properties(firmware_${image} PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 900 LABELS firmware)
endforeach()
