# Writes the build id header: the first 8 hex digits of the commit the tree is at (0 outside a
# git checkout). Run at every build; the header is only rewritten when the commit changed, so an
# unchanged tree rebuilds nothing.
execute_process(COMMAND git rev-parse --short=8 HEAD WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE
                RESULT_VARIABLE result ERROR_QUIET)
if(result EQUAL 0 AND commit MATCHES "^[0-9a-f]+$")
  set(id "0x${commit}u")
else()
  set(id "0u")
endif()
file(WRITE ${OUTPUT}.tmp "// Generated at build time by firmware/core/build_id.cmake.\n#pragma once\n"
     "#define VIBID_FW_BUILD_ID ${id}\n")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
