# ctest driver for the start-up code as the compiler left it in an image (what the fake register
# file cannot show): the reset handler's first instructions load MSP from the linker's _estack,
# before any code that could use a stack, and the default exception handler keeps a fault record
# and requests a system reset instead of spinning until a watchdog that may not run yet. Invoked with cmake -P and:
#   ELF       the image
#   OBJDUMP   arm-none-eabi-objdump
#   NM        arm-none-eabi-nm
execute_process(COMMAND ${OBJDUMP} -d --no-show-raw-insn ${ELF} OUTPUT_VARIABLE listing
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${ELF}: objdump failed")
endif()
# One function's instructions: from "<name>:" to the next blank line.
function(function_body name out)
  string(FIND "${listing}" "<${name}>:\n" at)
  if(at LESS 0)
    message(FATAL_ERROR "${ELF}: no function ${name}")
  endif()
  string(SUBSTRING "${listing}" ${at} -1 rest)
  string(FIND "${rest}" "\n\n" end)
  string(SUBSTRING "${rest}" 0 ${end} body)
  set(${out} "${body}" PARENT_SCOPE)
endfunction()

function_body(ResetHandler reset)
string(REGEX MATCHALL "\n[ ]*[0-9a-f]+:\t[^\n]*" lines "${reset}")
list(GET lines 0 first)
list(GET lines 1 second)
if(NOT first MATCHES "ldr[.w]*\tr0, \\[pc" OR NOT second MATCHES "msr\tMSP, r0")
  message(FATAL_ERROR "ResetHandler does not start by loading MSP from a literal:\n${reset}")
endif()
# The literal is _estack: its address as nm gives it, stored as a word in ResetHandler's pool.
execute_process(COMMAND ${NM} ${ELF} OUTPUT_VARIABLE symbols)
if(NOT symbols MATCHES "([0-9a-f]+) [A-Za-z] _estack\n")
  message(FATAL_ERROR "${ELF}: no _estack symbol")
endif()
set(estack "${CMAKE_MATCH_1}")
string(REGEX REPLACE "^0+" "" estack_digits "${estack}")
if(NOT reset MATCHES "\\.word\t0x0*${estack_digits}")
  message(FATAL_ERROR "ResetHandler's literal pool does not hold _estack (0x${estack}):\n${reset}")
endif()

# The default exception handler (every fault, every exception without a handler): reads the
# exception number, moves MSP back to _estack before any C++ runs (a fault from a stack overflow
# must not fault again), and goes to FaultCapture, which keeps the fault record
# (RecordFaultAndReset) and requests a system reset.
function_body(DefaultHandler fault)
if(NOT fault MATCHES "mrs\tr1, IPSR" OR NOT fault MATCHES "msr\tMSP, r2" OR
   NOT fault MATCHES "<FaultCapture>" OR NOT fault MATCHES "\\.word\t0x0*${estack_digits}")
  message(FATAL_ERROR "DefaultHandler does not take IPSR, move MSP to _estack (0x${estack}) and "
                      "branch to FaultCapture:\n${fault}")
endif()
function_body(FaultCapture capture)
if(NOT capture MATCHES "RecordFaultAndReset")
  message(FATAL_ERROR "FaultCapture does not keep the fault record:\n${capture}")
endif()
string(FIND "${listing}" "RecordFaultAndResetEPKmm>:\n" record_at)
if(record_at LESS 0)
  message(FATAL_ERROR "${ELF}: no function RecordFaultAndReset")
endif()
string(SUBSTRING "${listing}" ${record_at} -1 record_rest)
string(FIND "${record_rest}" "\n\n" record_end)
string(SUBSTRING "${record_rest}" 0 ${record_end} record)
if(NOT record MATCHES "SystemReset")
  message(FATAL_ERROR "RecordFaultAndReset does not request a system reset:\n${record}")
endif()
message(STATUS "${ELF}: MSP = _estack (0x${estack}) first in ResetHandler; DefaultHandler records "
               "the fault on a fresh stack and resets")
