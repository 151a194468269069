// How a host program's allocator treats freed memory.
//
// glibc maps every block above its mmap threshold (128 KiB at start, so every record-length
// vector of more than 16 384 samples) afresh and unmaps it on free, and returns the heap's top to
// the system once more than twice that is free there. A numerical pass then touches new pages on
// every allocation, and each first touch is a page fault: about 12 µs on a virtual machine, where
// a 20 000-sample output-error fit spent five sixths of its time in the kernel
// (docs/performance.md). Keeping freed memory for reuse makes those faults happen once per process.
#pragma once

#include <cstddef>

namespace vibid {

/// Blocks up to kReusedBlockBytes come from the heap and freed memory is kept in the process
/// (returned to the system only above kKeptFreeBytes). Call once at the start of main, before any
/// thread is started. A no-op where the C library offers no such control.
inline constexpr std::size_t kReusedBlockBytes = std::size_t{32} << 20;  // glibc's upper bound
inline constexpr std::size_t kKeptFreeBytes = std::size_t{512} << 20;
void KeepFreedMemory();

}  // namespace vibid
