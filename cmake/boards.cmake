# STM32F405 board definitions. A board is what changes from one PCB to another for the same
# image: the HSE crystal (the PLL factors follow at compile time, clock_plan.hpp) and the status
# LED. The signal pins are the chip's and the same on every board (ADC1 IN0..IN3 on PA0..PA3,
# TIM3 on PA6/PA7, TIM4 on PB6/PB7, OTG_FS on PA11/PA12); docs/board.md has each board's wiring
# table, its sources, and what cannot be wired on it.
#
#   vibid        the project's own board: HSE from VIBID_HSE_HZ (8 MHz by default), no LED, no
#                LSE, VBUS not wired
#   pyboard_v11  MicroPython pyboard v1.1 (PYBv1.1 schematic): 12 MHz HSE, blue LED4 on PB4,
#                lit high, 32.768 kHz LSE, VBUS to PA9
#   olimex_h405  Olimex STM32-H405 (rev. B schematic): 8 MHz HSE, STAT LED on PC12, lit high,
#                32.768 kHz LSE, VBUS not on PA9
#
# Each definition: HSE_HZ; LED as "PORT;PIN;ACTIVE" (PORT A..C, ACTIVE high|low) or empty; LSE
# 1 with a 32.768 kHz crystal on PC14/PC15, else 0; VBUS_PA9 1 when the USB connector's VBUS
# reaches PA9 (the OTG core then senses it), else 0.
set(VIBID_BOARDS vibid pyboard_v11 olimex_h405)
set(VIBID_BOARD_vibid_HSE_HZ "${VIBID_HSE_HZ}")
set(VIBID_BOARD_vibid_LED "")
set(VIBID_BOARD_vibid_LSE 0)
set(VIBID_BOARD_vibid_VBUS_PA9 0)
set(VIBID_BOARD_pyboard_v11_HSE_HZ 12000000)
set(VIBID_BOARD_pyboard_v11_LED "B;4;high")
set(VIBID_BOARD_pyboard_v11_LSE 1)
set(VIBID_BOARD_pyboard_v11_VBUS_PA9 1)
set(VIBID_BOARD_olimex_h405_HSE_HZ 8000000)
set(VIBID_BOARD_olimex_h405_LED "C;12;high")
set(VIBID_BOARD_olimex_h405_LSE 1)
set(VIBID_BOARD_olimex_h405_VBUS_PA9 0)

set(VIBID_BOARD vibid CACHE STRING "STM32F405 board of the vibid_board_stm32f405 image (one of VIBID_BOARDS)")
set_property(CACHE VIBID_BOARD PROPERTY STRINGS ${VIBID_BOARDS})
if(NOT VIBID_BOARD IN_LIST VIBID_BOARDS)
  string(REPLACE ";" ", " known "${VIBID_BOARDS}")
  message(FATAL_ERROR "VIBID_BOARD='${VIBID_BOARD}': not a board definition; known boards: ${known} (cmake/boards.cmake)")
endif()

# vibid_board_compile_definitions(TARGET BOARD [HSE_HZ]): the board's crystal (or HSE_HZ) and LED
# for one image.
function(vibid_board_compile_definitions target board)
  set(hse_hz ${VIBID_BOARD_${board}_HSE_HZ})
  if(ARGC GREATER 2)
    set(hse_hz ${ARGV2})
  endif()
  set(defs VIBID_HSE_HZ=${hse_hz} VIBID_BOARD_NAME="${board}"
      VIBID_BOARD_LSE=${VIBID_BOARD_${board}_LSE} VIBID_BOARD_VBUS_PA9=${VIBID_BOARD_${board}_VBUS_PA9})
  set(led "${VIBID_BOARD_${board}_LED}")
  if(led)
    list(GET led 0 port)
    list(GET led 1 pin)
    list(GET led 2 active)
    string(FIND "ABC" "${port}" port_index)
    if(port_index LESS 0 OR NOT pin MATCHES "^([0-9]|1[0-5])$" OR NOT active MATCHES "^(high|low)$")
      message(FATAL_ERROR "board ${board}: LED '${led}' is not PORT(A..C);PIN(0..15);high|low")
    endif()
    if(active STREQUAL "high")
      set(active_high 1)
    else()
      set(active_high 0)
    endif()
    list(APPEND defs VIBID_LED_PORT_INDEX=${port_index} VIBID_LED_PIN=${pin} VIBID_LED_ACTIVE_HIGH=${active_high})
  endif()
  target_compile_definitions(${target} PRIVATE ${defs})
endfunction()
