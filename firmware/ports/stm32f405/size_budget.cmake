# Post-build size check: sums the allocated sections of an image and fails the build when flash
# or static RAM exceeds its budget. Invoked with cmake -P and:
#   SIZE_TOOL   arm-none-eabi-size
#   ELF         the image
#   REPORT      output file for the report
#   FLASH_BUDGET / RAM_BUDGET   in bytes
execute_process(COMMAND ${SIZE_TOOL} -A ${ELF} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "size: cannot read ${ELF}")
endif()

set(flash 0)
set(ram 0)
string(REPLACE "\n" ";" lines "${out}")
foreach(line IN LISTS lines)
  if(line MATCHES "^(\\.[A-Za-z_.]+)[ \t]+([0-9]+)[ \t]+([0-9]+)")
    set(name ${CMAKE_MATCH_1})
    set(bytes ${CMAKE_MATCH_2})
    # Flash holds code, constants, the init table, the initial values of .data and the CRC trailer.
    if(name MATCHES "^\\.(isr_vector|text|ARM\\.exidx|init_array|data|image_crc)$")
      math(EXPR flash "${flash} + ${bytes}")
    endif()
    # Static RAM: initialized and zeroed data, no-init words, CCM buffers, the reserved stack.
    if(name MATCHES "^\\.(data|bss|noinit|ccm_bss|stack)$")
      math(EXPR ram "${ram} + ${bytes}")
    endif()
  endif()
endforeach()

math(EXPR flash_pct "${flash} * 100 / ${FLASH_BUDGET}")
math(EXPR ram_pct "${ram} * 100 / ${RAM_BUDGET}")
get_filename_component(image ${ELF} NAME)
set(report "${image}: flash ${flash} / ${FLASH_BUDGET} bytes (${flash_pct}%), static RAM ${ram} / ${RAM_BUDGET} bytes (${ram_pct}%)\n")
file(WRITE ${REPORT} "${report}")
message(STATUS "${report}")
if(flash GREATER FLASH_BUDGET)
  message(FATAL_ERROR "${image}: flash ${flash} bytes exceeds the budget of ${FLASH_BUDGET}")
endif()
if(ram GREATER RAM_BUDGET)
  message(FATAL_ERROR "${image}: static RAM ${ram} bytes exceeds the budget of ${RAM_BUDGET}")
endif()
