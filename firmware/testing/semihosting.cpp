#include "semihosting.hpp"

#include <cstddef>
#include <cstdint>

namespace vibid::testing {
namespace {

constexpr std::uint32_t kSysWrite0 = 0x04;
constexpr std::uint32_t kSysExitExtended = 0x20;
constexpr std::uint32_t kAdpStoppedApplicationExit = 0x20026;

// The Thumb semihosting trap is BKPT 0xAB with the operation in r0 and its argument in r1.
std::uint32_t Call(std::uint32_t op, const void* arg) {
  register std::uint32_t r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

}  // namespace

void SemihostWrite(const char* text) { Call(kSysWrite0, text); }

void SemihostExit(int code) {
  // A plain SYS_EXIT cannot carry a status on AArch32; the extended form takes {reason, code}.
  const std::uint32_t block[2] = {kAdpStoppedApplicationExit, static_cast<std::uint32_t>(code)};
  Call(kSysExitExtended, block);
  for (;;) {
  }
}

}  // namespace vibid::testing

// newlib's stdio ends here: printf from a test reaches the console too.
extern "C" int _write(int fd, const char* data, int size) {
  if (fd != 1 && fd != 2) return -1;
  char chunk[65];
  int done = 0;
  while (done < size) {
    int n = 0;
    while (n < 64 && done + n < size) {
      chunk[n] = data[done + n];
      ++n;
    }
    chunk[n] = '\0';
    vibid::testing::SemihostWrite(chunk);
    done += n;
  }
  return size;
}
