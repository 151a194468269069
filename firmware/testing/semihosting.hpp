// ARM semihosting calls used by the Cortex-M4 test images (QEMU `-semihosting-config enable=on`).
// Operation numbers and the exit reason are from Arm's "Semihosting for AArch32 and AArch64".
#pragma once

#include <cstdint>

namespace vibid::testing {

/// Writes a NUL-terminated string to the host console (SYS_WRITE0).
void SemihostWrite(const char* text);

/// Ends the emulation with `code` as the process exit status (SYS_EXIT_EXTENDED with
/// ADP_Stopped_ApplicationExit). Does not return.
[[noreturn]] void SemihostExit(int code);

}  // namespace vibid::testing
