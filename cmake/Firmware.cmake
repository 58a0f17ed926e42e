# The controller core on a Cortex-M4F (firmware/, docs/mcu.md): when Debian's gcc-arm-none-eabi
# (with newlib) and qemu-system-arm are found, records the test vector on the host, cross-builds
# the firmware as an external CMake project and lets tests/mcu run it under QEMU. Without them
# the host build is unchanged and the test reports itself skipped, naming what is missing.
option(PIEZOSHIFT_BUILD_FIRMWARE "Cross-build the Cortex-M4F firmware when the tools are found" ON)

set(PIEZOSHIFT_FIRMWARE_ENABLED OFF)
set(PIEZOSHIFT_FIRMWARE_MISSING "")
if(NOT PIEZOSHIFT_BUILD_FIRMWARE)
  set(PIEZOSHIFT_FIRMWARE_MISSING "PIEZOSHIFT_BUILD_FIRMWARE is OFF")
else()
  find_program(PIEZOSHIFT_ARM_GXX arm-none-eabi-g++)
  find_program(PIEZOSHIFT_QEMU qemu-system-arm)
  if(NOT PIEZOSHIFT_ARM_GXX)
    list(APPEND PIEZOSHIFT_FIRMWARE_MISSING "arm-none-eabi-g++ (gcc-arm-none-eabi)")
  else()
    # newlib-nano comes in its own package; without it the link fails much later.
    execute_process(COMMAND ${PIEZOSHIFT_ARM_GXX} -print-file-name=nano.specs
                    OUTPUT_VARIABLE nano_specs OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT IS_ABSOLUTE "${nano_specs}")
      list(APPEND PIEZOSHIFT_FIRMWARE_MISSING "newlib-nano (libnewlib-arm-none-eabi)")
    endif()
    # The C++ standard headers for the target come in a package of their own too.
    execute_process(COMMAND ${PIEZOSHIFT_ARM_GXX} -std=c++20 -x c++ -fsyntax-only -
                    INPUT_FILE ${PROJECT_SOURCE_DIR}/include/piezoshift/control/vec3.hpp
                    RESULT_VARIABLE cxx_headers_missing OUTPUT_QUIET ERROR_QUIET)
    if(cxx_headers_missing)
      list(APPEND PIEZOSHIFT_FIRMWARE_MISSING "C++ headers (libstdc++-arm-none-eabi-dev)")
    endif()
  endif()
  if(NOT PIEZOSHIFT_QEMU)
    list(APPEND PIEZOSHIFT_FIRMWARE_MISSING "qemu-system-arm")
  endif()
  list(JOIN PIEZOSHIFT_FIRMWARE_MISSING ", " PIEZOSHIFT_FIRMWARE_MISSING)
  if(PIEZOSHIFT_FIRMWARE_MISSING)
    set(PIEZOSHIFT_FIRMWARE_MISSING "not found: ${PIEZOSHIFT_FIRMWARE_MISSING} (scripts/install-deps installs them)")
  else()
    set(PIEZOSHIFT_FIRMWARE_ENABLED ON)
  endif()
endif()

if(NOT PIEZOSHIFT_FIRMWARE_ENABLED)
  message(STATUS "piezoshift: firmware not built: ${PIEZOSHIFT_FIRMWARE_MISSING}")
  return()
endif()

# The recorded test vector: the paper's controller closing the loop on the twin.
add_executable(piezoshift_make_test_vector ${PROJECT_SOURCE_DIR}/firmware/tools/make_test_vector.cpp)
target_include_directories(piezoshift_make_test_vector PRIVATE ${PROJECT_SOURCE_DIR}/firmware/include)
target_link_libraries(piezoshift_make_test_vector PRIVATE piezoshift::plant)
piezoshift_warnings(piezoshift_make_test_vector)

set(PIEZOSHIFT_TEST_VECTOR_BIN ${CMAKE_BINARY_DIR}/firmware-vector/test_vector.bin)
add_custom_command(OUTPUT ${PIEZOSHIFT_TEST_VECTOR_BIN}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/firmware-vector
  COMMAND piezoshift_make_test_vector ${PIEZOSHIFT_TEST_VECTOR_BIN}
  DEPENDS piezoshift_make_test_vector
  COMMENT "Recording the firmware's test vector on the twin")
add_custom_target(piezoshift_test_vector DEPENDS ${PIEZOSHIFT_TEST_VECTOR_BIN})

# The cross build: its own CMake project with the arm-none-eabi toolchain, rebuilt (a no-op when
# nothing changed) on every host build.
include(ExternalProject)
set(PIEZOSHIFT_FIRMWARE_ELF ${CMAKE_BINARY_DIR}/firmware/piezoshift_firmware.elf)
ExternalProject_Add(piezoshift_firmware
  SOURCE_DIR ${PROJECT_SOURCE_DIR}/firmware
  BINARY_DIR ${CMAKE_BINARY_DIR}/firmware
  CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/cmake/arm-none-eabi.cmake
             -DCMAKE_BUILD_TYPE=Release
             -DPIEZOSHIFT_TEST_VECTOR=${PIEZOSHIFT_TEST_VECTOR_BIN}
  BUILD_ALWAYS TRUE
  INSTALL_COMMAND ""
  BUILD_BYPRODUCTS ${PIEZOSHIFT_FIRMWARE_ELF}
  DEPENDS piezoshift_test_vector)
