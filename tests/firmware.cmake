# SPDX-License-Identifier: MIT
# Firmware images (ports/firmware) under QEMU, compared with the host build (issue 17).
#
# - fw_host_ref: the firmware application (ports/firmware/fw_detect.c) built for the host against lidet rebuilt
#   with the firmware's capacities (ports/firmware/config/lidet_user_config.h), on the same generated scan.
# - firmware_<board>: one cross build per board (ExternalProject: its own toolchain file), part of the normal
#   build when its cross compiler is installed (tools/scripts/install_deps.sh installs them), and one ctest test
#   per board that runs the image under QEMU and compares it with fw_host_ref (tools/firmware/run_fw.py).
#   Without the compiler or QEMU the test reports itself skipped with the reason.
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
set(fw_scan ${PROJECT_SOURCE_DIR}/tests/data/sim_vlp16/velodyne/000000.bin)
set(fw_ring ${PROJECT_SOURCE_DIR}/tests/data/sim_vlp16/ring/000000.bin)

# ---- the host reference ----------------------------------------------------------------------
file(GLOB fw_weights_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/weights/*.c)
add_library(lidet_fwcap STATIC ${LIDET_SOURCES} ${fw_weights_sources})
set_target_properties(lidet_fwcap PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
target_include_directories(lidet_fwcap PUBLIC ${PROJECT_SOURCE_DIR}/lib/include ${PROJECT_SOURCE_DIR}/weights
                                              ${fw_src}/config PRIVATE ${PROJECT_SOURCE_DIR}/lib/src)
target_compile_definitions(lidet_fwcap PUBLIC LIDET_USER_CONFIG)
# the same numerics as the images: one rounding per operation, no errno, no AVX2 kernel clones
target_compile_options(lidet_fwcap PRIVATE -Wall -Wextra -Wpedantic -Werror -Wdouble-promotion -fno-math-errno
                                           -ffp-contract=off)
if(LIDET_HAVE_LIBM)
  target_link_libraries(lidet_fwcap PUBLIC m)
endif()
set(fw_host_scan ${CMAKE_CURRENT_BINARY_DIR}/fw_host_scan.c)
add_custom_command(OUTPUT ${fw_host_scan}
  COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/scan_to_c.py ${fw_scan} --ring ${fw_ring}
          --name tests/data/sim_vlp16/000000 --out ${fw_host_scan}
  DEPENDS ${PROJECT_SOURCE_DIR}/tools/firmware/scan_to_c.py ${fw_scan} ${fw_ring} VERBATIM)
add_executable(fw_host_ref ${fw_src}/fw_detect.c ${fw_src}/fw_host_port.c ${fw_host_scan})
set_target_properties(fw_host_ref PROPERTIES C_STANDARD 99 C_EXTENSIONS OFF)
target_include_directories(fw_host_ref PRIVATE ${fw_src})
target_compile_options(fw_host_ref PRIVATE -Wall -Wextra -Werror -fno-math-errno -ffp-contract=off)
target_link_libraries(fw_host_ref PRIVATE lidet_fwcap)
add_test(NAME firmware_host_ref COMMAND fw_host_ref)
set_tests_properties(firmware_host_ref PROPERTIES PASS_REGULAR_EXPRESSION "lidet-fw: PASS")

# ---- the images --------------------------------------------------------------------------------
add_custom_target(firmware DEPENDS fw_host_ref)
# board | toolchain file | compiler | size tool
set(fw_boards
    "mps2-an385|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an385-m0plus|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an386|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "mps2-an500|arm-none-eabi|arm-none-eabi-gcc|arm-none-eabi-size"
    "virt-rv32imafc|riscv32-unknown-elf|riscv64-unknown-elf-gcc|riscv64-unknown-elf-size")
foreach(entry IN LISTS fw_boards)
  string(REPLACE "|" ";" f "${entry}")
  list(GET f 0 board)
  list(GET f 1 tc)
  list(GET f 2 cc)
  list(GET f 3 sz)
  find_program(LIDET_FW_CC_${tc} ${cc})
  if(NOT LIDET_FW_CC_${tc})
    add_test(NAME firmware_${board}
             COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/run_fw.py --board ${board}
                     --skip "${cc} not found (tools/scripts/install_deps.sh installs the cross toolchains)")
    set_tests_properties(firmware_${board} PROPERTIES SKIP_RETURN_CODE 77)
    continue()
  endif()
  set(bdir ${CMAKE_BINARY_DIR}/firmware/${board})
  ExternalProject_Add(firmware_${board}
    SOURCE_DIR ${fw_src}
    BINARY_DIR ${bdir}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/cmake/toolchains/${tc}.cmake
               -DLIDET_FW_BOARD=${board} -DPython3_EXECUTABLE=${Python3_EXECUTABLE}
               -DLIDET_FW_SCAN=${fw_scan} -DLIDET_FW_RING=${fw_ring}
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    BUILD_BYPRODUCTS ${bdir}/lidet_fw.elf)
  add_dependencies(firmware firmware_${board})
  add_test(NAME firmware_${board}
           COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/firmware/run_fw.py --board ${board}
                   --elf ${bdir}/lidet_fw.elf --host-ref $<TARGET_FILE:fw_host_ref> --size ${sz}
                   --json ${bdir}/report.json --timeout 600)
  set_tests_properties(firmware_${board} PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 900 LABELS firmware)
endforeach()
