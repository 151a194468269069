// Entry point of the Cortex-M4 test runner, called by the reset handler once C++ is set up.
#pragma once

namespace vibid::testing {

/// Runs every registered test in definition order, prints GoogleTest-style results.
/// @returns 0 if all passed, 1 otherwise (the emulator's exit status).
int RunAllTests();

}  // namespace vibid::testing
