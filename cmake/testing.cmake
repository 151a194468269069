# Test helpers.
#
# vibid_add_host_test(NAME SOURCES... LIBS... [LABELS...])
#   A GoogleTest executable for host-only code (Eigen numerics, CLI, device layer).
#
# vibid_add_portable_test(NAME SOURCES... LIBS... [LABELS...])
#   Tests of code that also runs on the board (shared/, firmware/core). On the host they link
#   GoogleTest; in the firmware preset they link the light gtest-compatible runner and run on the
#   Cortex-M4 under qemu-system-arm -M mps2-an386 with semihosting (label `qemu`).
#
# Test data paths are passed as compile definitions so a test runs from any working directory:
#   VIBID_SOURCE_DIR   the project root
#   VIBID_DATA_DIR     ../shared/data beside the project (real measured records)

# Runs one Cortex-M4 test image; semihosting carries stdout and the exit code back to ctest.
set(VIBID_QEMU_TEST_COMMAND qemu-system-arm -M mps2-an386 -cpu cortex-m4 -nographic -monitor none
    -serial none -semihosting-config enable=on,target=native -kernel)

set(VIBID_DATA_DIR "${PROJECT_SOURCE_DIR}/../shared/data" CACHE PATH "Measured records shared with other labs")

function(vibid_add_host_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main GTest::gmock vibid_warnings)
  target_compile_definitions(${name} PRIVATE
    VIBID_SOURCE_DIR="${PROJECT_SOURCE_DIR}" VIBID_DATA_DIR="${VIBID_DATA_DIR}")
  add_test(NAME ${name} COMMAND ${name})
  set_tests_properties(${name} PROPERTIES LABELS "host;${ARG_LABELS}")
endfunction()

function(vibid_add_portable_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_compile_definitions(${name} PRIVATE VIBID_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  if(CMAKE_CROSSCOMPILING)
    # Defined by firmware/testing: light runner, startup code and semihosting exit for mps2-an386.
    target_link_libraries(${name} PRIVATE ${ARG_LIBS} vibid_target_test_runner vibid_warnings)
    add_test(NAME ${name} COMMAND ${VIBID_QEMU_TEST_COMMAND} $<TARGET_FILE:${name}>)
    set_tests_properties(${name} PROPERTIES LABELS "qemu;${ARG_LABELS}")
  else()
    target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main vibid_warnings)
    add_test(NAME ${name} COMMAND ${name})
    set_tests_properties(${name} PROPERTIES LABELS "host;${ARG_LABELS}")
  endif()
endfunction()
