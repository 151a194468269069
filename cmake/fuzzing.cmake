# libFuzzer targets (clang only; the `asan` configure preset, `fuzz` build and test presets).
#
# vibid_add_fuzz_target(NAME SOURCES... LIBS... [SEEDS dirs...])
#   Each target runs for a bounded time under ctest (label `fuzz`) from its seed directories,
#   growing a working corpus in the build tree. The limits are the campaign's too: a run that
#   needs more than 10 s or 1 GiB for one input is a finding, not a slow machine.
set(VIBID_FUZZ_SECONDS 15 CACHE STRING "Seconds each fuzz target runs under ctest")
set(VIBID_FUZZ_TARGETS "" CACHE INTERNAL "Every libFuzzer target")

function(vibid_add_fuzz_target name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;SEEDS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} vibid_warnings)
  target_compile_options(${name} PRIVATE -fsanitize=fuzzer)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer)
  set(work ${CMAKE_CURRENT_BINARY_DIR}/${name}_corpus)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -E env ASAN_OPTIONS=detect_leaks=1
                   $<TARGET_FILE:${name}> -max_total_time=${VIBID_FUZZ_SECONDS} -seed=1
                   -timeout=10 -rss_limit_mb=1024 -malloc_limit_mb=512 ${work} ${ARG_SEEDS})
  set_tests_properties(${name} PROPERTIES LABELS fuzz TIMEOUT 120)
  file(MAKE_DIRECTORY ${work})
  # For scripts/fuzz-campaign and scripts/fuzz-coverage: the binary and its seed directories.
  set(VIBID_FUZZ_TARGETS ${VIBID_FUZZ_TARGETS} ${name} CACHE INTERNAL "")
  string(REPLACE ";" " " seeds "${ARG_SEEDS}")
  file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/fuzz/${name}.target
       CONTENT "$<TARGET_FILE:${name}>\n${seeds}\n")
endfunction()
