# Project-wide warning set. Applied per target through vibid_warnings() so third-party code found
# through find_package keeps its own flags.
option(VIBID_WERROR "Treat warnings as errors" ON)
option(VIBID_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(VIBID_FUZZ "Also build the libFuzzer targets (clang, with VIBID_SANITIZE; the `asan` preset)" OFF)
option(VIBID_COVERAGE "Source-based coverage (clang; the `fuzz-coverage` preset, scripts/fuzz-coverage)" OFF)

add_library(vibid_warnings INTERFACE)
target_compile_options(vibid_warnings INTERFACE
  # Options structs are filled with designated initializers; omitted fields keep their defaults.
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wdouble-promotion
  -Wno-missing-field-initializers -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Wimplicit-fallthrough
  $<$<BOOL:${VIBID_WERROR}>:-Werror>)

if(VIBID_SANITIZE)
  # vptr checks need RTTI, which the firmware core and shared code are built without on purpose.
  add_compile_options(-fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined -fno-sanitize=vptr)
  # UBSan's checks are not compiled into Eigen's own templates (AddressSanitizer still is, and
  # UBSan still checks every line of vibid's code, including its calls into Eigen). Measured with
  # clang 14 at -O1 on host/lib/ident/modes.cpp: 16.1 s of CPU with them, 11.4 s without; UBSan
  # alone costs 14.4 s against 8.1 s for no sanitizer. Eigen's index checks stay on (eigen_assert,
  # the build keeps NDEBUG off): this trims the asan build's compile time (docs/testing.md gives
  # the whole build's figures), not its guard over vibid's indexing.
  find_path(VIBID_EIGEN_INCLUDE_DIR signature_of_eigen3_matrix_library PATH_SUFFIXES eigen3)
  if(VIBID_EIGEN_INCLUDE_DIR)
    set(ignorelist "${CMAKE_BINARY_DIR}/ubsan-ignorelist.txt")
    file(WRITE "${ignorelist}" "[undefined]\nsrc:${VIBID_EIGEN_INCLUDE_DIR}/*\n")
    add_compile_options("-fsanitize-ignorelist=${ignorelist}")
  endif()
endif()
if(VIBID_FUZZ)
  # The coverage build runs the fuzz targets over their corpora only; the sanitizers there would
  # only slow it down.
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang" OR NOT (VIBID_SANITIZE OR VIBID_COVERAGE))
    message(FATAL_ERROR "VIBID_FUZZ needs clang and VIBID_SANITIZE=ON (use the `asan` preset)")
  endif()
  # Coverage counters in every library, so one sanitizer build serves the tests and the fuzzers.
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
if(VIBID_COVERAGE)
  add_compile_options(-fprofile-instr-generate -fcoverage-mapping)
  add_link_options(-fprofile-instr-generate)
endif()

# Firmware-core and shared code: the embedded rules hold on the host build too, so a heap call,
# a throw or a typeid fails to compile on the host before it reaches the board.
add_library(vibid_embedded_rules INTERFACE)
target_compile_options(vibid_embedded_rules INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti>)
