// A plain-text diagnostics line on USART2 (QEMU: the second -serial), for figures the wire
// protocol has no field for: the cost of the sampling interrupt per frame.
#pragma once

#include <cstdint>

namespace vibid::fw::qemu {

/// Enables USART2 transmit.
void DiagnosticsInit();
/// Writes `text` followed by "\n".
void DiagnosticsLine(const char* text);
/// Writes "<label> <value>" for each pair, space separated, then "\n".
void DiagnosticsValues(const char* const* labels, const std::uint64_t* values, int count);

}  // namespace vibid::fw::qemu
