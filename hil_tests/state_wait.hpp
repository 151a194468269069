// How long a hil test waits for a state it acts on: the emulator sampling, a client imported, an
// acquisition at its record limit, an image ready.
#pragma once

#include <chrono>

namespace vibid::hil {

/// Sized for a machine running 6-8 jobs on 2 cores, where a process's start or a realtime
/// emulator's first sample can take tens of seconds. A wait returns as soon as its state comes,
/// so the size costs nothing then; one that gives up fails the test and names what it waited
/// for. How fast a state comes is a benchmark's to judge, not a test's.
inline constexpr std::chrono::seconds kStateWait{120};

}  // namespace vibid::hil
