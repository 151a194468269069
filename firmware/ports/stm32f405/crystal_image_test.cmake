# ctest driver for the other-crystal images: builds TARGET in BUILD_DIR (the size budget is
# checked by the build), then looks for the RCC_PLLCFGR word the image must load. Invoked with
# cmake -P and:
#   BUILD_DIR   the firmware build tree
#   TARGET      the image target
#   ELF         its output
#   OBJDUMP     arm-none-eabi-objdump
#   PLLCFGR     the expected word, 0x........ (worked out by hand from RM0090 §7.3.2)
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGET} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${TARGET}: build failed")
endif()
execute_process(COMMAND ${OBJDUMP} -d ${ELF} OUTPUT_VARIABLE listing RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${ELF}: objdump failed")
endif()
string(TOLOWER "${PLLCFGR}" word)
if(NOT listing MATCHES "\\.word[ \t]+${word}")
  message(FATAL_ERROR "${TARGET}: RCC_PLLCFGR value ${PLLCFGR} not found in the image")
endif()
message(STATUS "${TARGET}: builds, fits the budget, loads RCC_PLLCFGR = ${PLLCFGR}")
