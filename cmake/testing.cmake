# Test helpers.
#
# vibid_add_host_test(NAME SOURCES... LIBS... [LABELS...] [DISCOVERY...])
#   A GoogleTest executable for host-only code (Eigen numerics, CLI, device layer). Its cases
#   are discovered when ctest runs: each is a test of its own, named NAME.Suite.Case, so
#   `ctest -N` lists every case and `ctest -R` picks single ones. DISCOVERY: more arguments of
#   gtest_discover_tests (e.g. TEST_FILTER).
#
# vibid_add_portable_test(NAME SOURCES... LIBS... [LABELS...])
#   Tests of code that also runs on the board (shared/, firmware/core). On the host they link
#   GoogleTest; in the firmware preset they link the light gtest-compatible runner and run on the
#   Cortex-M4 under qemu-system-arm -M mps2-an386 with semihosting (label `qemu`).
#
# Test data paths are passed as compile definitions so a test runs from any working directory:
#   VIBID_SOURCE_DIR   the project root
#   VIBID_TESTDATA_DIR testdata/: the licensed real records the project ships
#   VIBID_DATA_DIR     ../shared/data beside the project (the unlicensed real records; optional,
#                      see vibid/common/testing/real_data.hpp)

# Runs one Cortex-M4 test image; semihosting carries stdout and the exit code back to ctest.
set(VIBID_QEMU_TEST_COMMAND qemu-system-arm -M mps2-an386 -cpu cortex-m4 -nographic -monitor none
    -serial none -semihosting-config enable=on,target=native -kernel)

include(GoogleTest)

set(VIBID_DATA_DIR "${PROJECT_SOURCE_DIR}/../shared/data" CACHE PATH "Measured records shared with other labs")

function(vibid_add_host_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS;DISCOVERY" ${ARGN})
  # The studies labelled coverage run in the optimised build only (the asan test preset leaves
  # them out), so a sanitizer build does not compile them either.
  if(VIBID_SANITIZE AND "coverage" IN_LIST ARG_LABELS)
    return()
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main GTest::gmock vibid_warnings)
  target_compile_definitions(${name} PRIVATE
    VIBID_SOURCE_DIR="${PROJECT_SOURCE_DIR}" VIBID_TESTDATA_DIR="${PROJECT_SOURCE_DIR}/testdata"
    VIBID_DATA_DIR="${VIBID_DATA_DIR}")
  vibid_discover_tests(${name} "host;${ARG_LABELS}" ${ARG_DISCOVERY})
endfunction()

# vibid_discover_tests(NAME LABELS [gtest_discover_tests arguments...])
#   Every case of the GoogleTest executable NAME as its own ctest test NAME.Suite.Case (unless the
#   arguments name another TEST_PREFIX), labelled LABELS, with ENVIRONMENT (a list of NAME=VALUE)
#   if given. Discovery runs when ctest does, not at build time, so a sanitizer build does not
#   run each test binary once more.
function(vibid_discover_tests name labels)
  cmake_parse_arguments(ARG "" "TEST_PREFIX;ENVIRONMENT" "" ${ARGN})
  if(NOT ARG_TEST_PREFIX)
    set(ARG_TEST_PREFIX "${name}.")
  endif()
  string(MAKE_C_IDENTIFIER "${ARG_TEST_PREFIX}tests" list_var)
  gtest_discover_tests(${name} TEST_PREFIX "${ARG_TEST_PREFIX}" TEST_LIST ${list_var}
                       DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 ${ARG_UNPARSED_ARGUMENTS})
  # List-valued properties (two labels, two variables) do not survive gtest_discover_tests'
  # PROPERTIES; a script ctest includes after the discovery sets them on the discovered cases.
  set(properties "LABELS [==[${labels}]==]")
  if(ARG_ENVIRONMENT)
    string(APPEND properties " ENVIRONMENT [==[${ARG_ENVIRONMENT}]==]")
  endif()
  set(script "${CMAKE_CURRENT_BINARY_DIR}/${list_var}_properties.cmake")
  file(WRITE "${script}" "if(${list_var})\n  set_tests_properties(\${${list_var}} PROPERTIES ${properties})\nendif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${script}")
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
    vibid_discover_tests(${name} "host;${ARG_LABELS}")
  endif()
endfunction()
