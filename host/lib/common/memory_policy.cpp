#include "vibid/common/memory_policy.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace vibid {

void KeepFreedMemory() {
#if defined(__GLIBC__)
  // Setting either value also turns off glibc's own threshold adjustment, which would otherwise
  // move them again as blocks are freed.
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(kReusedBlockBytes));
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(kKeptFreeBytes));
#endif
}

}  // namespace vibid
