# vibid_firmware_image(TARGET [LINKER_SCRIPT file]): turns an executable into a board image:
# linker script (default: the STM32F405 board's), .elf suffix, the image's CRC-32 written into its
# trailer after the link (image_crc.py; the self-test compares it), .bin and .hex beside it made
# from that ELF, a map file, and the size budget checked after every link (flash <= 128 KiB,
# static RAM <= 160 KiB).
set(VIBID_STM32F405_DIR ${CMAKE_CURRENT_LIST_DIR} CACHE INTERNAL "STM32F405 port sources")
set(VIBID_FLASH_BUDGET_BYTES 131072 CACHE INTERNAL "Image flash budget")
set(VIBID_RAM_BUDGET_BYTES 163840 CACHE INTERNAL "Image static RAM budget")
find_program(VIBID_SYSTEM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT VIBID_SYSTEM_PYTHON)
  message(FATAL_ERROR "python3 not found in /usr/bin: the image's CRC is written by image_crc.py "
                      "after every link (scripts/setup installs python3)")
endif()

function(vibid_firmware_image target)
  cmake_parse_arguments(ARG "" "LINKER_SCRIPT" "" ${ARGN})
  if(NOT ARG_LINKER_SCRIPT)
    set(ARG_LINKER_SCRIPT ${VIBID_STM32F405_DIR}/stm32f405.ld)
  endif()
  set_target_properties(${target} PROPERTIES SUFFIX ".elf")
  target_link_options(${target} PRIVATE
    -T${ARG_LINKER_SCRIPT} -L${VIBID_STM32F405_DIR} -nostartfiles --specs=nano.specs --specs=nosys.specs
    -Wl,-Map=$<TARGET_FILE_DIR:${target}>/${target}.map)
  set_target_properties(${target} PROPERTIES
    LINK_DEPENDS "${ARG_LINKER_SCRIPT};${VIBID_STM32F405_DIR}/sections.ld")
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND ${VIBID_SYSTEM_PYTHON} ${VIBID_STM32F405_DIR}/image_crc.py stamp $<TARGET_FILE:${target}>
            --objcopy ${CMAKE_OBJCOPY}
    COMMAND ${CMAKE_OBJCOPY} -O binary --gap-fill 0xff $<TARGET_FILE:${target}> $<TARGET_FILE_DIR:${target}>/${target}.bin
    COMMAND ${CMAKE_OBJCOPY} -O ihex $<TARGET_FILE:${target}> $<TARGET_FILE_DIR:${target}>/${target}.hex
    COMMAND ${CMAKE_COMMAND} -DSIZE_TOOL=${CMAKE_SIZE} -DELF=$<TARGET_FILE:${target}>
            -DREPORT=$<TARGET_FILE_DIR:${target}>/${target}.size.txt
            -DFLASH_BUDGET=${VIBID_FLASH_BUDGET_BYTES} -DRAM_BUDGET=${VIBID_RAM_BUDGET_BYTES}
            -P ${VIBID_STM32F405_DIR}/size_budget.cmake
    VERBATIM)
endfunction()
