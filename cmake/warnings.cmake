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
